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
  N_Vector local_errors = nullptr, weights = nullptr;  ///< CVODES' estimates after a step

  ~Sundials() {
    if (local_errors) N_VDestroy(local_errors);
    if (weights) N_VDestroy(weights);
    if (mem) CVodeFree(&mem);
    if (ys) N_VDestroyVectorArray(ys, ns);
    if (y) N_VDestroy(y);
    if (NLSsens) SUNNonlinSolFree(NLSsens);
    if (ctx) SUNContext_Free(&ctx);
  }
};

/// One run: the SUNDIALS objects and what the steps of the run share.
class CvodesRun {
 public:
  CvodesRun(const Diagram& d, const RunOptions& options)
      : d_(d), bdf_(d.solver.method == "bdf"), nx_(d.num_states), nq_(d.num_quadratures),
        ns_(options.sensitivities ? static_cast<int>(d.sensitivities.size()) : 0), t0_(d.time.start),
        ev_(d, ns_ > 0), recorder_(d, ns_, result_, options), P_(d, ev_, nx_, ns_) {
    S_.ns = ns_;
  }

  RunResult run(const RunOptions& options) {
    set_up_states();
    if (ns_ > 0) set_up_sensitivities(options);
    record(t0_);
    march();
    finish();
    return std::move(result_);
  }

 private:
  void check(int flag, const char* call) const { check_call(P_, flag, call, t0_); }

  // The initial state [x(t0); 0] and the CVODES integrator with its tolerances.
  void set_up_states() {
    const int n_cv = std::max(nx_ + nq_, 1);  // [x; q]
    check(SUNContext_Create(nullptr, &S_.ctx), "SUNContext_Create");
    S_.y = N_VNew_Serial(n_cv, S_.ctx);
    N_VEnableFusedOps_Serial(S_.y, SUNTRUE);  // fewer passes over the sensitivity vectors
    use_compiled_vector_kernels(S_.y);         // before CVodeInit: CVODES clones its vectors from y
    N_VConst(0.0, S_.y);
    ev_.set_segment_start(t0_);
    ev_.initial_state(t0_, NV_DATA_S(S_.y));

    S_.mem = CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, S_.ctx);
    if (!S_.mem) throw SolverError(t0_, "", "CVodeCreate failed");
    // One absolute tolerance per state: atol times its nominal magnitude (a pressure in Pa, a
    // position in m, a flow in m^3/s each judged in its own units).
    atols_ = absolute_tolerances(d_, d_.solver.atol, ns_);
    const OwnedVector atol_states(state_tolerances(P_, atols_, d_.solver.atol, S_.y));  // CVODES keeps a copy
    set_up_forward(P_, S_.mem, S_.ctx, t0_, S_.y, atol_states.v, S_.forward);
  }

  // The sensitivities: their initial values, right-hand side and tolerances.
  void set_up_sensitivities(const RunOptions& options) {
    S_.ys = N_VCloneVectorArray(ns_, S_.y);
    std::vector<double> dx0(static_cast<size_t>(nx_) * ns_, 0.0);
    ev_.initial_state_tangent(t0_, NV_DATA_S(S_.y), {dx0.data(), nx_});
    for (int dir = 0; dir < ns_; ++dir) N_VConst(0.0, S_.ys[dir]);
    if (nx_ > 0) scatter(dx0, nx_, ns_, S_.ys);
    if (options.difference_quotient_sensitivities) {
      for (const auto& p : d_.parameters) P_.scene_values.push_back(p.value);
      std::vector<int> plist(d_.sensitivities.begin(), d_.sensitivities.end());
      std::vector<double> pbar;
      for (int i : d_.sensitivities) pbar.push_back(std::fabs(d_.parameters[i].value) > 0 ? std::fabs(d_.parameters[i].value) : 1.0);
      check(CVodeSensInit(S_.mem, ns_, CV_SIMULTANEOUS, nullptr, S_.ys), "CVodeSensInit");
      check(CVodeSetSensParams(S_.mem, P_.scene_values.data(), pbar.data(), plist.data()), "CVodeSetSensParams");
    } else {
      check(CVodeSensInit(S_.mem, ns_, CV_SIMULTANEOUS, sens_rhs, S_.ys), "CVodeSensInit");
    }
    // Sensitivity tolerances: the states' ones over the parameter's value (the pbar of CVODES'
    // guide), so dx/dk for a stiffness of 1e5 N/m is held to the same relative accuracy as dx/dm.
    N_Vector* atol_sens = sensitivity_tolerances(atols_, nx_, nq_, ns_, d_.solver.atol, S_.y);
    const int ssv_flag = CVodeSensSVtolerances(S_.mem, d_.solver.rtol, atol_sens);
    N_VDestroyVectorArray(atol_sens, ns_);
    check(ssv_flag, "CVodeSensSVtolerances");
    check(CVodeSetSensErrCon(S_.mem, d_.solver.sens_error_test), "CVodeSetSensErrCon");
    if (!bdf_) {
      S_.NLSsens = SUNNonlinSol_FixedPointSens(ns_ + 1, S_.y, 0, S_.ctx);
      check(CVodeSetNonlinearSolverSensSim(S_.mem, S_.NLSsens), "CVodeSetNonlinearSolverSensSim");
    }
  }

  // CVODES' counters of the segment just integrated added to the run's statistics.
  void accumulate() {
    RunStats& st = result_.stats;
    add_cvodes_counters(S_.mem, bdf_, st);
    st.local_jac_evals = P_.local_refreshes;
    st.jacobian_colours = P_.colouring.colours();
  }

  // The outputs at t (S_.y holds the state there; the sensitivities are interpolated).
  void record(double t) {
    std::vector<double> dx;
    if (ns_ > 0) {
      sunrealtype tret = t;
      if (t > t0_) check(CVodeGetSensDky(S_.mem, tret, 0, S_.ys), "CVodeGetSensDky");
      gather(S_.ys, nx_, ns_, dx);
      ev_.tangents(t, NV_DATA_S(S_.y), ns_, {dx.data(), nx_}, true, {}, {});
    } else {
      ev_.outputs(t, NV_DATA_S(S_.y));
    }
    recorder_.record(t, NV_DATA_S(S_.y), ev_);
  }

  // A failed step as a SolverError naming the state CVODES could not hold to its tolerance (the
  // largest weighted local error) and the last point a block refused.
  [[noreturn]] void fail(int flag, double t, std::string reason) {
    if (!P_.cvodes_message.empty()) reason += " (" + P_.cvodes_message + ")";
    std::string block;
    if (flag == CV_ERR_FAILURE || flag == CV_CONV_FAILURE || flag == CV_TOO_MUCH_WORK) {
      if (CVodeGetEstLocalErrors(S_.mem, S_.local_errors) == CV_SUCCESS &&
          CVodeGetErrWeights(S_.mem, S_.weights) == CV_SUCCESS) {
        int worst = -1;
        double largest = -1.0;
        for (int i = 0; i < nx_; ++i) {
          const double e = std::fabs(NV_Ith_S(S_.local_errors, i) * NV_Ith_S(S_.weights, i));
          if (e > largest) largest = e, worst = i;
        }
        for (const Node& n : d_.nodes)
          if (worst >= n.state_offset && worst < n.state_offset + n.block->num_states()) {
            block = n.name;
            reason += "; largest estimated local error in state " +
                      n.block->state_names()[worst - n.state_offset];
          }
      }
    }
    if (!P_.refusal.empty()) {
      block = P_.refusal.substr(0, P_.refusal.find(':'));
      reason += "; last refused point at t = " + std::to_string(P_.refusal_t) + " s: " + P_.refusal;
    }
    throw SolverError(t, block, reason);
  }

  // Steps up to `target` (not past `stop`, set as CVODES' stop time), one at a time, so that
  // after each accepted step the state with the largest weighted local error is counted
  // (StepLimiters). Returns whether the last step ended at target.
  bool step_to(double target, StepLimiters& limiters) {
    RunStats& st = result_.stats;
    long interval_steps = 0;
    bool at_target = false;  // S_.y holds the solution at target (a step ended there)
    while (reached_ < target) {
      if (++interval_steps > d_.solver.max_steps)
        fail(CV_TOO_MUCH_WORK, reached_,
             "CVode failed: CV_TOO_MUCH_WORK (" + std::to_string(d_.solver.max_steps) +
                 " steps taken before reaching the next output time " + format_number(target) + " s)");
      const int flag = CVode(S_.mem, target, S_.y, &reached_, CV_ONE_STEP);
      if (flag < 0) fail(flag, reached_, std::string("CVode failed: ") + flag_name(flag));
      if (nx_ + nq_ > 0 && CVodeGetEstLocalErrors(S_.mem, S_.local_errors) == CV_SUCCESS &&
          CVodeGetErrWeights(S_.mem, S_.weights) == CV_SUCCESS)
        limiters.add_step(NV_DATA_S(S_.local_errors), NV_DATA_S(S_.weights));
      if (int order = 0; CVodeGetLastOrder(S_.mem, &order) == CV_SUCCESS && order >= 1) {
        if (st.steps_per_order.size() < static_cast<size_t>(order)) st.steps_per_order.resize(order, 0);
        ++st.steps_per_order[order - 1];
      }
      at_target = reached_ == target;
    }
    return at_target;
  }

  // Record at t0, then march over outputs and breakpoints; restart CVODES after each breakpoint
  // since the right-hand side may jump there. Outputs are interpolated (CVodeGetDky) as CVODES'
  // normal mode does, from the same steps.
  void march() {
    const double tf = d_.time.stop;
    const Timeline timeline(d_);
    const std::vector<double>& breaks = timeline.breaks;
    StepLimiters limiters(nx_ + nq_);
    S_.local_errors = N_VClone(S_.y);
    S_.weights = N_VClone(S_.y);
    t_ = t0_;
    reached_ = t0_;
    size_t next_break = 0;
    for (double target : timeline.events) {
      while (next_break < breaks.size() && breaks[next_break] < target) ++next_break;
      const double stop = next_break < breaks.size() ? breaks[next_break] : tf;
      check(CVodeSetStopTime(S_.mem, stop), "CVodeSetStopTime");
      // Unless a step ended at target, the last step went past it, in this interval or an
      // earlier one (it may have ended exactly on the next output): interpolate.
      if (!step_to(target, limiters)) check(CVodeGetDky(S_.mem, target, 0, S_.y), "CVodeGetDky");
      t_ = target;
      if (timeline.is_output(target)) record(target);
      if (next_break < breaks.size() && breaks[next_break] == target && target < tf) {
        accumulate();
        ev_.set_segment_start(target);
        // The solution at the breakpoint (the last step ended there: it is the stop time) first,
        // then the restart from it.
        if (ns_ > 0) check(CVodeGetSensDky(S_.mem, target, 0, S_.ys), "CVodeGetSensDky");
        check(CVodeReInit(S_.mem, target, S_.y), "CVodeReInit");
        reached_ = target;
        if (ns_ > 0) check(CVodeSensReInit(S_.mem, CV_SIMULTANEOUS, S_.ys), "CVodeSensReInit");
        t_ = target;
      }
    }
    accumulate();
    result_.stats.sens_rhs_evals = P_.sens_passes;
    result_.stats.limiting_states = limiters.ranking(d_);
  }

  // The integrals and their sensitivities at the end (S_.y and S_.ys hold the solution at tf,
  // the last output), the final state and the statistics.
  void finish() {
    std::vector<double> q(std::max(nq_, 1), 0.0), dq(static_cast<size_t>(std::max(nq_, 1)) * ns_, 0.0);
    std::copy_n(NV_DATA_S(S_.y) + nx_, nq_, q.data());
    if (ns_ > 0 && nq_ > 0) {
      check(CVodeGetSensDky(S_.mem, t_, 0, S_.ys), "CVodeGetSensDky");
      for (int dir = 0; dir < ns_; ++dir) std::copy_n(NV_DATA_S(S_.ys[dir]) + nx_, nq_, dq.data() + dir * nq_);
    }
    recorder_.finish(q.data(), {dq.data(), std::max(nq_, 1)});
    result_.final_state.assign(NV_DATA_S(S_.y), NV_DATA_S(S_.y) + nx_);
    finish_cvodes_stats(result_.stats, d_, clock_.seconds());
  }

  const Diagram& d_;
  const bool bdf_;
  const int nx_, nq_, ns_;
  const double t0_;
  Evaluator ev_;
  RunResult result_;
  Recorder recorder_;
  Problem P_;
  const CpuClock clock_;
  Sundials S_;
  AbsoluteTolerances atols_;
  double t_ = 0.0;        // the last output or breakpoint reached
  double reached_ = 0.0;  // CVODES' internal time: the end of its last step
};

}  // namespace

RunResult run_cvodes(const Diagram& d, const RunOptions& options) { return CvodesRun(d, options).run(options); }

}  // namespace dydp::engine
