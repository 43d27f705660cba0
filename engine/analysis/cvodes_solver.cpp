// CVODES (BDF or Adams) with forward sensitivities by the direct method: the sensitivity
// right-hand side is the diagram's tangent pass, corrected simultaneously with the states and
// included in the error test or not (solver.sens_error_test); absolute tolerances per state
// from the blocks' nominal magnitudes (engine/analysis/tolerances.hpp); the Newton matrix is the exact
// Jacobian from tangent passes over the states. Objective integrals are integrated with the
// states: CVODES' vector is [x; q], their integrands evaluated by the same value and tangent
// passes as xdot (CVODES' own quadratures would cost one more value pass and one more tangent
// pass per step, at the corrected solution), held to their own tolerances and, with the
// sensitivities, their sensitivities' (in the error test with the states' sensitivities). Steps
// are taken one at a time to count the states that limit them.
#include "engine/analysis/cvodes_solver.hpp"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <memory>

#include "engine/analysis/cpu_clock.hpp"
#include "engine/analysis/dense_lu_solver.hpp"
#include "engine/analysis/recorder.hpp"
#include "engine/analysis/step_limiters.hpp"
#include "engine/analysis/sundials_kernels.hpp"
#include "engine/analysis/timeline.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/jacobian_colouring.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/solver_methods.hpp"

namespace dydp::engine {
namespace {

/// CVODES' name of a return flag. CVodeGetReturnFlagName mallocs the name; the caller frees it
/// (found by scene_run_fuzz: every failed run leaked it).
std::string flag_name(int flag) {
  char* name = CVodeGetReturnFlagName(flag);
  std::string s = name ? name : "unknown flag";
  std::free(name);
  return s;
}

/// Steps between CVODES' linear set-ups when blocks refresh their own Jacobian blocks.
constexpr int kLocalRefreshSetupSteps = 5;

/// What the C callbacks need, and what they found when they had to refuse a point.
struct Problem {
  Problem(const Diagram& diagram, Evaluator& evaluator, int states, int directions)
      : d(diagram), ev(evaluator), nx(states), nq(diagram.num_quadratures), ny(std::max(states + nq, 1)),
        ns(directions), colouring(diagram) {}
  const Diagram& d;
  Evaluator& ev;
  int nx;                 ///< states of the diagram
  int nq;                 ///< objective integrals, after the states in CVODES' vector
  int ny;                 ///< CVODES' vector: max(nx + nq, 1)
  int ns;
  std::vector<double> dx, dxdot;
  JacobianColouring colouring;  ///< the Jacobian's tangent passes, one per colour
  std::string refusal;    ///< last block that refused a point: "block: reason"
  double refusal_t = 0.0;
  std::string cvodes_message;
  long sens_passes = 0;
  long jac_passes = 0;
  long local_refreshes = 0;   ///< Newton matrices with the blocks' diagonal blocks refreshed
  std::vector<std::pair<int, int>> local_blocks;  ///< (first state, states) of those blocks
  std::vector<double> local;  ///< their Jacobians (nx x nx, only those blocks written)
  /// Difference-quotient mode: the scene parameter values CVODES perturbs.
  std::vector<double> scene_values;

  void refuse(double t, std::string why) {
    refusal = std::move(why);
    refusal_t = t;
  }
};

/// Copies N_Vector columns into a d-major buffer and back.
void gather(N_Vector* v, int n, int count, std::vector<double>& out) {
  out.resize(static_cast<size_t>(n) * count);
  for (int c = 0; c < count; ++c) std::copy_n(NV_DATA_S(v[c]), n, out.data() + c * n);
}
void scatter(const std::vector<double>& in, int n, int count, N_Vector* v) {
  for (int c = 0; c < count; ++c) std::copy_n(in.data() + c * n, n, NV_DATA_S(v[c]));
}

/// Runs a callback body for CVODES: 0 on success, 1 (recoverable: retry with a smaller step)
/// when a block refused the point, -1 on any other failure; the refusal is remembered.
template <class F>
int guarded(Problem& P, double t, F&& body) {
  try {
    body();
  } catch (const OutOfDomain& e) {
    P.refuse(t, e.reason);
    return 1;
  } catch (const std::exception& e) {
    P.refuse(t, e.what());
    return -1;
  }
  return 0;
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

/// Owns the SUNDIALS objects of one run and releases them in the right order.
struct Sundials {
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  N_Vector* ys = nullptr;
  int ns = 0;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  SUNNonlinearSolver NLS = nullptr, NLSsens = nullptr;

  ~Sundials() {
    if (mem) CVodeFree(&mem);
    if (ys) N_VDestroyVectorArray(ys, ns);
    if (y) N_VDestroy(y);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (NLS) SUNNonlinSolFree(NLS);
    if (NLSsens) SUNNonlinSolFree(NLSsens);
    if (ctx) SUNContext_Free(&ctx);
  }
};

}  // namespace

RunResult run_cvodes(const Diagram& d, const RunOptions& options) {
  const bool bdf = d.solver.method == "bdf";
  const int nx = d.num_states, nq = d.num_quadratures;
  const int ns = options.sensitivities ? static_cast<int>(d.sensitivities.size()) : 0;
  const int n_cv = std::max(nx + nq, 1);  // [x; q]
  const double t0 = d.time.start, tf = d.time.stop;

  Evaluator ev(d, ns > 0);
  RunResult result;
  Recorder recorder(d, ns, result, options);
  Problem P(d, ev, nx, ns);
  const CpuClock clock;

  Sundials S;
  S.ns = ns;
  auto check = [&](int flag, const char* call) {
    if (flag < 0)
      throw SolverError(t0, "", std::string(call) + " failed: " + flag_name(flag) +
                                    (P.cvodes_message.empty() ? "" : " (" + P.cvodes_message + ")"));
  };
  check(SUNContext_Create(nullptr, &S.ctx), "SUNContext_Create");
  S.y = N_VNew_Serial(n_cv, S.ctx);
  N_VEnableFusedOps_Serial(S.y, SUNTRUE);  // fewer passes over the sensitivity vectors
  use_compiled_vector_kernels(S.y);         // before CVodeInit: CVODES clones its vectors from y
  N_VConst(0.0, S.y);
  ev.set_segment_start(t0);
  ev.initial_state(t0, NV_DATA_S(S.y));

  S.mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, S.ctx);
  if (!S.mem) throw SolverError(t0, "", "CVodeCreate failed");
  check(CVodeSetErrHandlerFn(S.mem, error_handler, &P), "CVodeSetErrHandlerFn");
  check(CVodeInit(S.mem, rhs, t0, S.y), "CVodeInit");
  check(CVodeSetUserData(S.mem, &P), "CVodeSetUserData");
  // One absolute tolerance per state: atol times its nominal magnitude (a pressure in Pa, a
  // position in m, a flow in m^3/s each judged in its own units).
  const AbsoluteTolerances atols = absolute_tolerances(d, d.solver.atol, ns);
  N_Vector atol_states = N_VClone(S.y);
  N_VConst(d.solver.atol, atol_states);
  std::copy_n(atols.states.data(), nx, NV_DATA_S(atol_states));
  std::copy_n(atols.quadratures.data(), nq, NV_DATA_S(atol_states) + nx);
  const int sv_flag = CVodeSVtolerances(S.mem, d.solver.rtol, atol_states);
  N_VDestroy(atol_states);
  check(sv_flag, "CVodeSVtolerances");
  check(CVodeSetMaxNumSteps(S.mem, d.solver.max_steps), "CVodeSetMaxNumSteps");
  check(CVodeSetMinStep(S.mem, d.solver.min_step), "CVodeSetMinStep");
  check(CVodeSetNonlinConvCoef(S.mem, d.solver.newton_coefficient), "CVodeSetNonlinConvCoef");
  if (d.solver.max_order > 0) check(CVodeSetMaxOrd(S.mem, d.solver.max_order), "CVodeSetMaxOrd");
  if (bdf) {
    S.A = SUNDenseMatrix(n_cv, n_cv, S.ctx);
    use_compiled_matrix_kernels(S.A);
    S.LS = make_dense_lu_solver(S.ctx);
    check(CVodeSetLinearSolver(S.mem, S.LS, S.A), "CVodeSetLinearSolver");
    check(CVodeSetJacFn(S.mem, jacobian), "CVodeSetJacFn");
    // With the local blocks refreshed at each set-up, a set-up every few steps (CVODES: 20)
    // keeps them current; a factorisation costs a few percent of a step.
    if (d.solver.refresh_local_jacobians && refresh_local_blocks(P, S.mem, S.LS, t0, NV_DATA_S(S.y))) {
      check(CVodeSetLSetupFrequency(S.mem, kLocalRefreshSetupSteps), "CVodeSetLSetupFrequency");
    }
  } else {
    S.NLS = SUNNonlinSol_FixedPoint(S.y, 0, S.ctx);
    check(CVodeSetNonlinearSolver(S.mem, S.NLS), "CVodeSetNonlinearSolver");
  }

  if (ns > 0) {
    S.ys = N_VCloneVectorArray(ns, S.y);
    std::vector<double> dx0(static_cast<size_t>(nx) * ns, 0.0);
    ev.initial_state_tangent(t0, NV_DATA_S(S.y), {dx0.data(), nx});
    for (int dir = 0; dir < ns; ++dir) N_VConst(0.0, S.ys[dir]);
    if (nx > 0) scatter(dx0, nx, ns, S.ys);
    if (options.difference_quotient_sensitivities) {
      for (const auto& p : d.parameters) P.scene_values.push_back(p.value);
      std::vector<int> plist(d.sensitivities.begin(), d.sensitivities.end());
      std::vector<double> pbar;
      for (int i : d.sensitivities) pbar.push_back(std::fabs(d.parameters[i].value) > 0 ? std::fabs(d.parameters[i].value) : 1.0);
      check(CVodeSensInit(S.mem, ns, CV_SIMULTANEOUS, nullptr, S.ys), "CVodeSensInit");
      check(CVodeSetSensParams(S.mem, P.scene_values.data(), pbar.data(), plist.data()), "CVodeSetSensParams");
    } else {
      check(CVodeSensInit(S.mem, ns, CV_SIMULTANEOUS, sens_rhs, S.ys), "CVodeSensInit");
    }
    // Sensitivity tolerances: the states' ones over the parameter's value (the pbar of CVODES'
    // guide), so dx/dk for a stiffness of 1e5 N/m is held to the same relative accuracy as dx/dm.
    N_Vector* atol_sens = N_VCloneVectorArray(ns, S.y);
    for (int dir = 0; dir < ns; ++dir) {
      N_VConst(d.solver.atol, atol_sens[dir]);  // the placeholder state of a stateless diagram
      std::copy_n(atols.sensitivities.data() + static_cast<size_t>(dir) * nx, nx, NV_DATA_S(atol_sens[dir]));
      std::copy_n(atols.quadrature_sensitivities.data() + static_cast<size_t>(dir) * nq, nq,
                  NV_DATA_S(atol_sens[dir]) + nx);
    }
    const int ssv_flag = CVodeSensSVtolerances(S.mem, d.solver.rtol, atol_sens);
    N_VDestroyVectorArray(atol_sens, ns);
    check(ssv_flag, "CVodeSensSVtolerances");
    check(CVodeSetSensErrCon(S.mem, d.solver.sens_error_test), "CVodeSetSensErrCon");
    if (!bdf) {
      S.NLSsens = SUNNonlinSol_FixedPointSens(ns + 1, S.y, 0, S.ctx);
      check(CVodeSetNonlinearSolverSensSim(S.mem, S.NLSsens), "CVodeSetNonlinearSolverSensSim");
    }
  }
  RunStats& st = result.stats;
  auto accumulate = [&] {
    long v = 0;
    CVodeGetNumSteps(S.mem, &v), st.steps += v;
    CVodeGetNumRhsEvals(S.mem, &v), st.rhs_evals += v;
    CVodeGetNumErrTestFails(S.mem, &v), st.error_test_failures += v;
    CVodeGetNumNonlinSolvIters(S.mem, &v), st.nonlinear_iterations += v;
    CVodeGetNumNonlinSolvConvFails(S.mem, &v), st.nonlinear_failures += v;
    if (bdf) CVodeGetNumJacEvals(S.mem, &v), st.jac_evals += v;
    st.local_jac_evals = P.local_refreshes;
    st.jacobian_colours = P.colouring.colours();
  };

  // Record at t0, then march over outputs and breakpoints; restart CVODES after each breakpoint
  // since the right-hand side may jump there.
  auto record = [&](double t) {
    std::vector<double> dx;
    if (ns > 0) {
      sunrealtype tret = t;
      if (t > t0) check(CVodeGetSensDky(S.mem, tret, 0, S.ys), "CVodeGetSensDky");
      gather(S.ys, nx, ns, dx);
      ev.tangents(t, NV_DATA_S(S.y), ns, {dx.data(), nx}, true, {}, {});
    } else {
      ev.outputs(t, NV_DATA_S(S.y));
    }
    recorder.record(t, NV_DATA_S(S.y), ev);
  };
  record(t0);

  const Timeline timeline(d);
  const std::vector<double>& breaks = timeline.breaks;

  // One step at a time, so that after each accepted step the state with the largest weighted
  // local error is counted (StepLimiters); outputs are interpolated (CVodeGetDky) as CVODES'
  // normal mode does, from the same steps.
  StepLimiters limiters(nx + nq);
  N_Vector local_errors = N_VClone(S.y), weights = N_VClone(S.y);
  struct Release {
    N_Vector a, b;
    ~Release() { N_VDestroy(a), N_VDestroy(b); }
  } release{local_errors, weights};

  auto fail = [&](int flag, double t, std::string reason) {
    if (!P.cvodes_message.empty()) reason += " (" + P.cvodes_message + ")";
    std::string block;
    // Name the state CVODES could not hold to its tolerance: the largest weighted local error.
    if (flag == CV_ERR_FAILURE || flag == CV_CONV_FAILURE || flag == CV_TOO_MUCH_WORK) {
      if (CVodeGetEstLocalErrors(S.mem, local_errors) == CV_SUCCESS &&
          CVodeGetErrWeights(S.mem, weights) == CV_SUCCESS) {
        int worst = -1;
        double largest = -1.0;
        for (int i = 0; i < nx; ++i) {
          const double e = std::fabs(NV_Ith_S(local_errors, i) * NV_Ith_S(weights, i));
          if (e > largest) largest = e, worst = i;
        }
        for (const Node& n : d.nodes)
          if (worst >= n.state_offset && worst < n.state_offset + n.block->num_states()) {
            block = n.name;
            reason += "; largest estimated local error in state " +
                      n.block->state_names()[worst - n.state_offset];
          }
      }
    }
    if (!P.refusal.empty()) {
      block = P.refusal.substr(0, P.refusal.find(':'));
      reason += "; last refused point at t = " + std::to_string(P.refusal_t) + " s: " + P.refusal;
    }
    throw SolverError(t, block, reason);
  };

  double t = t0;
  double reached = t0;  // CVODES' internal time: the end of its last step
  size_t next_break = 0;
  for (double target : timeline.events) {
    while (next_break < breaks.size() && breaks[next_break] < target) ++next_break;
    const double stop = next_break < breaks.size() ? breaks[next_break] : tf;
    check(CVodeSetStopTime(S.mem, stop), "CVodeSetStopTime");
    long interval_steps = 0;
    bool at_target = false;  // S.y holds the solution at target (a step ended there)
    while (reached < target) {
      if (++interval_steps > d.solver.max_steps)
        fail(CV_TOO_MUCH_WORK, reached,
             "CVode failed: CV_TOO_MUCH_WORK (" + std::to_string(d.solver.max_steps) +
                 " steps taken before reaching the next output time " + format_number(target) + " s)");
      const int flag = CVode(S.mem, target, S.y, &reached, CV_ONE_STEP);
      if (flag < 0) fail(flag, reached, std::string("CVode failed: ") + flag_name(flag));
      if (nx + nq > 0 && CVodeGetEstLocalErrors(S.mem, local_errors) == CV_SUCCESS &&
          CVodeGetErrWeights(S.mem, weights) == CV_SUCCESS)
        limiters.add_step(NV_DATA_S(local_errors), NV_DATA_S(weights));
      if (int order = 0; CVodeGetLastOrder(S.mem, &order) == CV_SUCCESS && order >= 1) {
        if (st.steps_per_order.size() < static_cast<size_t>(order)) st.steps_per_order.resize(order, 0);
        ++st.steps_per_order[order - 1];
      }
      at_target = reached == target;
    }
    // Otherwise the last step went past target, in this interval or an earlier one (it may have
    // ended exactly on the next output): interpolate.
    if (!at_target) check(CVodeGetDky(S.mem, target, 0, S.y), "CVodeGetDky");
    t = target;
    if (timeline.is_output(target)) record(target);
    if (next_break < breaks.size() && breaks[next_break] == target && target < tf) {
      accumulate();
      ev.set_segment_start(target);
      // The solution at the breakpoint (the last step ended there: it is the stop time) first,
      // then the restart from it.
      if (ns > 0) check(CVodeGetSensDky(S.mem, target, 0, S.ys), "CVodeGetSensDky");
      check(CVodeReInit(S.mem, target, S.y), "CVodeReInit");
      reached = target;
      if (ns > 0) check(CVodeSensReInit(S.mem, CV_SIMULTANEOUS, S.ys), "CVodeSensReInit");
      t = target;
    }
  }
  accumulate();
  st.sens_rhs_evals = P.sens_passes;
  st.limiting_states = limiters.ranking(d);

  // the integrals at the end: S.y and S.ys hold the solution at tf (the last output)
  std::vector<double> q(std::max(nq, 1), 0.0), dq(static_cast<size_t>(std::max(nq, 1)) * ns, 0.0);
  std::copy_n(NV_DATA_S(S.y) + nx, nq, q.data());
  if (ns > 0 && nq > 0) {
    check(CVodeGetSensDky(S.mem, t, 0, S.ys), "CVodeGetSensDky");
    for (int dir = 0; dir < ns; ++dir) std::copy_n(NV_DATA_S(S.ys[dir]) + nx, nq, dq.data() + dir * nq);
  }
  recorder.finish(q.data(), {dq.data(), std::max(nq, 1)});
  result.final_state.assign(NV_DATA_S(S.y), NV_DATA_S(S.y) + nx);

  st.rtol = d.solver.rtol;
  st.atol = d.solver.atol;
  st.max_order = d.solver.max_order > 0 ? d.solver.max_order : highest_order(d.solver.method);
  finish_stats(st, d.solver.method, clock.seconds(), d.time);
  return result;
}

}  // namespace dydp::engine
