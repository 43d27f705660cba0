#include "io/output_writer.hpp"

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/files.hpp"

namespace dydp::io {

using engine::LimitingState;
using engine::RunStats;

namespace {

void write_signals_header(std::ostream& out, const engine::RunResult& r) {
  out << "t";
  for (const auto& s : r.signal_names) out << ',' << s;
  if (r.signal_sensitivities)
    for (const auto& p : r.sensitivity_names)
      for (const auto& s : r.signal_names) out << ",d(" << s << ")/d(" << p << ')';
  out << '\n';
}

void write_signals_row(std::ostream& out, const engine::RunResult& r, size_t k) {
  const int nsig = r.num_signals();
  const int ns = r.signal_sensitivities ? static_cast<int>(r.sensitivity_names.size()) : 0;
  out << r.t[k];
  for (int i = 0; i < nsig; ++i) out << ',' << r.value(static_cast<int>(k), i);
  for (int d = 0; d < ns; ++d)
    for (int i = 0; i < nsig; ++i) out << ',' << r.tangent(static_cast<int>(k), d, i);
  out << '\n';
}

}  // namespace

std::string signals_csv(const engine::RunResult& r) {
  std::ostringstream out;
  out.precision(12);
  write_signals_header(out, r);
  for (size_t k = 0; k < r.t.size(); ++k) write_signals_row(out, r, k);
  return out.str();
}

SignalsCsvStream::SignalsCsvStream(std::string path) : path_(std::move(path)), partial_(path_ + ".partial") {}

SignalsCsvStream::~SignalsCsvStream() {
  if (!done_) std::remove(partial_.c_str());
}

void SignalsCsvStream::sample(const engine::RunResult& r) {
  if (!out_.is_open()) {
    out_.open(partial_, std::ios::trunc);
    if (!out_) throw std::runtime_error("cannot write " + partial_);
    out_.precision(12);
    write_signals_header(out_, r);
  }
  write_signals_row(out_, r, r.t.size() - 1);
  out_.flush();
}

void SignalsCsvStream::finish() {
  out_.close();
  std::filesystem::rename(partial_, path_);
  done_ = true;
}

std::string objectives_json(const engine::RunResult& r) {
  nlohmann::ordered_json objectives = nlohmann::ordered_json::object();
  for (const auto& o : r.objectives) {
    nlohmann::ordered_json sens = nlohmann::ordered_json::object();
    for (size_t d = 0; d < r.sensitivity_names.size(); ++d) sens[r.sensitivity_names[d]] = o.sensitivity[d];
    objectives[o.name] = {{"value", o.value}, {"unit", o.unit}, {"sensitivity", sens}};
  }
  return nlohmann::ordered_json{{"objectives", objectives}}.dump(2) + "\n";
}

std::string run_json(const engine::Diagram& d, const engine::RunResult& r) {
  const RunStats& s = r.stats;
  nlohmann::ordered_json parameters = nlohmann::ordered_json::object();
  for (const auto& p : d.parameters) parameters[p.name] = {{"value", p.value}, {"unit", p.unit}};
  // Per state: the share of the accepted steps at which it had the largest weighted local error.
  nlohmann::ordered_json limiting = nlohmann::ordered_json::array();
  for (const LimitingState& l : s.limiting_states)
    limiting.push_back({{"state", l.state}, {"steps", l.steps}, {"share", l.share}});
  nlohmann::ordered_json estimate = nullptr;
  if (s.error_estimate.estimated)
    estimate = {{"signals", s.error_estimate.signal_error},
                {"sensitivities", s.error_estimate.sensitivity_error},
                {"worst_signal", s.error_estimate.worst_signal},
                {"worst_sensitivity", s.error_estimate.worst_sensitivity},
                {"how", s.error_estimate.how},
                {"cpu_seconds", s.error_estimate.cpu_seconds}};
  // an adjoint run: its checkpoints, backward steps and memory (a forward run has no such key)
  nlohmann::ordered_json adjoint = nullptr;
  if (s.adjoint.used) {
    const engine::AdjointStats& a = s.adjoint;
    adjoint = {{"objectives", a.objectives},
               {"segments", a.segments},
               {"checkpoints", a.checkpoints},
               {"steps_between_checkpoints", a.steps_between_checkpoints},
               {"forward_steps", a.forward_steps},
               {"replay_steps", a.replay_steps},
               {"replays_differing", a.replays_differing},
               {"backward_steps", a.backward_steps},
               {"backward_rhs_evaluations", a.backward_rhs_evals},
               {"backward_quadrature_evaluations", a.backward_quadrature_evals},
               {"backward_jacobian_evaluations", a.backward_jac_evals},
               {"checkpoint_bytes", a.checkpoint_bytes},
               {"peak_rss_bytes", a.peak_rss_bytes},
               {"forward_cpu_seconds", a.forward_cpu_seconds},
               {"backward_cpu_seconds", a.backward_cpu_seconds}};
  }
  nlohmann::ordered_json j = {
      {"scene", d.scene_name},
      {"file", d.file},
      {"solver", s.method},
      {"rtol", s.rtol},
      {"atol", s.atol},
      {"fixed_step", s.step},
      {"sens_error_test", d.solver.sens_error_test},
      {"nominal_scaling", d.solver.nominal_scaling},
      {"newton_coefficient", d.solver.newton_coefficient},
      {"refresh_local_jacobians", d.solver.refresh_local_jacobians},
      {"max_order", s.max_order},
      {"parameters", parameters},
      {"sensitivities", r.sensitivity_names},
      {"states", d.num_states},
      {"steps", s.steps},
      {"rhs_evaluations", s.rhs_evals},
      {"sensitivity_rhs_evaluations", s.sens_rhs_evals},
      {"jacobian_evaluations", s.jac_evals},
      {"jacobian_colours", s.jacobian_colours},
      {"local_jacobian_refreshes", s.local_jac_evals},
      {"substeps", s.substeps},
      {"error_test_failures", s.error_test_failures},
      {"nonlinear_iterations", s.nonlinear_iterations},
      {"nonlinear_failures", s.nonlinear_failures},
      {"steps_per_order", s.steps_per_order},
      {"limiting_states", limiting},
      {"cpu_seconds", s.cpu_seconds},
      {"simulated_seconds", s.simulated_seconds},
      {"realtime_factor", s.realtime_factor},
      {"error_estimate", estimate},
      {"pruned_blocks", d.pruned},
      {"warnings", s.warnings},
  };
  if (s.adjoint.used) j["adjoint"] = adjoint;
  return j.dump(2) + "\n";
}

void write_outputs(const std::string& dir, const engine::Diagram& d, const engine::RunResult& r) {
  std::filesystem::create_directories(dir);
  // Compose everything first so that a failure leaves no half-written set behind.
  const std::string signals = signals_csv(r), objectives = objectives_json(r), run = run_json(d, r);
  write_file_atomically(dir + "/signals.csv", signals);
  write_file_atomically(dir + "/objectives.json", objectives);
  write_file_atomically(dir + "/run.json", run);
}

}  // namespace dydp::io
