#include "fmi/cvodes_stepper.hpp"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/analysis/cvodes_problem.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/framework/block.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::fmi {
namespace {

N_Vector vec(void* p) { return static_cast<N_Vector>(p); }

// A callback's body for CVODES (as engine::cvodes::guarded for the engine's runs): its own
// result, or 1 (recoverable: a smaller step) when a block refused the point, -1 on any other
// failure; what failed is kept for advance's message.
template <class F>
int guarded(CvodesStepper& s, double t, F&& body) {
  try {
    return body();
  } catch (const engine::OutOfDomain& e) {
    s.failure = e.reason, s.failure_time = t;
    return 1;
  } catch (const std::exception& e) {
    s.failure = e.what(), s.failure_time = t;
    return -1;
  }
}

int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
  auto& s = *static_cast<CvodesStepper*>(user);
  return guarded(s, t, [&] {
    s.model.move_to(t, N_VGetArrayPointer(y));
    s.model.derivatives(N_VGetArrayPointer(ydot));
    for (int i = 0; i < s.model.num_states(); ++i)
      if (!std::isfinite(N_VGetArrayPointer(ydot)[i])) return 1;  // recoverable: a smaller step
    return 0;
  });
}

int jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix jac, void* user, N_Vector, N_Vector, N_Vector) {
  auto& s = *static_cast<CvodesStepper*>(user);
  return guarded(s, t, [&] {
    s.model.move_to(t, N_VGetArrayPointer(y));
    s.model.state_jacobian(SUNDenseMatrix_Data(jac));
    return 0;
  });
}

int sens_rhs(int ns, sunrealtype t, N_Vector y, N_Vector, N_Vector* ys, N_Vector* ysdot, void* user, N_Vector,
             N_Vector) {
  auto& s = *static_cast<CvodesStepper*>(user);
  return guarded(s, t, [&] {
    const int n = s.model.num_states();
    s.model.move_to(t, N_VGetArrayPointer(y));
    engine::cvodes::gather(ys, n, ns, s.s_buffer);
    s.sdot_buffer.resize(s.s_buffer.size());
    s.model.sensitivity_derivatives(s.s_buffer.data(), s.sdot_buffer.data());
    engine::cvodes::scatter(s.sdot_buffer, n, ns, ysdot);
    return 0;
  });
}

void silent(int, const char*, const char*, char*, void*) {}

void check(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string("CVODES ") + call + " failed (flag " + std::to_string(flag) + ")");
}

}  // namespace

CvodesStepper::CvodesStepper(FmuModel& m, const StepperSettings& settings) : model(m), settings_(settings) {
  SUNContext ctx = nullptr;
  check(SUNContext_Create(nullptr, &ctx), "SUNContext_Create");
  context_ = ctx;
  const int n = std::max(model.num_states(), 1);
  y_ = N_VNew_Serial(n, ctx);
  atol_ = N_VNew_Serial(n, ctx);
  for (int i = 0; i < n; ++i)
    N_VGetArrayPointer(vec(atol_))[i] = settings_.atol * (i < model.num_states() ? model.table().nominals[i] : 1.0);
  cvode_ = CVodeCreate(CV_BDF, ctx);
  if (!cvode_) throw std::runtime_error("CVODES CVodeCreate failed");
  std::fill_n(N_VGetArrayPointer(vec(y_)), n, 0.0);
  check(CVodeInit(cvode_, rhs, model.time(), vec(y_)), "CVodeInit");
  check(CVodeSetErrHandlerFn(cvode_, silent, nullptr), "CVodeSetErrHandlerFn");
  check(CVodeSVtolerances(cvode_, settings_.rtol, vec(atol_)), "CVodeSVtolerances");
  check(CVodeSetUserData(cvode_, this), "CVodeSetUserData");
  matrix_ = SUNDenseMatrix(n, n, ctx);
  solver_ = SUNLinSol_Dense(vec(y_), static_cast<SUNMatrix>(matrix_), ctx);
  check(CVodeSetLinearSolver(cvode_, static_cast<SUNLinearSolver>(solver_), static_cast<SUNMatrix>(matrix_)),
        "CVodeSetLinearSolver");
  check(CVodeSetJacFn(cvode_, jacobian), "CVodeSetJacFn");
  check(CVodeSetMaxNumSteps(cvode_, settings_.max_steps), "CVodeSetMaxNumSteps");
  if (settings_.max_order > 0) check(CVodeSetMaxOrd(cvode_, settings_.max_order), "CVodeSetMaxOrd");
  ns_ = model.num_states() > 0 ? model.num_sensitivities() : 0;
  if (ns_ > 0) {
    // Forward sensitivities by the simultaneous corrector, their right-hand side the tangent pass
    // (as dydp's own runs, engine/analysis/cvodes_solver.cpp); in the error test or not as the
    // scene's solver says. Their values and tolerances are set at each (re)start.
    N_Vector* ys = N_VCloneVectorArray(ns_, vec(y_));
    sens_ = ys;
    for (int dir = 0; dir < ns_; ++dir) N_VConst(0.0, ys[dir]);
    check(CVodeSensInit(cvode_, ns_, CV_SIMULTANEOUS, sens_rhs, ys), "CVodeSensInit");
    check(CVodeSetSensErrCon(cvode_, model.diagram().solver.sens_error_test), "CVodeSetSensErrCon");
  }
}

CvodesStepper::~CvodesStepper() {
  CVodeFree(&cvode_);
  if (sens_) N_VDestroyVectorArray(static_cast<N_Vector*>(sens_), ns_);
  if (sens_atol_) N_VDestroyVectorArray(static_cast<N_Vector*>(sens_atol_), ns_);
  SUNLinSolFree(static_cast<SUNLinearSolver>(solver_));
  SUNMatDestroy(static_cast<SUNMatrix>(matrix_));
  N_VDestroy(vec(y_));
  N_VDestroy(vec(atol_));
  SUNContext ctx = static_cast<SUNContext>(context_);
  SUNContext_Free(&ctx);
}

void CvodesStepper::restart() {
  std::copy(model.states().begin(), model.states().end(), N_VGetArrayPointer(vec(y_)));
  check(CVodeReInit(cvode_, model.time(), vec(y_)), "CVodeReInit");
  if (ns_ == 0) return;
  // The sensitivities go on from the model's (the start's, or as the last step left them: an
  // importer's new states or parameters do not change them), held to dydp's tolerances for the
  // parameters' present values (engine/analysis/tolerances.hpp).
  N_Vector* ys = static_cast<N_Vector*>(sens_);
  const int n = model.num_states();
  engine::cvodes::scatter(model.sensitivities(), n, ns_, ys);
  check(CVodeSensReInit(cvode_, CV_SIMULTANEOUS, ys), "CVodeSensReInit");
  const engine::Diagram& d = model.diagram();
  const engine::AbsoluteTolerances atols = engine::absolute_tolerances(d, settings_.atol, ns_);
  if (sens_atol_) N_VDestroyVectorArray(static_cast<N_Vector*>(sens_atol_), ns_);
  sens_atol_ = engine::cvodes::sensitivity_tolerances(atols, d.num_states, d.num_quadratures, ns_, settings_.atol, vec(y_));
  check(CVodeSensSVtolerances(cvode_, settings_.rtol, static_cast<N_Vector*>(sens_atol_)), "CVodeSensSVtolerances");
}

void CvodesStepper::take_sensitivities() {
  if (ns_ == 0) return;
  sunrealtype t = model.time();
  N_Vector* ys = static_cast<N_Vector*>(sens_);
  if (CVodeGetSens(cvode_, &t, ys) < 0) return;
  engine::cvodes::gather(ys, model.num_states(), ns_, s_buffer);
  model.move_sensitivities(s_buffer.data());
}

long CvodesStepper::steps() const {
  long n = 0;
  CVodeGetNumSteps(cvode_, &n);
  return steps_before_ + n;
}

void CvodesStepper::advance(double t_end) {
  if (model.num_states() == 0) {  // nothing to integrate: time moves on
    model.move_to(t_end, nullptr);
    return;
  }
  while (model.time() < t_end) {
    const double t_break = model.next_breakpoint(model.time());
    const double target = std::min(t_end, t_break);
    if (model.changes() != seen_changes_) {
      steps_before_ = steps();
      restart();
    }
    check(CVodeSetStopTime(cvode_, target), "CVodeSetStopTime");
    sunrealtype reached = model.time();
    failure.clear();
    const int flag = CVode(cvode_, target, vec(y_), &reached, CV_NORMAL);
    if (flag < 0) {
      const std::string why = failure.empty() ? "CVODES failed (flag " + std::to_string(flag) + ")" : failure;
      const double at = failure.empty() ? reached : failure_time;
      model.move_to(reached, N_VGetArrayPointer(vec(y_)));
      take_sensitivities();
      seen_changes_ = -1;
      if (!failure.empty() && failure.find(": ") != std::string::npos)
        throw engine::domain_failure(at, engine::OutOfDomain{why});
      throw engine::SolverError(at, "", why);
    }
    model.move_to(target, N_VGetArrayPointer(vec(y_)));
    take_sensitivities();
    if (target == t_break) {  // a breakpoint: the right-hand side may jump, BDF starts again
      model.set_segment_start(target);
      seen_changes_ = -1;
    } else {
      seen_changes_ = model.changes();
    }
  }
}

}  // namespace dydp::fmi
