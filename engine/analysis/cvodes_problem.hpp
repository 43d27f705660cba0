// The pieces of a CVODES run that the forward-sensitivity run (cvodes_solver.cpp) and the
// adjoint run (cvodes_adjoint.cpp) share: the callbacks' problem (the diagram's evaluator, its
// coloured Jacobian, what a refused point said), the right-hand side and Newton matrix callbacks,
// the refresh of the blocks' own diagonal Jacobian blocks, the forward problem's set-up and the
// statistics at the end.
#pragma once

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_nonlinearsolver.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/evaluation/jacobian_colouring.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::engine::cvodes {

/// CVODES' name of a return flag.
std::string flag_name(int flag);

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
inline void gather(N_Vector* v, int n, int count, std::vector<double>& out) {
  out.resize(static_cast<size_t>(n) * count);
  for (int c = 0; c < count; ++c) std::copy_n(NV_DATA_S(v[c]), n, out.data() + c * n);
}
inline void scatter(const std::vector<double>& in, int n, int count, N_Vector* v) {
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

int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user);
int sens_rhs(int ns, sunrealtype t, N_Vector y, N_Vector, N_Vector* yS, N_Vector* ySdot, void* user, N_Vector,
             N_Vector);
int jacobian(sunrealtype t, N_Vector y, N_Vector, SUNMatrix J, void* user, N_Vector, N_Vector, N_Vector);
void error_handler(int, const char* module, const char* function, char* msg, void* user);
/// The blocks' own diagonal blocks of the Newton matrix refreshed at every factorisation
/// (cvodes_problem.cpp); false when no block provides a local Jacobian.
bool refresh_local_blocks(Problem& P, void* mem, SUNLinearSolver solver, double t0, const double* x0);

/// An N_Vector destroyed with its owner.
struct OwnedVector {
  N_Vector v = nullptr;
  OwnedVector() = default;
  explicit OwnedVector(N_Vector w) : v(w) {}
  OwnedVector(const OwnedVector&) = delete;
  OwnedVector& operator=(OwnedVector&& o) noexcept {
    std::swap(v, o.v);
    return *this;
  }
  ~OwnedVector() {
    if (v) N_VDestroy(v);
  }
};

/// Throws SolverError at t when a SUNDIALS call failed (flag < 0), naming the call, the flag,
/// CVODES' message and the last refused point.
void check_call(const Problem& P, int flag, const char* call, double t);

/// The per-state absolute tolerances of CVODES' vector [x; q] (atol times each one's nominal
/// magnitude, tolerances.hpp; `atol` for the placeholder state of a stateless diagram), a new
/// vector like `like` for the caller to destroy.
N_Vector state_tolerances(const Problem& P, const AbsoluteTolerances& atols, double atol, N_Vector like);

/// The absolute tolerances of the sensitivities of CVODES' vector [x; q] in ns directions, one
/// vector per direction: atols' sensitivities and quadrature sensitivities (`atol` for the
/// placeholder state of a stateless diagram), a new array like `like` for the caller to destroy
/// (N_VDestroyVectorArray). Also the FMU's integrator's (fmi/cvodes_stepper.cpp).
N_Vector* sensitivity_tolerances(const AbsoluteTolerances& atols, int nx, int nq, int ns, double atol, N_Vector like);

/// What a forward CVODES problem owns besides its memory (null where unused); an owner frees its
/// CVODES memory before these (its destructor's body runs before its members').
struct ForwardSolvers {
  SUNMatrix A = nullptr;             ///< BDF: the dense Newton matrix
  SUNLinearSolver LS = nullptr;      ///< BDF: its LU
  SUNNonlinearSolver NLS = nullptr;  ///< Adams: the fixed-point iteration
  ForwardSolvers() = default;
  ForwardSolvers(const ForwardSolvers&) = delete;
  ForwardSolvers& operator=(const ForwardSolvers&) = delete;
  ~ForwardSolvers() {
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (NLS) SUNNonlinSolFree(NLS);
  }
};

/// The forward problem on `mem` (from CVodeCreate), one code for the forward-sensitivity run and
/// the adjoint's passes: the right-hand side from (t, y) with P as user data and CVODES' messages
/// kept in P, the scene's rtol with the per-state `atol`, its limits (steps, minimum step, Newton
/// coefficient, highest order), and for BDF the dense Newton matrix from the coloured Jacobian
/// with the blocks' local Jacobian blocks refreshed at each set-up (a set-up every
/// kLocalRefreshSetupSteps steps then), for Adams the fixed-point iteration.
void set_up_forward(Problem& P, void* mem, SUNContext ctx, double t, N_Vector y, N_Vector atol, ForwardSolvers& s);

/// CVODES' counters of the integration in `mem` (steps, right-hand sides, error test failures,
/// Newton iterations and failures, for BDF Jacobians) added to st: once per segment, since a
/// restart or a new solver starts them again.
void add_cvodes_counters(void* mem, bool bdf, RunStats& st);

/// The run's statistics at its end: the tolerances, the highest order and the CPU time.
void finish_cvodes_stats(RunStats& st, const Diagram& d, double cpu_seconds);

}  // namespace dydp::engine::cvodes
