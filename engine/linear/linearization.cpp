#include "engine/linear/linearization.hpp"

#include <algorithm>
#include <cmath>

#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/numbers.hpp"
#include "engine/linear/signal_lookup.hpp"

namespace dydp::engine {

std::vector<std::pair<int, double>> held_signals(const Diagram& d, const std::vector<std::string>& specs,
                                                 const std::string& field) {
  std::vector<std::pair<int, double>> out;
  for (const std::string& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos) throw InputError(field, 0, spec, "expected SIGNAL=VALUE");
    double value = 0.0;
    if (!parse_number(spec.substr(eq + 1), value)) throw InputError(field, 0, spec, "the value after '=' is not a number");
    for (int o : signal_offsets(d, spec.substr(0, eq), field)) out.push_back({o, value});
  }
  return out;
}

Eigen::MatrixXd state_jacobian(Evaluator& e, int n, double t, const std::vector<double>& x,
                               const std::vector<int>& held) {
  Eigen::MatrixXd A(n, n);
  if (n == 0) return A;
  const Eigen::MatrixXd seeds = Eigen::MatrixXd::Identity(n, n);
  e.set_signal_seeds(held, std::vector<double>(held.size() * n, 0.0));
  e.tangents(t, x.data(), n, {seeds.data(), n}, false, {A.data(), n}, {});
  e.set_signal_seeds({}, {});
  return A;
}

namespace {

struct Ports {
  std::vector<std::vector<int>> inputs;  ///< per input: the offsets it moves
  std::vector<int> held;                 ///< all of them
  std::vector<int> outputs;              ///< one offset per output row
  size_t num_inputs_held = 0;            ///< the inputs' offsets at the end of `held`
};

Ports resolve(const Diagram& d, const std::vector<std::string>& inputs, std::vector<std::string>& outputs,
              const std::vector<std::pair<int, double>>& held) {
  Ports p;
  for (const std::string& name : inputs) p.inputs.push_back(signal_offsets(d, name, "--input"));
  // A held signal that is also an input keeps its held value as the operating point; its
  // tangent is the input's.
  const auto is_input = [&](int offset) {
    for (const auto& in : p.inputs)
      if (std::find(in.begin(), in.end(), offset) != in.end()) return true;
    return false;
  };
  for (const auto& h : held)
    if (!is_input(h.first)) p.held.push_back(h.first);
  const size_t held_only = p.held.size();
  for (size_t j = 0; j < inputs.size(); ++j)
    for (int o : p.inputs[j]) {
      if (std::find(p.held.begin() + static_cast<long>(held_only), p.held.end(), o) != p.held.end())
        throw InputError("--input", 0, inputs[j], "names a signal another input already names");
      p.held.push_back(o);
    }
  p.num_inputs_held = p.held.size() - held_only;
  std::vector<std::string> rows;
  if (outputs.empty()) {
    for (const LoggedSignal& s : d.logged) p.outputs.push_back(s.offset), rows.push_back(s.name);
  } else {
    for (const std::string& name : outputs)
      for (int o : signal_offsets(d, name, "--output")) p.outputs.push_back(o), rows.push_back(signal_name(d, o));
  }
  outputs = rows;
  return p;
}

}  // namespace

LinearModel linearize(const Diagram& d, double t, const std::vector<double>& x,
                      const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                      const std::vector<std::pair<int, double>>& held) {
  LinearModel m;
  m.held = held;
  m.t = t;
  m.x = x;
  m.inputs = inputs;
  m.outputs = outputs;
  const Ports ports = resolve(d, inputs, m.outputs, held);
  const int first_input = static_cast<int>(ports.held.size() - ports.num_inputs_held);  // held ones, then the inputs'
  const int n = d.num_states, ni = static_cast<int>(inputs.size()), no = static_cast<int>(ports.outputs.size());
  for (int i = 0; i < n; ++i) m.states.push_back(state_label(d, i));
  Evaluator e(d, false);
  e.set_segment_start(t);
  e.hold_signals(held);
  // A and C from one pass: state seeds, the inputs' wires cut (their tangents held at zero).
  m.A.resize(n, n);
  m.C.resize(no, n);
  if (n > 0) {
    const Eigen::MatrixXd seeds = Eigen::MatrixXd::Identity(n, n);
    e.set_signal_seeds(ports.held, std::vector<double>(ports.held.size() * n, 0.0));
    e.tangents(t, x.data(), n, {seeds.data(), n}, false, {m.A.data(), n}, {});
    for (int r = 0; r < no; ++r)
      for (int c = 0; c < n; ++c) m.C(r, c) = e.signal_tangents()[static_cast<size_t>(c) * d.num_signals + ports.outputs[r]];
  }
  // B and D: one direction per input, seeding every signal it moves with 1.
  m.B = Eigen::MatrixXd::Zero(n, ni);
  m.D = Eigen::MatrixXd::Zero(no, ni);
  if (ni > 0) {
    const int nh = static_cast<int>(ports.held.size());
    std::vector<double> seeds(static_cast<size_t>(nh) * ni, 0.0);
    for (int j = 0, h = first_input; j < ni; ++j)
      for (size_t k = 0; k < ports.inputs[j].size(); ++k, ++h) seeds[static_cast<size_t>(j) * nh + h] = 1.0;
    e.set_signal_seeds(ports.held, seeds);
    e.tangents(t, x.data(), ni, {}, false, {m.B.data(), n}, {});
    for (int r = 0; r < no; ++r)
      for (int c = 0; c < ni; ++c) m.D(r, c) = e.signal_tangents()[static_cast<size_t>(c) * d.num_signals + ports.outputs[r]];
    e.set_signal_seeds({}, {});
  }
  return m;
}

std::vector<double> signal_values(const Diagram& d, double t, const std::vector<double>& x,
                                  const std::vector<std::string>& names,
                                  const std::vector<std::pair<int, double>>& held) {
  Evaluator e(d, false);
  e.set_segment_start(t);
  e.hold_signals(held);
  e.outputs(t, x.data());
  std::vector<double> values;
  for (const std::string& name : names)
    for (int o : signal_offsets(d, name, "--output")) values.push_back(e.signals()[o]);
  return values;
}

LinearModelDerivative linear_model_derivative(Diagram& d, const LinearModel& m, int parameter,
                                              const Eigen::VectorXd& dx_dp, double relative_step) {
  const SceneParameter& sp = d.parameters[parameter];
  const double p0 = sp.value;
  const double span = std::isfinite(sp.upper - sp.lower) ? sp.upper - sp.lower : 0.0;
  const double h = relative_step * std::max({std::fabs(p0), 1e-3 * span, 1e-8});
  LinearModel at[2];
  for (int s = 0; s < 2; ++s) {
    const double sign = s == 0 ? 1.0 : -1.0;
    std::vector<double> x = m.x;
    for (size_t i = 0; i < x.size(); ++i) x[i] += sign * h * dx_dp[static_cast<Eigen::Index>(i)];
    d.set_parameter(parameter, p0 + sign * h, false);
    try {
      at[s] = linearize(d, m.t, x, m.inputs, m.outputs, m.held);
    } catch (...) {
      d.set_parameter(parameter, p0, false);
      throw;
    }
  }
  d.set_parameter(parameter, p0, false);
  const double scale = 1.0 / (2 * h);
  return {(at[0].A - at[1].A) * scale, (at[0].B - at[1].B) * scale, (at[0].C - at[1].C) * scale,
          (at[0].D - at[1].D) * scale};
}

}  // namespace dydp::engine
