// The adjoint method through the diagram (the continuous adjoint of CVODES' guide, ch. 2.6).
//
// The run's vector is y = [x; q]: states and objective integrals, y' = F(y) = [f(x, p); h(x, p)].
// An objective psi = G(q(T)) (rms, mean, integral: Objective::quadrature_gradient gives g =
// dG/dq) has the adjoint lambda_q = g constant and
//   lambda_x' = -(f_x^T lambda_x + h_x^T g),            lambda_x(T) = 0,
//   dpsi/dp   = lambda_x(t0)^T dx0/dp + integral over [t0, T] of (lambda_x^T f_p + g^T h_p) dt.
// Every product is the diagram's adjoint pass (Evaluator::adjoint), for all objectives at once:
// CVODES' backward vector holds one lambda_x per objective, and the gradient is its backward
// quadrature (sign: CVODES integrates qB' = -(...) from T down to t0, so qB(t0) is the integral).
// The backward Newton matrix is -f_x^T per objective, from the same coloured Jacobian as the
// forward one. The run stops at the blocks' breakpoints like the forward run (the right-hand side may
// jump there), and lambda_x is carried across them (it is continuous: x is).
//
// Checkpoints are dydp's own, not CVODES': the forward run is cut into chunks of about
// steps_between_checkpoints steps, each chunk a fresh CVODES problem from the state at its start
// (kept: the checkpoint). The backward run replays one chunk at a time from its checkpoint with
// CVodeF, storing every step of it (CVodeAdjInit's Nd above the chunk's steps, so CVODES makes no
// checkpoint of its own), and integrates lambda back over it. A replay is the same computation
// as the first pass (same start, same targets, a fresh solver), so it takes the same steps.
// CVODES' own recomputation from its checkpoints restarts with a fresh Newton matrix where the
// first pass had a kept one, can take more steps than it stored room for, and then writes past
// its array (SUNDIALS issue #49; it crashed the sedan's backward run).
#include "engine/analysis/cvodes_adjoint.hpp"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>
#include <sys/resource.h>

#include <cmath>
#include <memory>

#include "engine/analysis/cpu_clock.hpp"
#include "engine/analysis/cvodes_problem.hpp"
#include "engine/analysis/dense_lu_solver.hpp"
#include "engine/analysis/recorder.hpp"
#include "engine/analysis/sundials_kernels.hpp"
#include "engine/analysis/timeline.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/solver_methods.hpp"

namespace dydp::engine {
namespace {

using namespace cvodes;

/// What the backward callbacks need: the forward problem, the objectives' dG/dq and scratch.
struct Backward {
  explicit Backward(Problem& problem) : P(problem) {}
  Problem& P;
  int nm = 0;                 ///< objectives: adjoint directions
  int ns = 0;                 ///< sensitivity directions
  std::vector<double> g;      ///< dpsi_m/dq: nq x nm
  std::vector<double> ax, ap, jac;
  long rhs_passes = 0, quadrature_passes = 0, jac_passes = 0;
};

// lambda' = -(f_x^T lambda + h_x^T g), every objective's column at once
int backward_rhs(sunrealtype t, N_Vector y, N_Vector yB, N_Vector yBdot, void* user) {
  auto& B = *static_cast<Backward*>(user);
  Problem& P = B.P;
  return guarded(P, t, [&] {
    B.ax.assign(static_cast<size_t>(P.nx) * B.nm, 0.0);
    P.ev.adjoint(t, NV_DATA_S(y), B.nm, {NV_DATA_S(yB), P.nx}, {B.g.data(), std::max(P.nq, 1)},
                 {B.ax.data(), P.nx}, {});
    double* out = NV_DATA_S(yBdot);
    for (size_t i = 0; i < B.ax.size(); ++i) out[i] = -B.ax[i];
    ++B.rhs_passes;
  });
}

// qB' = -(lambda^T f_p + g^T h_p): qB(t0) is the integral of the gradient's integrand
int backward_quadrature(sunrealtype t, N_Vector y, N_Vector yB, N_Vector qBdot, void* user) {
  auto& B = *static_cast<Backward*>(user);
  Problem& P = B.P;
  return guarded(P, t, [&] {
    B.ap.assign(static_cast<size_t>(B.ns) * B.nm, 0.0);
    P.ev.adjoint(t, NV_DATA_S(y), B.nm, {NV_DATA_S(yB), P.nx}, {B.g.data(), std::max(P.nq, 1)}, {},
                 {B.ap.data(), B.ns});
    double* out = NV_DATA_S(qBdot);
    for (size_t i = 0; i < B.ap.size(); ++i) out[i] = -B.ap[i];
    ++B.quadrature_passes;
  });
}

// d(lambda')/d(lambda) = -f_x^T in each objective's diagonal block
int backward_jacobian(sunrealtype t, N_Vector y, N_Vector, N_Vector, SUNMatrix JB, void* user, N_Vector, N_Vector,
                      N_Vector) {
  auto& B = *static_cast<Backward*>(user);
  Problem& P = B.P;
  SUNMatZero(JB);
  return guarded(P, t, [&] {
    const int nx = P.nx, ld = nx + P.nq;
    B.jac.assign(static_cast<size_t>(ld) * nx, 0.0);
    P.colouring.evaluate(P.ev, t, NV_DATA_S(y), {B.jac.data(), ld}, {});
    const sunindextype ldb = SM_ROWS_D(JB);
    double* a = SM_DATA_D(JB);
    for (int m = 0; m < B.nm; ++m)
      for (int j = 0; j < nx; ++j)      // JB(i, j) = -f_x(j, i): column j of block m is row j of f_x
        for (int i = 0; i < nx; ++i) a[(m * nx + j) * ldb + m * nx + i] = -B.jac[static_cast<size_t>(i) * ld + j];
    ++B.jac_passes;
  });
}

/// A chunk of the forward run: from its checkpoint (start, y0) through the output and break
/// targets the first pass integrated to, in the segment between two breakpoints it belongs to.
struct Chunk {
  double segment_start = 0.0, segment_stop = 0.0;
  double start = 0.0;
  std::vector<double> y0;
  std::vector<double> targets;  ///< in (start, end], the last one the chunk's end
  long steps = 0;               ///< the first pass's steps over the chunk
};

/// One CVODES problem of the forward run (a chunk), and for its replay the backward problem.
struct Solver {
  void* mem = nullptr;
  ForwardSolvers forward;
  SUNMatrix AB = nullptr;
  SUNLinearSolver LSB = nullptr;
  SUNNonlinearSolver NLSB = nullptr;
  Solver() = default;
  Solver(const Solver&) = delete;
  Solver& operator=(const Solver&) = delete;
  ~Solver() {
    if (mem) CVodeFree(&mem);
    if (LSB) SUNLinSolFree(LSB);
    if (AB) SUNMatDestroy(AB);
    if (NLSB) SUNNonlinSolFree(NLSB);
  }
};

struct Context {
  SUNContext ctx = nullptr;
  ~Context() {
    if (ctx) SUNContext_Free(&ctx);
  }
};

/// One adjoint run: the forward problem, its chunks and the backward problem the steps share.
class AdjointRun {
 public:
  AdjointRun(const Diagram& d, const RunOptions& options)
      : d_(d), options_(options), bdf_(d.solver.method == "bdf"), nx_(d.num_states), nq_(d.num_quadratures),
        ns_(static_cast<int>(d.sensitivities.size())), nm_(static_cast<int>(d.objectives.size())),
        n_cv_(std::max(nx_ + nq_, 1)), t0_(d.time.start), tf_(d.time.stop), ev_(d, true),
        recorder_(d, 0, result_, options), P_(d, ev_, nx_, 0), timeline_(d), B_(P_) {}

  RunResult run() {
    set_up_states();
    first_pass();
    finish_forward();
    if (nm_ > 0 && ns_ > 0) backward_pass();
    struct rusage usage {};
    if (getrusage(RUSAGE_SELF, &usage) == 0)
      result_.stats.adjoint.peak_rss_bytes = 1024.0 * static_cast<double>(usage.ru_maxrss);

    finish_cvodes_stats(result_.stats, d_, clock_.seconds());
    return std::move(result_);
  }

 private:
  void check(int flag, const char* call, double t) const { check_call(P_, flag, call, t); }

  // The initial state [x(t0); 0], its tolerances, the segments between breakpoints, the adjoint's
  // statistics so far and the outputs at t0.
  void set_up_states() {
    check(SUNContext_Create(nullptr, &C_.ctx), "SUNContext_Create", t0_);
    y_ = OwnedVector(N_VNew_Serial(n_cv_, C_.ctx));
    N_VEnableFusedOps_Serial(y_.v, SUNTRUE);
    use_compiled_vector_kernels(y_.v);
    N_VConst(0.0, y_.v);
    ev_.set_segment_start(t0_);
    ev_.initial_state(t0_, NV_DATA_S(y_.v));
    x0_.assign(NV_DATA_S(y_.v), NV_DATA_S(y_.v) + nx_);

    atols_ = absolute_tolerances(d_, d_.solver.atol, 0);
    atol_states_ = OwnedVector(state_tolerances(P_, atols_, d_.solver.atol, y_.v));

    bounds_ = {t0_};
    for (double b : timeline_.breaks)
      if (b < tf_) bounds_.push_back(b);
    bounds_.push_back(tf_);

    AdjointStats& as = result_.stats.adjoint;
    as.used = true;
    as.objectives = nm_;
    as.steps_between_checkpoints = options_.steps_between_checkpoints;
    as.segments = static_cast<int>(bounds_.size()) - 1;
    record(t0_);
  }

  // The outputs at t (y_ holds the state there).
  void record(double t) {
    ev_.outputs(t, NV_DATA_S(y_.v));
    recorder_.record(t, NV_DATA_S(y_.v), ev_);
  }

  // A fresh forward problem from (start, y) with the run's settings, stopping at the segment's end.
  void open_forward(Solver& S, const Chunk& c) {
    ev_.set_segment_start(c.segment_start);
    S.mem = CVodeCreate(bdf_ ? CV_BDF : CV_ADAMS, C_.ctx);
    if (!S.mem) throw SolverError(c.start, "", "CVodeCreate failed");
    set_up_forward(P_, S.mem, C_.ctx, c.start, y_.v, atol_states_.v, S.forward);
    check(CVodeSetStopTime(S.mem, c.segment_stop), "CVodeSetStopTime", c.start);
  }

  // CVODES' counters of one forward problem added to the run's statistics.
  // The forward run over every segment, cut into chunks, and its statistics.
  void first_pass() {
    const bool backward = nm_ > 0 && ns_ > 0;
    const long chunk_steps = std::max(options_.steps_between_checkpoints, 1);

    // the first pass: the outputs, and a checkpoint every chunk_steps steps (at an output time)
    size_t next_event = 0;
    for (size_t k = 0; k + 1 < bounds_.size(); ++k) {
      Chunk c;
      c.segment_start = c.start = bounds_[k];
      c.segment_stop = bounds_[k + 1];
      c.y0.assign(NV_DATA_S(y_.v), NV_DATA_S(y_.v) + n_cv_);
      auto S = std::make_unique<Solver>();
      open_forward(*S, c);
      while (next_event < timeline_.events.size() && timeline_.events[next_event] <= c.segment_stop) {
        const double target = timeline_.events[next_event++];
        double reached = c.start;
        check(CVode(S->mem, target, y_.v, &reached, CV_NORMAL), "CVode", reached);
        c.targets.push_back(target);
        if (timeline_.is_output(target)) record(target);
        long steps = 0;
        CVodeGetNumSteps(S->mem, &steps);
        if (backward && steps >= chunk_steps && target < c.segment_stop) {
          c.steps = steps;
          add_cvodes_counters(S->mem, bdf_, result_.stats);
          chunks_.push_back(c);
          c.start = target;
          c.targets.clear();
          c.y0.assign(NV_DATA_S(y_.v), NV_DATA_S(y_.v) + n_cv_);
          S = std::make_unique<Solver>();
          open_forward(*S, c);
        }
      }
      CVodeGetNumSteps(S->mem, &c.steps);
      add_cvodes_counters(S->mem, bdf_, result_.stats);
      if (!c.targets.empty()) chunks_.push_back(std::move(c));
    }
    RunStats& st = result_.stats;
    st.adjoint.checkpoints = static_cast<long>(chunks_.size());
    st.adjoint.forward_steps = st.steps;
    st.local_jac_evals = P_.local_refreshes;
    st.jacobian_colours = P_.colouring.colours();
    st.adjoint.forward_cpu_seconds = clock_.seconds();
  }

  // The objectives' values at the end, the final state and the (zero) gradients' layout.
  void finish_forward() {
    // the objectives' values and dG/dq at the end
    q_.assign(std::max(nq_, 1), 0.0);
    std::copy_n(NV_DATA_S(y_.v) + nx_, nq_, q_.data());
    recorder_.finish(q_.data(), {});
    result_.final_state.assign(NV_DATA_S(y_.v), NV_DATA_S(y_.v) + nx_);
    for (int dir = 0; dir < ns_; ++dir)
      result_.sensitivity_names.push_back(d_.parameters[d_.sensitivities[dir]].name);
    result_.signal_sensitivities = false;
    for (auto& o : result_.objectives) o.sensitivity.assign(ns_, 0.0);
  }

  // The objectives' dG/dq and the backward problem's vectors with their tolerances.
  void set_up_backward() {
    B_.nm = nm_, B_.ns = ns_;
    B_.g.assign(static_cast<size_t>(std::max(nq_, 1)) * nm_, 0.0);
    ObjectiveSamples samples;
    samples.t_start = t0_, samples.t_stop = tf_;
    std::vector<double> scale(nm_, 1.0);  // each objective's magnitude, for the tolerances
    for (int m = 0; m < nm_; ++m) {
      const Node& n = d_.nodes[d_.objectives[m]];
      const int nqn = n.block->num_quadratures();
      if (nqn > 0 && !n.objective->quadrature_gradient(n.p.data(), q_.data() + n.quad_offset, nqn, samples,
                                                       B_.g.data() + static_cast<size_t>(m) * nq_ + n.quad_offset))
        throw InputError(n.file.empty() ? d_.file : n.file, n.line, n.name, "objective " + n.name + " has no adjoint");
      const double psi = std::fabs(result_.objectives[m].value);
      if (psi > 0 && std::isfinite(psi)) scale[m] = psi;
    }
    nb_ = nx_ * nm_;
    // tolerances: the gradient ~ psi / |p| (the forward run's pbar); lambda_i is the change of psi
    // for a unit change of state i at time t, lambda_i ~ psi / nominal_i at most. Most states
    // (pressures, wheel hop) move psi by a small fraction of it for a nominal-sized change, so
    // lambda's atol is 1/100 of that bound: on the quarter car at rtol = atol = 1e-9 the
    // gradients are 7e-6 off the converged ones with the bound itself, 8e-7 with 1/10 and 2e-7
    // with 1/100 (for 50 % more backward time; docs/engine.md, Adjoint).
    constexpr double kLambdaAtolFraction = 0.01;
    const std::vector<double> nominal = state_nominals(d_);
    lambda_ = OwnedVector(N_VNew_Serial(std::max(nb_, 1), C_.ctx));
    atol_b_ = OwnedVector(N_VNew_Serial(std::max(nb_, 1), C_.ctx));
    atol_q_ = OwnedVector(N_VNew_Serial(ns_ * nm_, C_.ctx));
    N_VConst(0.0, lambda_.v);
    N_VConst(d_.solver.atol, atol_b_.v);
    for (int m = 0; m < nm_; ++m) {
      for (int i = 0; i < nx_; ++i)
        NV_Ith_S(atol_b_.v, m * nx_ + i) =
            kLambdaAtolFraction * d_.solver.atol * scale[m] / (d_.solver.nominal_scaling ? nominal[i] : 1.0);
      for (int dir = 0; dir < ns_; ++dir) {
        const double p = std::fabs(d_.parameters[d_.sensitivities[dir]].value);
        NV_Ith_S(atol_q_.v, m * ns_ + dir) = d_.solver.atol * scale[m] / (p > 0 ? p : 1.0);
      }
    }
    gradient_.assign(static_cast<size_t>(ns_) * nm_, 0.0);
    qB_ = OwnedVector(N_VNew_Serial(ns_ * nm_, C_.ctx));
  }

  // The gradients: lambda back over the chunks, last first, then the initial state's term.
  void backward_pass() {
    set_up_backward();
    AdjointStats& as = result_.stats.adjoint;
    const CpuClock backward_clock;
    for (size_t k = chunks_.size(); k-- > 0;) {
      const Chunk& c = chunks_[k];
      Solver S;
      replay(S, c);
      integrate_back(S, c);
    }
    add_initial_state_term();
    as.backward_rhs_evals = B_.rhs_passes;
    as.backward_quadrature_evals = B_.quadrature_passes;
    as.backward_jac_evals = B_.jac_passes;
    as.backward_cpu_seconds = backward_clock.seconds();
    // held: each checkpoint's state, and for the chunk being worked on y and y' at each of its
    // steps (Hermite), in room for the most steps of a chunk
    as.checkpoint_bytes = 8.0 * n_cv_ * (static_cast<double>(as.checkpoints) + 2.0 * (most_steps_ + 1));
  }

  // Replays chunk c on S (CVodeF) for the backward run and counts the replay's steps.
  void replay(Solver& S, const Chunk& c) {
    AdjointStats& as = result_.stats.adjoint;
    // the chunk's forward run again from its checkpoint, every step stored
    std::copy(c.y0.begin(), c.y0.end(), NV_DATA_S(y_.v));
    open_forward(S, c);
    void* mem = S.mem;
    const long room = c.steps + std::max(16L, c.steps / 4);
    most_steps_ = std::max(most_steps_, room);
    check(CVodeAdjInit(mem, room, CV_HERMITE), "CVodeAdjInit", c.start);
    double reached = c.start;
    for (double target : c.targets) {
      int ncheck = 0;
      check(CVodeF(mem, target, y_.v, &reached, CV_NORMAL, &ncheck), "CVodeF", reached);
    }
    long replayed = 0;
    CVodeGetNumSteps(mem, &replayed);
    as.replay_steps += replayed;
    if (replayed != c.steps) ++as.replays_differing;
  }

  // lambda and the gradient's quadrature integrated back over the chunk replayed on S.
  void integrate_back(Solver& S, const Chunk& c) {
    void* mem = S.mem;
    // lambda back over the chunk
    const double te = c.targets.back();
    int which = 0;
    check(CVodeCreateB(mem, bdf_ ? CV_BDF : CV_ADAMS, &which), "CVodeCreateB", te);
    check(CVodeInitB(mem, which, backward_rhs, te, lambda_.v), "CVodeInitB", te);
    check(CVodeSetUserDataB(mem, which, &B_), "CVodeSetUserDataB", te);
    check(CVodeSVtolerancesB(mem, which, d_.solver.rtol, atol_b_.v), "CVodeSVtolerancesB", te);
    check(CVodeSetMaxNumStepsB(mem, which, d_.solver.max_steps), "CVodeSetMaxNumStepsB", te);
    if (d_.solver.max_order > 0) check(CVodeSetMaxOrdB(mem, which, d_.solver.max_order), "CVodeSetMaxOrdB", te);
    if (bdf_) {
      S.AB = SUNDenseMatrix(std::max(nb_, 1), std::max(nb_, 1), C_.ctx);
      S.LSB = SUNLinSol_Dense(lambda_.v, S.AB, C_.ctx);
      check(CVodeSetLinearSolverB(mem, which, S.LSB, S.AB), "CVodeSetLinearSolverB", te);
      check(CVodeSetJacFnB(mem, which, backward_jacobian), "CVodeSetJacFnB", te);
    } else {
      S.NLSB = SUNNonlinSol_FixedPoint(lambda_.v, 0, C_.ctx);
      check(CVodeSetNonlinearSolverB(mem, which, S.NLSB), "CVodeSetNonlinearSolverB", te);
    }
    N_VConst(0.0, qB_.v);
    check(CVodeQuadInitB(mem, which, backward_quadrature, qB_.v), "CVodeQuadInitB", te);
    check(CVodeQuadSVtolerancesB(mem, which, d_.solver.rtol, atol_q_.v), "CVodeQuadSVtolerancesB", te);
    check(CVodeSetQuadErrConB(mem, which, SUNTRUE), "CVodeSetQuadErrConB", te);
    check(CVodeB(mem, c.start, CV_NORMAL), "CVodeB", te);
    double tret = 0.0;
    check(CVodeGetB(mem, which, &tret, lambda_.v), "CVodeGetB", c.start);
    check(CVodeGetQuadB(mem, which, &tret, qB_.v), "CVodeGetQuadB", c.start);
    for (int i = 0; i < ns_ * nm_; ++i) gradient_[i] += NV_Ith_S(qB_.v, i);
    void* memB = CVodeGetAdjCVodeBmem(mem, which);
    long v = 0;
    CVodeGetNumSteps(memB, &v), result_.stats.adjoint.backward_steps += v;
  }

  // The term lambda(t0)^T dx0/dp added, and the gradients checked and stored in the objectives.
  void add_initial_state_term() {
    // lambda(t0)^T dx0/dp
    ev_.set_segment_start(t0_);
    ev_.initial_state_adjoint(t0_, x0_.data(), nm_, {NV_DATA_S(lambda_.v), nx_}, {gradient_.data(), ns_});
    for (int m = 0; m < nm_; ++m)
      for (int dir = 0; dir < ns_; ++dir) {
        const double g = gradient_[static_cast<size_t>(m) * ns_ + dir];
        if (!std::isfinite(g))
          throw SolverError(t0_, result_.objectives[m].name, "the adjoint gradient is not finite (direction " +
                                                                 d_.parameters[d_.sensitivities[dir]].name + ")");
        result_.objectives[m].sensitivity[dir] = g;
      }
  }

  const Diagram& d_;
  const RunOptions& options_;
  const bool bdf_;
  const int nx_, nq_, ns_, nm_, n_cv_;
  const double t0_, tf_;
  const CpuClock clock_;
  Evaluator ev_;
  RunResult result_;
  Recorder recorder_;
  Problem P_;
  Context C_;
  OwnedVector y_;
  std::vector<double> x0_;
  AbsoluteTolerances atols_;
  OwnedVector atol_states_;
  const Timeline timeline_;
  std::vector<double> bounds_;  // t0, the breakpoints before tf, tf
  std::vector<Chunk> chunks_;
  std::vector<double> q_;       // the objective integrals at the end
  Backward B_;
  int nb_ = 0;                  // lambda's entries: nx per objective
  OwnedVector lambda_, atol_b_, atol_q_, qB_;
  std::vector<double> gradient_;  // d(psi_m)/dp: ns x nm
  long most_steps_ = 0;           // the most steps stored for a chunk
};

}  // namespace

void check_adjoint_possible(const Diagram& d) {
  if (d.solver.method != "bdf" && d.solver.method != "adams")
    throw InputError(d.file, 0, "--adjoint",
                     "the adjoint method runs with CVODES only; the solver is " + d.solver.method +
                         " (a fixed-step method, whose discrete adjoint dydp does not have): use --solver bdf");
  for (int o : d.objectives) {
    const Node& n = d.nodes[o];
    if (n.objective->needs_samples())
      throw InputError(n.file.empty() ? d.file : n.file, n.line, n.name,
                       "objective " + n.name + " (" + n.type->name +
                           ") has no adjoint: it reads the output samples, not integrals; run it without --adjoint "
                           "or leave it out of the outputs");
  }
}

RunResult run_cvodes_adjoint(const Diagram& d, const RunOptions& options) {
  check_adjoint_possible(d);
  return AdjointRun(d, options).run();
}

}  // namespace dydp::engine
