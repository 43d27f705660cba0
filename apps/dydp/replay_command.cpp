#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "apps/dydp/commands.hpp"
#include "engine/analysis/error_estimate.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "engine/studies/recording_validation.hpp"
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

/// Replay integrates with Rosenbrock-W (rosw) unless --solver names another integrator: its
/// local stages follow the dampers' valves at millisecond steps (docs/engine.md).
/// With rosw, named or not, the step is --step, else the scene's own rosw step, else chosen by
/// the error control at replay's tolerances (--rtol, --atol change them).
engine::SolverOverrides replay_solver(const ReplayArgs& args, const engine::Diagram& d) {
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
  return solver;
}

void require_recorded_input(const ReplayArgs& args, const engine::Diagram& d) {
  for (const auto& n : d.nodes)
    for (const auto& s : n.type->settings)
      if (s.name == "input_file") return;
  throw engine::InputError(args.scene, 0, "blocks",
                           "no block of this scene takes recorded input (a block with an `input_file` "
                           "setting, such as road.fourposter)");
}

}  // namespace

int replay_command(const ReplayArgs& args) {
  const std::shared_ptr<const io::CsvFile> recording = io::load_recording(args.input);
  const io::CsvFile& recorded = *recording;
  if (recorded.names.empty() || recorded.names[0] != "t")
    throw engine::InputError(args.input, 1, "t", "the first column must be the time t [s]");
  const std::string input = std::filesystem::absolute(args.input).string();
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets), {{"input_file", input}});
  const engine::SolverOverrides solver = replay_solver(args, d);
  engine::apply_solver_overrides(d, solver);
  // Replay's error-controlled rosw holds the sensitivities to the tolerances as well: on rough
  // roads their error at a valve's switch is not the states' (docs/accuracy.md).
  const bool controlled_rosw = d.solver.method == "rosw" && d.solver.step <= 0;
  if (controlled_rosw) d.solver.sens_error_test = true;
  require_recorded_input(args, d);
  print_warnings(d.warnings);

  std::filesystem::create_directories(args.out);
  io::SignalsCsvStream stream(args.out + "/signals.csv");
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
  engine::start_at_equilibrium(d);  // `initial: equilibrium`; the shadow run starts there too
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
  for (const engine::SignalAgreement& a : engine::compare_with_recording(r, recorded)) {
    j["validation"][a.signal] = {{"rms_error", a.rms_error}, {"correlation", a.correlation}, {"samples", a.samples}};
    std::cout << "  " << a.signal << ": rms error " << a.rms_error << ", correlation " << a.correlation << "\n";
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
