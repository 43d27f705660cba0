#include "engine/linear/frequency_response.hpp"

#include <cmath>

namespace dydp::engine {
namespace {

constexpr double kTwoPi = 6.283185307179586;
using Complex = std::complex<double>;

Eigen::VectorXcd input_column(const Eigen::MatrixXd& B, FrequencyInput in, Complex s) {
  Eigen::VectorXcd b = B.col(in.input).cast<Complex>();
  if (in.rate >= 0) b += s * B.col(in.rate).cast<Complex>();
  return b;
}

}  // namespace

std::vector<double> log_frequencies(double lo, double hi, int n) {
  std::vector<double> f(n);
  for (int k = 0; k < n; ++k) f[k] = lo * std::pow(hi / lo, n > 1 ? k / double(n - 1) : 0.0);
  return f;
}

FrequencyResponse frequency_response(const LinearModel& m, FrequencyInput input, const std::vector<double>& frequency_hz,
                                     const std::vector<LinearModelDerivative>& derivatives) {
  const Eigen::Index n = m.A.rows(), no = m.C.rows();
  FrequencyResponse out;
  out.frequency_hz = frequency_hz;
  out.dmagnitude.assign(derivatives.size(), {});
  const Eigen::MatrixXcd A = m.A.cast<Complex>(), C = m.C.cast<Complex>();
  for (double f : frequency_hz) {
    const Complex s(0.0, kTwoPi * f);
    const Eigen::MatrixXcd K = s * Eigen::MatrixXcd::Identity(n, n) - A;
    const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(K);
    const Eigen::VectorXcd b = input_column(m.B, input, s), dcol = input_column(m.D, input, s);
    const Eigen::VectorXcd Rb = n ? Eigen::VectorXcd(lu.solve(b)) : Eigen::VectorXcd(0);
    const Eigen::VectorXcd H = (n ? Eigen::VectorXcd(C * Rb) : Eigen::VectorXcd::Zero(no)) + dcol;
    out.H.emplace_back(H.data(), H.data() + no);
    // dH = C R (dA R b + db) + dC R b + dd: one more solve with R on the left, per parameter.
    for (size_t p = 0; p < derivatives.size(); ++p) {
      const LinearModelDerivative& dm = derivatives[p];
      Eigen::VectorXcd dH = input_column(dm.D, input, s);
      if (n) {
        const Eigen::VectorXcd inner = dm.A.cast<Complex>() * Rb + input_column(dm.B, input, s);
        dH += C * lu.solve(inner) + dm.C.cast<Complex>() * Rb;
      }
      std::vector<double> dmag(no);
      for (Eigen::Index o = 0; o < no; ++o) {
        const double mag = std::abs(H[o]);
        dmag[o] = mag > 0 ? (std::conj(H[o]) * dH[o]).real() / mag : 0.0;
      }
      out.dmagnitude[p].push_back(std::move(dmag));
    }
  }
  return out;
}

}  // namespace dydp::engine
