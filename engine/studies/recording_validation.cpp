#include "engine/studies/recording_validation.hpp"

#include <cmath>

#include "engine/framework/interpolation.hpp"

namespace dydp::engine {

std::vector<SignalAgreement> compare_with_recording(const RunResult& run, const io::CsvFile& recording) {
  std::vector<SignalAgreement> out;
  for (size_t c = 1; c < recording.names.size(); ++c) {
    const int i = run.signal_index(recording.names[c]);
    if (i < 0) continue;
    double se = 0, sm = 0, ss = 0, smm = 0, sss = 0, sms = 0;
    const size_t n = run.t.size();
    for (size_t k = 0; k < n; ++k) {
      const double meas = interpolate_linear(recording.columns[0], recording.columns[c], run.t[k]);
      const double sim = run.value(static_cast<int>(k), i);
      se += (sim - meas) * (sim - meas);
      sm += meas, ss += sim, smm += meas * meas, sss += sim * sim, sms += meas * sim;
    }
    const double cov = sms / n - sm / n * ss / n;
    const double var_m = smm / n - sm / n * sm / n, var_s = sss / n - ss / n * ss / n;
    SignalAgreement a;
    a.signal = recording.names[c];
    a.correlation = var_m > 0 && var_s > 0 ? cov / std::sqrt(var_m * var_s) : 0.0;
    a.rms_error = std::sqrt(se / n);
    a.samples = n;
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace dydp::engine
