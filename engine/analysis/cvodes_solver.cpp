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
#include "engine/analysis/cvodes_problem.hpp"
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

using namespace cvodes;


/// Owns the SUNDIALS objects of one run and releases them in the right order.
struct Sundials {
  SUNContext ctx = nullptr;
  void* mem = nullptr;
  N_Vector y = nullptr;
  N_Vector* ys = nullptr;
  int ns = 0;
  ForwardSolvers forward;
  SUNNonlinearSolver NLSsens = nullptr;

  ~Sundials() {
    if (mem) CVodeFree(&mem);
    if (ys) N_VDestroyVectorArray(ys, ns);
    if (y) N_VDestroy(y);
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
  auto check = [&](int flag, const char* call) { check_call(P, flag, call, t0); };
  check(SUNContext_Create(nullptr, &S.ctx), "SUNContext_Create");
  S.y = N_VNew_Serial(n_cv, S.ctx);
  N_VEnableFusedOps_Serial(S.y, SUNTRUE);  // fewer passes over the sensitivity vectors
  use_compiled_vector_kernels(S.y);         // before CVodeInit: CVODES clones its vectors from y
  N_VConst(0.0, S.y);
  ev.set_segment_start(t0);
  ev.initial_state(t0, NV_DATA_S(S.y));

  S.mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, S.ctx);
  if (!S.mem) throw SolverError(t0, "", "CVodeCreate failed");
  // One absolute tolerance per state: atol times its nominal magnitude (a pressure in Pa, a
  // position in m, a flow in m^3/s each judged in its own units).
  const AbsoluteTolerances atols = absolute_tolerances(d, d.solver.atol, ns);
  const OwnedVector atol_states(state_tolerances(P, atols, d.solver.atol, S.y));  // CVODES keeps a copy
  set_up_forward(P, S.mem, S.ctx, t0, S.y, atol_states.v, S.forward);

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

  finish_cvodes_stats(st, d, clock.seconds());
  return result;
}

}  // namespace dydp::engine
