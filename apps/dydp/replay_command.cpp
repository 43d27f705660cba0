#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "apps/dydp/commands.hpp"
#include "engine/analysis/error_estimate.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "io/files.hpp"
#include "io/mat_outputs.hpp"
#include "io/output_writer.hpp"
#include "io/recording.hpp"
#include "io/rpc3_outputs.hpp"

namespace dydp::apps {
namespace {

/// Replay's tolerances with Rosenbrock-W when neither --step nor a rosw scene fixes its step
/// (and --rtol, --atol do not give them): the error-controlled steps' rtol and atol (atol
/// relative to each state's nominal magnitude), chosen for replay's stated accuracy, 1 % in
/// every logged signal and 5 % in every sensitivity column (docs/accuracy.md).
constexpr double kReplayRtol = 2e-3;
constexpr double kReplayAtol = 2e-3;

double interpolate(const std::vector<double>& t, const std::vector<double>& y, double x) {
  if (x <= t.front()) return y.front();
  if (x >= t.back()) return y.back();
  const size_t k = std::upper_bound(t.begin(), t.end(), x) - t.begin();
  const double w = (x - t[k - 1]) / (t[k] - t[k - 1]);
  return (1 - w) * y[k - 1] + w * y[k];
}

/// One CSV line per output sample, appended and flushed as the run goes.
class StreamingCsv {
 public:
  explicit StreamingCsv(std::string path) : path_(std::move(path)), partial_(path_ + ".partial") {}
  ~StreamingCsv() {
    if (!done_) std::remove(partial_.c_str());
  }
  void sample(const engine::RunResult& r) {
    if (!out_.is_open()) {
      out_.open(partial_, std::ios::trunc);
      if (!out_) throw std::runtime_error("cannot write " + partial_);
      out_.precision(12);
      out_ << "t";
      for (const auto& s : r.signal_names) out_ << ',' << s;
      for (const auto& p : r.sensitivity_names)
        for (const auto& s : r.signal_names) out_ << ",d(" << s << ")/d(" << p << ')';
      out_ << '\n';
    }
    const int k = static_cast<int>(r.t.size()) - 1, nsig = r.num_signals();
    out_ << r.t[k];
    for (int i = 0; i < nsig; ++i) out_ << ',' << r.value(k, i);
    for (size_t d = 0; d < r.sensitivity_names.size(); ++d)
      for (int i = 0; i < nsig; ++i) out_ << ',' << r.tangent(k, static_cast<int>(d), i);
    out_ << '\n';
    out_.flush();
  }
  void finish() {
    out_.close();
    std::filesystem::rename(partial_, path_);
    done_ = true;
  }

 private:
  std::string path_, partial_;
  std::ofstream out_;
  bool done_ = false;
};

}  // namespace

int replay_command(const ReplayArgs& args) {
  const io::CsvFile recorded = io::read_recording(args.input);
  if (recorded.names.empty() || recorded.names[0] != "t")
    throw engine::InputError(args.input, 1, "t", "the first column must be the time t [s]");
  const std::string input = std::filesystem::absolute(args.input).string();
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets), {{"input_file", input}});
  // Replay integrates with Rosenbrock-W (rosw) unless --solver names another integrator: its
  // local stages follow the dampers' valves at millisecond steps (docs/engine.md).
  // With rosw, named or not, the step is --step, else the scene's own rosw step, else chosen by
  // the error control at replay's tolerances (--rtol, --atol change them).
  engine::SolverOverrides solver = args.solver;
  if (solver.method.empty()) {
    if (solver.max_order)
      throw engine::InputError("--max-order", 0, "",
                               "applies to bdf and adams; replay integrates with rosw unless --solver names another "
                               "(add --solver bdf)");
    solver.method = "rosw";
  }
  const bool scene_rosw_step = d.solver.method == "rosw" && d.solver.step > 0;
  if (solver.method == "rosw" && !solver.step && !scene_rosw_step) {
    if (!solver.rtol) solver.rtol = kReplayRtol;
    if (!solver.atol) solver.atol = kReplayAtol;
  }
  engine::apply_solver_overrides(d, solver);
  // Replay's error-controlled rosw holds the sensitivities to the tolerances as well: on rough
  // roads their error at a valve's switch is not the states' (docs/accuracy.md).
  const bool controlled_rosw = d.solver.method == "rosw" && d.solver.step <= 0;
  if (controlled_rosw) d.solver.sens_error_test = true;
  bool takes_input = false;
  for (const auto& n : d.nodes)
    for (const auto& s : n.type->settings) takes_input = takes_input || s.name == "input_file";
  if (!takes_input)
    throw engine::InputError(args.scene, 0, "blocks",
                             "no block of this scene takes recorded input (a block with an `input_file` "
                             "setting, such as road.fourposter)");
  print_warnings(d.warnings);

  std::filesystem::create_directories(args.out);
  StreamingCsv stream(args.out + "/signals.csv");
  engine::RunOptions options;
  options.sensitivities = !args.no_sens;
  long missed = 0;
  double worst_lag = 0;
  const auto wall_start = std::chrono::steady_clock::now();
  options.on_sample = [&](const engine::RunResult& r) {
    stream.sample(r);
    if (!args.realtime) return;
    // Paced to the wall clock: wait for the sample's time; a sample made later than one output
    // step after its time is a missed deadline.
    const double due = r.t.back() - d.time.start;
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    if (now < due) std::this_thread::sleep_for(std::chrono::duration<double>(due - now));
    else if (now - due > d.time.output_step) ++missed;
    worst_lag = std::max(worst_lag, now - due);
  };
  const auto t0 = std::chrono::steady_clock::now();
  engine::RunResult r;
  if (args.no_estimate) {
    r = engine::run(d, options);
  } else {
    engine::Diagram shadow = engine::load_scene(args.scene, parse_sets(args.sets), {{"input_file", input}});
    engine::apply_solver_overrides(shadow, solver);
    shadow.solver.sens_error_test = d.solver.sens_error_test;
    r = engine::run_with_error_estimate(d, shadow, options);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stream.finish();
  io::write_file_atomically(args.out + "/objectives.json", io::objectives_json(r));
  io::write_file_atomically(args.out + "/run.json", io::run_json(d, r));

  // Measured responses: columns named after logged signals.
  nlohmann::ordered_json j = {{"input", args.input}, {"simulated_seconds", r.stats.simulated_seconds},
                              {"cpu_seconds", r.stats.cpu_seconds}, {"wall_seconds", wall},
                              {"realtime_factor", r.stats.realtime_factor}, {"paced", args.realtime}};
  if (args.realtime) j["missed_deadlines"] = missed, j["worst_lag_seconds"] = worst_lag;
  std::cout << std::setprecision(4) << d.scene_name << " replay of " << args.input << " (" << d.solver.method;
  if (r.stats.step > 0) std::cout << ", step " << r.stats.step * 1e3 << " ms";
  std::cout << "): " << r.stats.simulated_seconds << " s simulated in " << r.stats.cpu_seconds << " CPU s ("
            << r.stats.realtime_factor << "x real time)";
  if (args.realtime) std::cout << ", paced: " << missed << " missed deadlines";
  std::cout << "\n";
  print_limiting_states(std::cout, r.stats);
  print_error_estimate(std::cout, r.stats);
  print_run_warnings(d, r);
  j["validation"] = nlohmann::ordered_json::object();
  for (size_t c = 1; c < recorded.names.size(); ++c) {
    const int i = r.signal_index(recorded.names[c]);
    if (i < 0) continue;
    double se = 0, sm = 0, ss = 0, smm = 0, sss = 0, sms = 0;
    const size_t n = r.t.size();
    for (size_t k = 0; k < n; ++k) {
      const double meas = interpolate(recorded.columns[0], recorded.columns[c], r.t[k]);
      const double sim = r.value(static_cast<int>(k), i);
      se += (sim - meas) * (sim - meas);
      sm += meas, ss += sim, smm += meas * meas, sss += sim * sim, sms += meas * sim;
    }
    const double cov = sms / n - sm / n * ss / n;
    const double var_m = smm / n - sm / n * sm / n, var_s = sss / n - ss / n * ss / n;
    const double corr = var_m > 0 && var_s > 0 ? cov / std::sqrt(var_m * var_s) : 0.0;
    const double rms = std::sqrt(se / n);
    j["validation"][recorded.names[c]] = {{"rms_error", rms}, {"correlation", corr}, {"samples", n}};
    std::cout << "  " << recorded.names[c] << ": rms error " << rms << ", correlation " << corr << "\n";
  }
  io::write_file_atomically(args.out + "/replay.json", j.dump(2) + "\n");
  if (args.format == "mat") io::write_run_mat(args.out + "/replay.mat", d, r, {{"replay", j.dump()}});
  if (args.format == "rpc")
    io::write_file_atomically(args.out + "/signals.rsp", io::run_rpc3(d, r, io::Rpc3DataType::floating_point));
  std::cout << "  results in " << args.out << "/ (signals.csv streamed, objectives.json, run.json, replay.json"
            << (args.format == "mat" ? ", replay.mat" : args.format == "rpc" ? ", signals.rsp" : "") << ")\n";
  return 0;
}

}  // namespace dydp::apps
