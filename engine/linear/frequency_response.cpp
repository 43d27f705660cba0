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

BandRms band_rms(const FrequencyResponse& h) {
  const size_t nf = h.frequency_hz.size(), no = nf ? h.H[0].size() : 0, np = h.dmagnitude.size();
  BandRms out;
  out.value.assign(no, 0.0);
  out.sensitivity.assign(np, std::vector<double>(no, 0.0));
  if (nf < 2) return out;
  const double band = h.frequency_hz.back() - h.frequency_hz.front();
  for (size_t f = 0; f + 1 < nf; ++f) {
    const double w = 0.5 * (h.frequency_hz[f + 1] - h.frequency_hz[f]) / band;
    for (size_t o = 0; o < no; ++o) {
      const double a = std::abs(h.H[f][o]), b = std::abs(h.H[f + 1][o]);
      out.value[o] += w * (a * a + b * b);
      for (size_t p = 0; p < np; ++p)
        out.sensitivity[p][o] += w * 2.0 * (a * h.dmagnitude[p][f][o] + b * h.dmagnitude[p][f + 1][o]);
    }
  }
  for (size_t o = 0; o < no; ++o) {
    out.value[o] = std::sqrt(out.value[o]);
    for (size_t p = 0; p < np; ++p) out.sensitivity[p][o] = out.value[o] > 0 ? out.sensitivity[p][o] / (2.0 * out.value[o]) : 0.0;
  }
  return out;
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
