// dydp: runs scenes (values, sensitivities, objectives) and lists the block library.
// Exit status: 0 success, 2 bad input (file:line: message on stderr), 1 solver failure.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/run_sharing.hpp"

namespace {

/// --solver, --rtol, --atol, --step, --max-order over the scene's solver section.
void add_solver_options(CLI::App* command, dydp::engine::SolverOverrides& o) {
  command->add_option("--solver", o.method, "integrator instead of the scene's (bdf adams rk4 sdirk2 rosw)");
  command->add_option_function<double>("--rtol", [&o](const double& v) { o.rtol = v; }, "relative tolerance");
  command->add_option_function<double>(
      "--atol", [&o](const double& v) { o.atol = v; }, "absolute tolerance, times each state's nominal magnitude");
  command->add_option_function<double>("--step", [&o](const double& v) { o.step = v; }, "fixed step [s]");
  command->add_option_function<int>(
      "--max-order", [&o](const int& v) { o.max_order = v; }, "highest order of bdf (1-5) or adams (1-12)");
}

/// `dydp run`.
CLI::App* add_run(CLI::App& app, dydp::apps::RunArgs& a) {
  CLI::App* run = app.add_subcommand("run", "Run a scene: signals, sensitivities, objectives");
  run->add_option("scene", a.scene, "scene file (YAML)")->required();
  run->add_option("--out", a.out, "output folder")->capture_default_str();
  run->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  run->add_flag("--no-sens", a.no_sens, "run without sensitivities");
  run->add_flag("--no-estimate", a.no_estimate, "no shadow run: no estimate of the run's error");
  run->add_flag("--adjoint", a.adjoint,
                "the objectives' gradients for every declared parameter and direction by the adjoint method "
                "(one backward run; the signals without sensitivities)");
  run->add_flag("--report", a.report, "also write plots (gnuplot) and report.md");
  add_solver_options(run, a.solver);
  run->add_option("--format", a.format, "csv: the CSV/JSON files; mat: also run.mat (MAT v5)")
      ->check(CLI::IsMember({"csv", "mat"}))->capture_default_str();
  return run;
}

/// `dydp sweep`.
CLI::App* add_sweep(CLI::App& app, dydp::apps::SweepArgs& a) {
  CLI::App* sweep = app.add_subcommand("sweep", "psi and d(psi)/dp over a range of one parameter");
  sweep->add_option("scene", a.scene, "scene file (YAML)")->required();
  sweep->add_option("--param", a.parameter, "scene parameter to sweep")->required();
  sweep->add_option("--range", a.range, "LO:HI:N")->required();
  sweep->add_option("--out", a.out, "output folder")->capture_default_str();
  sweep->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  sweep->add_option("--fd", a.fd_steps, "central differences at these absolute steps")->delimiter(',');
  sweep->add_option("--delta", a.delta, "report the change of psi for this step of the parameter");
  sweep->add_flag("--report", a.report, "also write plots (gnuplot) and report.md");
  sweep->add_flag("--no-estimate", a.no_estimate, "no shadow runs: the points' error is not estimated (half the CPU)");
  add_solver_options(sweep, a.solver);
  sweep->add_option("--format", a.format, "csv: the CSV/JSON files; mat: also sweep.mat (MAT v5)")
      ->check(CLI::IsMember({"csv", "mat"}))->capture_default_str();
  return sweep;
}

/// `dydp accuracy`.
CLI::App* add_accuracy(CLI::App& app, dydp::apps::AccuracyArgs& a) {
  CLI::App* accuracy = app.add_subcommand("accuracy", "Error against run time over solvers and tolerances");
  accuracy->add_option("scene", a.scene, "scene file (YAML)")->required();
  accuracy->add_option("--out", a.out, "output folder")->capture_default_str();
  accuracy->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  accuracy->add_option("--target", a.target, "accuracy for the cheapest-setting line")->capture_default_str();
  accuracy->add_option("--methods", a.methods, "methods of the ladder (bdf adams rk4 sdirk2 rosw; default all but rosw)")
      ->delimiter(',')
      ->check(CLI::IsMember({"bdf", "adams", "rk4", "sdirk2", "rosw"}))
      ->capture_default_str();
  add_solver_options(accuracy, a.solver);
  return accuracy;
}

/// `dydp replay`.
CLI::App* add_replay(CLI::App& app, dydp::apps::ReplayArgs& a) {
  CLI::App* replay = app.add_subcommand("replay", "Replay recorded test-bench input through a scene");
  replay->add_option("scene", a.scene, "scene file (YAML)")->required();
  replay->add_option("--input", a.input, "recorded CSV (t, one column per pad named in the scene, measured outputs) "
                     "or RPC III file (.rsp, .drv, .tim: channels named by their descriptions)")->required();
  replay->add_option("--out", a.out, "output folder")->capture_default_str();
  replay->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  replay->add_flag("--realtime", a.realtime, "pace the run to the wall clock and report missed deadlines");
  replay->add_flag("--no-sens", a.no_sens, "run without sensitivities");
  replay->add_flag("--no-estimate", a.no_estimate, "no shadow run: no estimate of the replay's error");
  add_solver_options(replay, a.solver);
  replay->add_option("--format", a.format,
                     "csv: the CSV/JSON files; mat: also replay.mat (MAT v5); rpc: also signals.rsp (RPC III)")
      ->check(CLI::IsMember({"csv", "mat", "rpc"}))->capture_default_str();
  return replay;
}

/// `dydp screen`.
CLI::App* add_screen(CLI::App& app, dydp::apps::ScreenArgs& a) {
  CLI::App* screen = app.add_subcommand(
      "screen", "Rank parameters over their ranges: Sobol' points, exact gradients, derivative-based global measures");
  screen->add_option("scene", a.scene, "scene file (YAML)")->required();
  screen->add_option("--params", a.parameters,
                     "scene parameters or declared directions to screen, each with a range in the scene")
      ->delimiter(',')->required();
  screen->add_option("--samples", a.samples, "Sobol' points (runs besides the nominal one)")->capture_default_str();
  screen->add_option("--out", a.out, "output folder (runs recorded in OUT/runs/)")->capture_default_str();
  screen->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  screen->add_flag("--report", a.report, "also write plots (gnuplot) and report.md");
  screen->add_flag("--no-estimate", a.no_estimate, "no shadow runs: the runs' error is not estimated (half the CPU)");
  screen->add_flag("--adjoint", a.adjoint,
                   "each run's gradients by the adjoint method (one backward run, whatever the number of parameters)");
  screen->add_flag("--resume", a.resume, "keep the runs recorded in OUT/runs/ and run only the missing ones");
  screen->add_option("--threads", a.threads, "runs at a time (0: one per core; one per rank under MPI)")
      ->capture_default_str();
  add_solver_options(screen, a.solver);
  return screen;
}

/// `dydp kc`.
CLI::App* add_kc(CLI::App& app, dydp::apps::KcArgs& a) {
  CLI::App* kc = app.add_subcommand("kc", "Suspension kinematics of the scene's car: bump steer, camber gain, track change, "
                                          "motion ratios, roll centre, roll steer, steering, with their derivatives");
  kc->add_option("scene", a.scene, "scene file (YAML)")->required();
  kc->add_option("--out", a.out, "output folder")->capture_default_str();
  kc->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  kc->add_option("--block", a.block, "the multibody block (default: the scene's first)");
  kc->add_option("--travel", a.travel, "wheel travel swept each way [m]")->capture_default_str();
  kc->add_option("--points", a.points, "poses of the wheel travel sweep (odd)")->capture_default_str();
  kc->add_flag("--report", a.report, "also write the plots (gnuplot) and report.md");
  kc->add_option("--format", a.format, "csv: the CSV/JSON files; mat: also a MAT v5 file")
      ->check(CLI::IsMember({"csv", "mat"}))->capture_default_str();
  return kc;
}

/// `dydp fmu`.
CLI::App* add_fmu(CLI::App& app, dydp::apps::FmuArgs& a) {
  CLI::App* fmu = app.add_subcommand("fmu", "Export the scene (or an FMU description naming a scene, its inputs, outputs "
                                            "and parameters) as an FMI 3.0 FMU with exact directional and adjoint derivatives");
  fmu->add_option("scene", a.scene, "scene file or FMU description (YAML)")->required();
  fmu->add_option("--out", a.out, "the FMU archive, NAME.fmu")->required();
  fmu->add_option("--kind", a.kind, "me: Model Exchange, cs: Co-Simulation, both")
      ->check(CLI::IsMember({"me", "cs", "both"}))->capture_default_str();
  return fmu;
}

/// One of the analyses about one operating point (engine/linear/): the options they share.
CLI::App* add_linear(CLI::App& app, dydp::apps::LinearArgs& a, const char* name, const char* what) {
  CLI::App* c = app.add_subcommand(name, what);
  c->add_option("scene", a.scene, "scene file (YAML)")->required();
  c->add_option("--out", a.out, "output folder")->capture_default_str();
  c->add_option("--set", a.sets, "override a scene parameter: NAME=VALUE");
  c->add_option("--time", a.time, "hold the inputs at their values at this time [s] (default: the scene's start)");
  c->add_option("--hold", a.holds, "hold a signal at a value, SIGNAL=VALUE (e.g. rig.zdot=0: the pads still); the equilibrium also holds the scene's initial.hold, a --hold of the same signal replacing its value");
  c->add_option("--format", a.format, "csv: the CSV/JSON files; mat: also a MAT v5 file")
      ->check(CLI::IsMember({"csv", "mat"}))->capture_default_str();
  return c;
}

/// The linear analyses' commands.
struct LinearCommands {
  CLI::App *equilibrium, *linearize, *modes, *frf;
};
LinearCommands add_linear_commands(CLI::App& app, dydp::apps::LinearArgs& a) {
  LinearCommands c;
  c.equilibrium = add_linear(app, a, "equilibrium", "Static equilibrium with the inputs held, and dx*/dp for every parameter");
  c.linearize = add_linear(app, a, "linearize", "A, B, C, D of the whole diagram about its equilibrium (or a time of a run)");
  c.linearize->add_option("--input", a.inputs, "input signal BLOCK.PORT or BLOCK.PORT[i] (its wire cut)");
  c.linearize->add_option("--output", a.outputs, "output signal (default: the scene's logged signals)");
  c.linearize->add_option("--at", a.at, "about the run's state at this time [s] instead of the equilibrium");
  c.modes = add_linear(app, a, "modes", "Ride modes: eigenvalues, frequencies, damping ratios, dominant states, d(lambda)/dp");
  c.modes->add_option("--max-frequency", a.max_frequency, "the terminal table's highest frequency [Hz]")->capture_default_str();
  c.frf = add_linear(app, a, "frf", "Frequency response from one input to outputs, with d|H|/dp");
  c.frf->add_option("--input", a.inputs, "input SIGNAL or SIGNAL:RATE_SIGNAL (e.g. rig.z:rig.zdot, the pads' heave)")->required();
  c.frf->add_option("--output", a.outputs, "output signals")->required();
  c.frf->add_option("--frequencies", a.frequencies, "LO:HI:N [Hz], log spaced")->capture_default_str();
  c.frf->add_flag("--report", a.report, "also write the plot (gnuplot) and report.md");
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  // Under mpirun: one process per rank; rank 0 alone prints and writes results.
  const dydp::engine::RankSession ranks(&argc, &argv);
  std::ostringstream quiet;
  std::ostream& err = dydp::engine::world_rank() == 0 ? std::cerr : quiet;
  CLI::App app{"dydp: exact sensitivities of vehicle comfort and handling to design parameters"};
  app.require_subcommand(1);

  dydp::apps::RunArgs run_args;
  CLI::App* run = add_run(app, run_args);
  dydp::apps::SweepArgs sweep_args;
  CLI::App* sweep = add_sweep(app, sweep_args);
  dydp::apps::AccuracyArgs accuracy_args;
  CLI::App* accuracy = add_accuracy(app, accuracy_args);
  dydp::apps::ReplayArgs replay_args;
  CLI::App* replay = add_replay(app, replay_args);
  dydp::apps::ScreenArgs screen_args;
  CLI::App* screen = add_screen(app, screen_args);
  dydp::apps::LinearArgs linear_args;
  const LinearCommands linear = add_linear_commands(app, linear_args);
  CLI::App* equilibrium = linear.equilibrium;
  CLI::App* linearize = linear.linearize;
  CLI::App* modes = linear.modes;
  CLI::App* frf = linear.frf;
  dydp::apps::KcArgs kc_args;
  CLI::App* kc = add_kc(app, kc_args);
  dydp::apps::FmuArgs fmu_args;
  CLI::App* fmu = add_fmu(app, fmu_args);

  CLI::App* blocks = app.add_subcommand("blocks", "List the block types with ports and parameters; [direction]: a parameter that can be a "
      "sensitivity direction, written BLOCK.PARAMETER in a scene's sensitivities: list");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = dydp::engine::world_rank() == 0 ? app.exit(e) : app.exit(e, quiet, quiet);
    return code == 0 ? 0 : 2;
  }

  try {
    if (*run) return dydp::apps::run_command(run_args);
    if (*sweep) return dydp::apps::sweep_command(sweep_args);
    if (*screen) return dydp::apps::screen_command(screen_args);
    accuracy_args.methods_given = accuracy->count("--methods") > 0;
    if (*accuracy) return dydp::apps::accuracy_command(accuracy_args);
    if (*replay) return dydp::apps::replay_command(replay_args);
    if (*equilibrium) return dydp::apps::equilibrium_command(linear_args);
    if (*linearize) return dydp::apps::linearize_command(linear_args);
    if (*modes) return dydp::apps::modes_command(linear_args);
    if (*frf) return dydp::apps::frf_command(linear_args);
    if (*kc) return dydp::apps::kc_command(kc_args);
    if (*fmu) return dydp::apps::fmu_command(fmu_args);
    if (*blocks) return dydp::apps::blocks_command(std::cout);
  } catch (const dydp::engine::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const dydp::engine::SolverError& e) {
    err << "solver failure: " << e.what() << "\n";
    return 1;
  } catch (const dydp::engine::OutOfDomain& e) {
    err << "solver failure: " << e.reason << "\n";
    return 1;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
