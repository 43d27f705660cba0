#include "engine/analysis/cvodes_problem.hpp"

#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "engine/analysis/dense_lu_solver.hpp"
#include "engine/analysis/sundials_kernels.hpp"
#include "engine/analysis/timeline.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/solver_methods.hpp"

namespace dydp::engine::cvodes {

/// CVODES' name of a return flag. CVodeGetReturnFlagName mallocs the name; the caller frees it
/// (found by scene_run_fuzz: every failed run leaked it).
std::string flag_name(int flag) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string s = name ? name : "unknown flag";
  std::free(name);
  return s;
}

int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user) {
  auto& P = *static_cast<Problem*>(user);
  double* xdot = NV_DATA_S(ydot);
  if (!P.scene_values.empty()) P.ev.use_parameter_values(P.scene_values.data());
  if (P.nx + P.nq == 0) xdot[0] = 0.0;
  if (const int flag = guarded(P, t, [&] {
        P.ev.derivatives(t, NV_DATA_S(y), xdot);
        if (P.nq > 0) P.ev.quadratures(t, NV_DATA_S(y), xdot + P.nx);  // the same value pass
      }))
    return flag;
  if (!P.ev.all_finite(xdot)) {
    P.refuse(t, P.ev.find_nonfinite(xdot));
    return 1;  // recoverable: CVODES retries with a smaller step, then fails naming it
  }
  return 0;
}

int sens_rhs(int ns, sunrealtype t, N_Vector y, N_Vector, N_Vector* yS, N_Vector* ySdot,
             void* user, N_Vector, N_Vector) {
  auto& P = *static_cast<Problem*>(user);
  return guarded(P, t, [&] {
    gather(yS, P.nx, ns, P.dx);  // the states' part: nothing reads the integrals
    P.dxdot.assign(static_cast<size_t>(P.ny) * ns, 0.0);
    P.ev.tangents(t, NV_DATA_S(y), ns, {P.dx.data(), P.nx}, true, {P.dxdot.data(), P.ny},
                  {P.dxdot.data() + P.nx, P.ny});
    scatter(P.dxdot, P.ny, ns, ySdot);
    ++P.sens_passes;
  });
}

// The Newton matrix's columns for the states from one tangent pass seeded on each; the
// integrals' rows come with it, and their columns are zero (nothing reads an integral).
int jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix J, void* user, N_Vector, N_Vector,
             N_Vector) {
  auto& P = *static_cast<Problem*>(user);
  SUNMatZero(J);
  if (P.nx == 0) return 0;
  return guarded(P, t, [&] {
    const int ld = static_cast<int>(SM_ROWS_D(J));
    P.colouring.evaluate(P.ev, t, NV_DATA_S(y), {SM_DATA_D(J), ld}, {SM_DATA_D(J) + P.nx, ld});
    ++P.jac_passes;
  });
}

void error_handler(int, const char* module, const char* function, char* msg, void* user) {
  static_cast<Problem*>(user)->cvodes_message = std::string(function) + ": " + msg;
}

/// The blocks' own diagonal blocks of the Newton matrix (Block::local_jacobian: a damper's
/// pressures) refreshed at every factorisation, at the state of the Newton iteration's first
/// right-hand side (which the evaluator still holds, so they cost the blocks' own derivatives
/// only). CVODES keeps the whole Jacobian for many steps, and a kept one fails where the stiff,
/// strongly nonlinear hydraulic blocks have moved on (an orifice's flow goes as the root of its
/// pressure drop). With this refresh and a set-up every few steps, the main job's Newton
/// failures, each a whole Jacobian and a retry, fall from 494 to 87 on 4 s (docs/engine.md).
/// False when no block provides a local Jacobian (nothing is set).
bool refresh_local_blocks(Problem& P, void* mem, SUNLinearSolver solver, double t0, const double* x0) {
  if (P.nx == 0) return false;
  const int nx = P.nx;
  // which blocks provide one: found once, at the initial state
  {
    std::vector<double> probe(static_cast<size_t>(nx) * nx, std::numeric_limits<double>::quiet_NaN());
    try {
      if (!P.ev.local_jacobians(t0, x0, probe.data(), nx)) return false;
    } catch (const OutOfDomain&) {
      return false;
    }
    for (const Node& n : P.d.nodes) {
      const int o = n.state_offset, k = n.block->num_states();
      if (k > 0 && !std::isnan(probe[static_cast<size_t>(o) * nx + o])) P.local_blocks.emplace_back(o, k);
    }
  }
  P.local.assign(static_cast<size_t>(nx) * nx, 0.0);
  set_matrix_refresh(solver, [&P, mem, nx](SUNMatrix A) {
    double gamma = 0.0, t = 0.0;
    N_Vector y = nullptr;
    if (CVodeGetCurrentGamma(mem, &gamma) != CV_SUCCESS || CVodeGetCurrentTime(mem, &t) != CV_SUCCESS ||
        CVodeGetCurrentState(mem, &y) != CV_SUCCESS)
      return;
    try {
      if (!P.ev.local_jacobians(t, NV_DATA_S(y), P.local.data(), nx)) return;
    } catch (const OutOfDomain&) {
      return;  // the kept matrix as it is: the step's own evaluation reports the point
    }
    const sunindextype ld = SM_ROWS_D(A);
    double* a = SM_DATA_D(A);
    for (const auto& [o, k] : P.local_blocks)
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i)
          a[(o + j) * ld + o + i] = (i == j ? 1.0 : 0.0) - gamma * P.local[static_cast<size_t>(o + j) * nx + o + i];
    ++P.local_refreshes;
  });
  return true;
}

void check_call(const Problem& P, int flag, const char* call, double t) {
  if (flag >= 0) return;
  throw SolverError(t, P.refusal.empty() ? "" : P.refusal.substr(0, P.refusal.find(':')),
                    std::string(call) + " failed: " + flag_name(flag) +
                        (P.cvodes_message.empty() ? "" : " (" + P.cvodes_message + ")") +
                        (P.refusal.empty() ? "" : "; last refused point: " + P.refusal));
}

N_Vector state_tolerances(const Problem& P, const AbsoluteTolerances& atols, double atol, N_Vector like) {
  N_Vector v = N_VClone(like);
  N_VConst(atol, v);
  std::copy_n(atols.states.data(), P.nx, NV_DATA_S(v));
  std::copy_n(atols.quadratures.data(), P.nq, NV_DATA_S(v) + P.nx);
  return v;
}

N_Vector* sensitivity_tolerances(const AbsoluteTolerances& atols, int nx, int nq, int ns, double atol, N_Vector like) {
  N_Vector* v = N_VCloneVectorArray(ns, like);
  for (int dir = 0; dir < ns; ++dir) {
    N_VConst(atol, v[dir]);
    std::copy_n(atols.sensitivities.data() + static_cast<size_t>(dir) * nx, nx, NV_DATA_S(v[dir]));
    std::copy_n(atols.quadrature_sensitivities.data() + static_cast<size_t>(dir) * nq, nq, NV_DATA_S(v[dir]) + nx);
  }
  return v;
}

void set_up_forward(Problem& P, void* mem, SUNContext ctx, double t, N_Vector y, N_Vector atol, ForwardSolvers& s) {
  const SolverSpec& solver = P.d.solver;
  check_call(P, CVodeSetErrHandlerFn(mem, error_handler, &P), "CVodeSetErrHandlerFn", t);
  check_call(P, CVodeInit(mem, rhs, t, y), "CVodeInit", t);
  check_call(P, CVodeSetUserData(mem, &P), "CVodeSetUserData", t);
  check_call(P, CVodeSVtolerances(mem, solver.rtol, atol), "CVodeSVtolerances", t);
  check_call(P, CVodeSetMaxNumSteps(mem, solver.max_steps), "CVodeSetMaxNumSteps", t);
  check_call(P, CVodeSetMinStep(mem, solver.min_step), "CVodeSetMinStep", t);
  check_call(P, CVodeSetNonlinConvCoef(mem, solver.newton_coefficient), "CVodeSetNonlinConvCoef", t);
  if (solver.max_order > 0) check_call(P, CVodeSetMaxOrd(mem, solver.max_order), "CVodeSetMaxOrd", t);
  if (solver.method == "bdf") {
    const sunindextype n = NV_LENGTH_S(y);
    s.A = SUNDenseMatrix(n, n, ctx);
    use_compiled_matrix_kernels(s.A);
    s.LS = make_dense_lu_solver(ctx);
    check_call(P, CVodeSetLinearSolver(mem, s.LS, s.A), "CVodeSetLinearSolver", t);
    check_call(P, CVodeSetJacFn(mem, jacobian), "CVodeSetJacFn", t);
    // With the local blocks refreshed at each set-up, a set-up every few steps (CVODES: 20)
    // keeps them current; a factorisation costs a few percent of a step.
    P.local_blocks.clear();
    if (solver.refresh_local_jacobians && refresh_local_blocks(P, mem, s.LS, t, NV_DATA_S(y)))
      check_call(P, CVodeSetLSetupFrequency(mem, kLocalRefreshSetupSteps), "CVodeSetLSetupFrequency", t);
  } else {
    s.NLS = SUNNonlinSol_FixedPoint(y, 0, ctx);
    check_call(P, CVodeSetNonlinearSolver(mem, s.NLS), "CVodeSetNonlinearSolver", t);
  }
}

void add_cvodes_counters(void* mem, bool bdf, RunStats& st) {
  long v = 0;
  CVodeGetNumSteps(mem, &v), st.steps += v;
  CVodeGetNumRhsEvals(mem, &v), st.rhs_evals += v;
  CVodeGetNumErrTestFails(mem, &v), st.error_test_failures += v;
  CVodeGetNumNonlinSolvIters(mem, &v), st.nonlinear_iterations += v;
  CVodeGetNumNonlinSolvConvFails(mem, &v), st.nonlinear_failures += v;
  if (bdf) CVodeGetNumJacEvals(mem, &v), st.jac_evals += v;
}

void finish_cvodes_stats(RunStats& st, const Diagram& d, double cpu_seconds) {
  st.rtol = d.solver.rtol;
  st.atol = d.solver.atol;
  st.max_order = d.solver.max_order > 0 ? d.solver.max_order : highest_order(d.solver.method);
  finish_stats(st, d.solver.method, cpu_seconds, d.time);
}

}  // namespace dydp::engine::cvodes
