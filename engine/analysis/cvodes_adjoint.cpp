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
  const bool bdf = d.solver.method == "bdf";
  const int nx = d.num_states, nq = d.num_quadratures;
  const int ns = static_cast<int>(d.sensitivities.size());
  const int nm = static_cast<int>(d.objectives.size());
  const int n_cv = std::max(nx + nq, 1);
  const double t0 = d.time.start, tf = d.time.stop;
  const CpuClock clock;

  Evaluator ev(d, true);
  RunResult result;
  Recorder recorder(d, 0, result, options);
  Problem P(d, ev, nx, 0);
  Context C;
  auto check = [&](int flag, const char* call, double t) { check_call(P, flag, call, t); };
  check(SUNContext_Create(nullptr, &C.ctx), "SUNContext_Create", t0);
  OwnedVector y(N_VNew_Serial(n_cv, C.ctx));
  N_VEnableFusedOps_Serial(y.v, SUNTRUE);
  use_compiled_vector_kernels(y.v);
  N_VConst(0.0, y.v);
  ev.set_segment_start(t0);
  ev.initial_state(t0, NV_DATA_S(y.v));
  const std::vector<double> x0(NV_DATA_S(y.v), NV_DATA_S(y.v) + nx);

  const AbsoluteTolerances atols = absolute_tolerances(d, d.solver.atol, 0);
  OwnedVector atol_states(state_tolerances(P, atols, d.solver.atol, y.v));

  const Timeline timeline(d);
  std::vector<double> bounds = {t0};
  for (double b : timeline.breaks)
    if (b < tf) bounds.push_back(b);
  bounds.push_back(tf);

  RunStats& st = result.stats;
  AdjointStats& as = st.adjoint;
  as.used = true;
  as.objectives = nm;
  as.steps_between_checkpoints = options.steps_between_checkpoints;
  as.segments = static_cast<int>(bounds.size()) - 1;
  auto record = [&](double t) {
    ev.outputs(t, NV_DATA_S(y.v));
    recorder.record(t, NV_DATA_S(y.v), ev);
  };
  record(t0);

  // A fresh forward problem from (start, y) with the run's settings, stopping at the segment's end.
  auto open_forward = [&](Solver& S, const Chunk& c) {
    ev.set_segment_start(c.segment_start);
    S.mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, C.ctx);
    if (!S.mem) throw SolverError(c.start, "", "CVodeCreate failed");
    set_up_forward(P, S.mem, C.ctx, c.start, y.v, atol_states.v, S.forward);
    check(CVodeSetStopTime(S.mem, c.segment_stop), "CVodeSetStopTime", c.start);
  };
  auto add_forward_stats = [&](void* mem) {
    long v = 0;
    CVodeGetNumSteps(mem, &v), st.steps += v;
    CVodeGetNumRhsEvals(mem, &v), st.rhs_evals += v;
    CVodeGetNumErrTestFails(mem, &v), st.error_test_failures += v;
    CVodeGetNumNonlinSolvIters(mem, &v), st.nonlinear_iterations += v;
    CVodeGetNumNonlinSolvConvFails(mem, &v), st.nonlinear_failures += v;
    if (bdf) CVodeGetNumJacEvals(mem, &v), st.jac_evals += v;
  };
  const bool backward = nm > 0 && ns > 0;
  const long chunk_steps = std::max(options.steps_between_checkpoints, 1);

  // the first pass: the outputs, and a checkpoint every chunk_steps steps (at an output time)
  std::vector<Chunk> chunks;
  size_t next_event = 0;
  for (size_t k = 0; k + 1 < bounds.size(); ++k) {
    Chunk c;
    c.segment_start = c.start = bounds[k];
    c.segment_stop = bounds[k + 1];
    c.y0.assign(NV_DATA_S(y.v), NV_DATA_S(y.v) + n_cv);
    auto S = std::make_unique<Solver>();
    open_forward(*S, c);
    while (next_event < timeline.events.size() && timeline.events[next_event] <= c.segment_stop) {
      const double target = timeline.events[next_event++];
      double reached = c.start;
      check(CVode(S->mem, target, y.v, &reached, CV_NORMAL), "CVode", reached);
      c.targets.push_back(target);
      if (timeline.is_output(target)) record(target);
      long steps = 0;
      CVodeGetNumSteps(S->mem, &steps);
      if (backward && steps >= chunk_steps && target < c.segment_stop) {
        c.steps = steps;
        add_forward_stats(S->mem);
        chunks.push_back(c);
        c.start = target;
        c.targets.clear();
        c.y0.assign(NV_DATA_S(y.v), NV_DATA_S(y.v) + n_cv);
        S = std::make_unique<Solver>();
        open_forward(*S, c);
      }
    }
    CVodeGetNumSteps(S->mem, &c.steps);
    add_forward_stats(S->mem);
    if (!c.targets.empty()) chunks.push_back(std::move(c));
  }
  as.checkpoints = static_cast<long>(chunks.size());
  as.forward_steps = st.steps;
  st.local_jac_evals = P.local_refreshes;
  st.jacobian_colours = P.colouring.colours();
  as.forward_cpu_seconds = clock.seconds();

  // the objectives' values and dG/dq at the end
  std::vector<double> q(std::max(nq, 1), 0.0);
  std::copy_n(NV_DATA_S(y.v) + nx, nq, q.data());
  recorder.finish(q.data(), {});
  result.final_state.assign(NV_DATA_S(y.v), NV_DATA_S(y.v) + nx);
  for (int dir = 0; dir < ns; ++dir) result.sensitivity_names.push_back(d.parameters[d.sensitivities[dir]].name);
  result.signal_sensitivities = false;
  for (auto& o : result.objectives) o.sensitivity.assign(ns, 0.0);

  if (nm > 0 && ns > 0) {
    Backward B(P);
    B.nm = nm, B.ns = ns;
    B.g.assign(static_cast<size_t>(std::max(nq, 1)) * nm, 0.0);
    ObjectiveSamples samples;
    samples.t_start = t0, samples.t_stop = tf;
    std::vector<double> scale(nm, 1.0);  // each objective's magnitude, for the tolerances
    for (int m = 0; m < nm; ++m) {
      const Node& n = d.nodes[d.objectives[m]];
      const int nqn = n.block->num_quadratures();
      if (nqn > 0 && !n.objective->quadrature_gradient(n.p.data(), q.data() + n.quad_offset, nqn, samples,
                                                       B.g.data() + static_cast<size_t>(m) * nq + n.quad_offset))
        throw InputError(n.file.empty() ? d.file : n.file, n.line, n.name, "objective " + n.name + " has no adjoint");
      const double psi = std::fabs(result.objectives[m].value);
      if (psi > 0 && std::isfinite(psi)) scale[m] = psi;
    }
    const int nb = nx * nm;
    // tolerances: the gradient ~ psi / |p| (the forward run's pbar); lambda_i is the change of psi
    // for a unit change of state i at time t, lambda_i ~ psi / nominal_i at most. Most states
    // (pressures, wheel hop) move psi by a small fraction of it for a nominal-sized change, so
    // lambda's atol is 1/100 of that bound: on the quarter car at rtol = atol = 1e-9 the
    // gradients are 7e-6 off the converged ones with the bound itself, 8e-7 with 1/10 and 2e-7
    // with 1/100 (for 50 % more backward time; docs/engine.md, Adjoint).
    constexpr double kLambdaAtolFraction = 0.01;
    const std::vector<double> nominal = state_nominals(d);
    OwnedVector lambda(N_VNew_Serial(std::max(nb, 1), C.ctx)), atol_b(N_VNew_Serial(std::max(nb, 1), C.ctx));
    OwnedVector grad(N_VNew_Serial(ns * nm, C.ctx)), atol_q(N_VNew_Serial(ns * nm, C.ctx));
    N_VConst(0.0, lambda.v);
    N_VConst(d.solver.atol, atol_b.v);
    for (int m = 0; m < nm; ++m) {
      for (int i = 0; i < nx; ++i)
        NV_Ith_S(atol_b.v, m * nx + i) =
            kLambdaAtolFraction * d.solver.atol * scale[m] / (d.solver.nominal_scaling ? nominal[i] : 1.0);
      for (int dir = 0; dir < ns; ++dir) {
        const double p = std::fabs(d.parameters[d.sensitivities[dir]].value);
        NV_Ith_S(atol_q.v, m * ns + dir) = d.solver.atol * scale[m] / (p > 0 ? p : 1.0);
      }
    }
    std::vector<double> gradient(static_cast<size_t>(ns) * nm, 0.0);
    OwnedVector qB(N_VNew_Serial(ns * nm, C.ctx));
    const CpuClock backward_clock;
    long most_steps = 0;
    for (size_t k = chunks.size(); k-- > 0;) {
      const Chunk& c = chunks[k];
      // the chunk's forward run again from its checkpoint, every step stored
      std::copy(c.y0.begin(), c.y0.end(), NV_DATA_S(y.v));
      Solver S;
      open_forward(S, c);
      void* mem = S.mem;
      const long room = c.steps + std::max(16L, c.steps / 4);
      most_steps = std::max(most_steps, room);
      check(CVodeAdjInit(mem, room, CV_HERMITE), "CVodeAdjInit", c.start);
      double reached = c.start;
      for (double target : c.targets) {
        int ncheck = 0;
        check(CVodeF(mem, target, y.v, &reached, CV_NORMAL, &ncheck), "CVodeF", reached);
      }
      long replayed = 0;
      CVodeGetNumSteps(mem, &replayed);
      as.replay_steps += replayed;
      if (replayed != c.steps) ++as.replays_differing;
      // lambda back over the chunk
      const double te = c.targets.back();
      int which = 0;
      check(CVodeCreateB(mem, bdf ? CV_BDF : CV_ADAMS, &which), "CVodeCreateB", te);
      check(CVodeInitB(mem, which, backward_rhs, te, lambda.v), "CVodeInitB", te);
      check(CVodeSetUserDataB(mem, which, &B), "CVodeSetUserDataB", te);
      check(CVodeSVtolerancesB(mem, which, d.solver.rtol, atol_b.v), "CVodeSVtolerancesB", te);
      check(CVodeSetMaxNumStepsB(mem, which, d.solver.max_steps), "CVodeSetMaxNumStepsB", te);
      if (d.solver.max_order > 0) check(CVodeSetMaxOrdB(mem, which, d.solver.max_order), "CVodeSetMaxOrdB", te);
      if (bdf) {
        S.AB = SUNDenseMatrix(std::max(nb, 1), std::max(nb, 1), C.ctx);
        S.LSB = SUNLinSol_Dense(lambda.v, S.AB, C.ctx);
        check(CVodeSetLinearSolverB(mem, which, S.LSB, S.AB), "CVodeSetLinearSolverB", te);
        check(CVodeSetJacFnB(mem, which, backward_jacobian), "CVodeSetJacFnB", te);
      } else {
        S.NLSB = SUNNonlinSol_FixedPoint(lambda.v, 0, C.ctx);
        check(CVodeSetNonlinearSolverB(mem, which, S.NLSB), "CVodeSetNonlinearSolverB", te);
      }
      N_VConst(0.0, qB.v);
      check(CVodeQuadInitB(mem, which, backward_quadrature, qB.v), "CVodeQuadInitB", te);
      check(CVodeQuadSVtolerancesB(mem, which, d.solver.rtol, atol_q.v), "CVodeQuadSVtolerancesB", te);
      check(CVodeSetQuadErrConB(mem, which, SUNTRUE), "CVodeSetQuadErrConB", te);
      check(CVodeB(mem, c.start, CV_NORMAL), "CVodeB", te);
      double tret = 0.0;
      check(CVodeGetB(mem, which, &tret, lambda.v), "CVodeGetB", c.start);
      check(CVodeGetQuadB(mem, which, &tret, qB.v), "CVodeGetQuadB", c.start);
      for (int i = 0; i < ns * nm; ++i) gradient[i] += NV_Ith_S(qB.v, i);
      void* memB = CVodeGetAdjCVodeBmem(mem, which);
      long v = 0;
      CVodeGetNumSteps(memB, &v), as.backward_steps += v;
    }
    // lambda(t0)^T dx0/dp
    ev.set_segment_start(t0);
    ev.initial_state_adjoint(t0, x0.data(), nm, {NV_DATA_S(lambda.v), nx}, {gradient.data(), ns});
    for (int m = 0; m < nm; ++m)
      for (int dir = 0; dir < ns; ++dir) {
        const double g = gradient[static_cast<size_t>(m) * ns + dir];
        if (!std::isfinite(g))
          throw SolverError(t0, result.objectives[m].name, "the adjoint gradient is not finite (direction " +
                                                               d.parameters[d.sensitivities[dir]].name + ")");
        result.objectives[m].sensitivity[dir] = g;
      }
    as.backward_rhs_evals = B.rhs_passes;
    as.backward_quadrature_evals = B.quadrature_passes;
    as.backward_jac_evals = B.jac_passes;
    as.backward_cpu_seconds = backward_clock.seconds();
    // held: each checkpoint's state, and for the chunk being worked on y and y' at each of its
    // steps (Hermite), in room for the most steps of a chunk
    as.checkpoint_bytes = 8.0 * n_cv * (static_cast<double>(as.checkpoints) + 2.0 * (most_steps + 1));
  }
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) == 0) as.peak_rss_bytes = 1024.0 * static_cast<double>(usage.ru_maxrss);

  finish_cvodes_stats(st, d, clock.seconds());
  return result;
}

}  // namespace dydp::engine
