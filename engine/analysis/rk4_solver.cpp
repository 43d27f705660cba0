#include "engine/analysis/rk4_solver.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "engine/analysis/step_driver.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

/// k = f(t, x), dk = f_x dx + f_p: one value and one tangent pass per stage.
class Rk4Stepper final : public FixedStepper {
 public:
  Rk4Stepper(const Diagram& d, Evaluator& ev, int ns, RunStats& stats)
      : FixedStepper(scene_fixed_step(d)), ev_(ev), nx_(d.num_states), nq_(d.num_quadratures), ns_(ns),
        stats_(stats) {
    for (int i = 0; i < 4; ++i) {
      kx_[i].setZero(std::max(nx_, 1));
      kq_[i].setZero(std::max(nq_, 1));
      kdx_[i].setZero(nx_, ns_);
      kdq_[i].setZero(std::max(nq_, 1), ns_);
    }
  }

 protected:
  void step(MarchState& s, double h) override {
    const double tn = s.t;
    evaluate(tn, s.x, s.S, 0);
    stage(s, h / 2, 0);
    evaluate(tn + h / 2, x_stage_, s_stage_, 1);
    stage(s, h / 2, 1);
    evaluate(tn + h / 2, x_stage_, s_stage_, 2);
    stage(s, h, 2);
    evaluate(tn + h, x_stage_, s_stage_, 3);
    combine(s.x, kx_, h);
    combine(s.q, kq_, h);
    combine(s.S, kdx_, h);
    combine(s.Sq, kdq_, h);
    ++stats_.steps;
  }

 private:
  void evaluate(double t, const Vector& x, const Matrix& dx, int i) {
    try {
      ev_.derivatives(t, x.data(), kx_[i].data());
      if (nq_ > 0) ev_.quadratures(t, x.data(), kq_[i].data());
      ++stats_.rhs_evals;
      const std::string bad = ev_.find_nonfinite(kx_[i].data());
      if (!bad.empty())
        throw SolverError(t, bad.substr(0, bad.find(':')),
                          bad.substr(bad.find(':') + 2) + " (rk4 step " + std::to_string(h_max_) +
                              " s: unstable or too large for this scene?)");
      if (ns_ > 0) {
        ev_.tangents(t, x.data(), ns_, {dx.data(), nx_}, true, {kdx_[i].data(), nx_},
                     {nq_ ? kdq_[i].data() : nullptr, nq_});
        ++stats_.sens_rhs_evals;
      }
    } catch (const OutOfDomain& e) {
      throw domain_failure(t, e);
    }
  }
  /// The next stage's point: x + a k_i and its sensitivity.
  void stage(const MarchState& s, double a, int i) {
    x_stage_ = s.x + a * kx_[i].head(nx_);
    if (ns_ > 0) s_stage_ = s.S + a * kdx_[i];
  }
  template <class M>
  static void combine(M& y, const M* k, double h) {
    const auto n = y.size();
    double* out = y.data();
    for (Eigen::Index i = 0; i < n; ++i)
      out[i] += h / 6 * (k[0].data()[i] + 2 * k[1].data()[i] + 2 * k[2].data()[i] + k[3].data()[i]);
  }

  Evaluator& ev_;
  int nx_, nq_, ns_;
  RunStats& stats_;
  Vector kx_[4], kq_[4], x_stage_;
  Matrix kdx_[4], kdq_[4], s_stage_;
};

}  // namespace

RunResult run_rk4(const Diagram& d, const RunOptions& options) {
  return march(d, options, "rk4", [&](Evaluator& ev, int ns, RunStats& st) {
    return std::make_unique<Rk4Stepper>(d, ev, ns, st);
  });
}

}  // namespace dydp::engine
