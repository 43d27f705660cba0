#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/report.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/run_sharing.hpp"
#include "engine/studies/sweep.hpp"
#include "io/files.hpp"
#include "io/mat_outputs.hpp"

namespace dydp::apps {
namespace {

constexpr int kMaxSweepPoints = 1000000;

/// "LO:HI:N" -> low, high, points.
void parse_range(const std::string& text, engine::SweepSpec& spec) {
  double points = 0;
  if (!split_range(text, spec.low, spec.high, points) || points < 1 || points != std::floor(points) || spec.high < spec.low)
    throw engine::InputError("--range", 0, text, "expected LO:HI:N with LO <= HI and N >= 1");
  // One point spans no range: LO:HI:1 with LO < HI would sweep nothing but LO.
  if (points > kMaxSweepPoints)
    throw engine::InputError("--range", 0, text, "N = " + text.substr(text.rfind(':') + 1) + " is more than " + std::to_string(kMaxSweepPoints) + " runs");
  if (points == 1 && spec.low < spec.high)
    throw engine::InputError("--range", 0, text, "N = 1 with LO < HI sweeps one point: give N >= 2, or LO = HI");
  spec.points = static_cast<int>(points);
}

std::string sweep_csv(const engine::SweepResult& r, double delta) {
  std::ostringstream out;
  out.precision(12);
  out << r.parameter;
  for (const auto& o : r.objectives) {
    out << ',' << o << ",d(" << o << ")/d(" << r.parameter << "),normalised(" << o << ")";
    if (delta > 0) out << ",change(" << o << ")for_step_" << delta;
    for (double h : r.fd_steps) out << ",fd(" << o << ")h=" << h << ",fd_error(" << o << ")h=" << h;
  }
  out << ",cpu_seconds,error_estimate_signals,error_estimate_sensitivities\n";
  for (const auto& pt : r.points) {
    out << pt.p;
    for (size_t o = 0; o < r.objectives.size(); ++o) {
      out << ',' << pt.psi[o] << ',' << pt.dpsi[o] << ','
          << (pt.psi[o] != 0 ? pt.p / pt.psi[o] * pt.dpsi[o] : 0.0);
      if (delta > 0) out << ',' << pt.dpsi[o] * delta;
      for (size_t s = 0; s < r.fd_steps.size(); ++s)
        out << ',' << pt.fd[s][o] << ',' << std::fabs(pt.fd[s][o] - pt.dpsi[o]) / std::max(std::fabs(pt.dpsi[o]), 1e-300);
    }
    const engine::ErrorEstimate& e = pt.stats.error_estimate;
    out << ',' << pt.stats.cpu_seconds;
    if (e.estimated)
      out << ',' << e.signal_error << ',' << e.sensitivity_error << '\n';
    else
      out << ",nan,nan\n";
  }
  return out.str();
}

}  // namespace

int sweep_command(const SweepArgs& args) {
  engine::SweepSpec spec;
  spec.scene = args.scene;
  spec.overrides = parse_sets(args.sets);
  spec.solver = args.solver;
  spec.parameter = args.parameter;
  parse_range(args.range, spec);
  spec.fd_steps = args.fd_steps;
  for (double h : spec.fd_steps)
    if (!(h > 0 && std::isfinite(h))) throw engine::InputError("--fd", 0, engine::format_number(h), "steps must be positive");
  if (!(args.delta >= 0 && std::isfinite(args.delta)))
    throw engine::InputError("--delta", 0, engine::format_number(args.delta), "must be positive (0: no change column)");
  spec.keep_runs = args.report;
  spec.estimate = !args.no_estimate;
  if (engine::world_rank() == 0)
    std::cerr << "sweep: " << spec.points << " runs of " << args.scene << " over " << spec.parameter
            << " in [" << spec.low << ", " << spec.high << "]"
            << (spec.fd_steps.empty() ? "" : ", with central differences") << "\n";
  const engine::SweepResult r = engine::sweep(spec);
  if (!r.complete) return 0;  // another rank writes the results

  std::filesystem::create_directories(args.out);
  const std::string csv = sweep_csv(r, args.delta);
  nlohmann::ordered_json j;
  j["parameter"] = r.parameter;
  j["unit"] = r.unit;
  j["objectives"] = r.objectives;
  j["objective_units"] = r.objective_units;
  j["fd_steps"] = r.fd_steps;
  for (const auto& pt : r.points) {
    nlohmann::ordered_json p = {{"p", pt.p}, {"cpu_seconds", pt.stats.cpu_seconds}};
    const engine::ErrorEstimate& e = pt.stats.error_estimate;
    p["error_estimate"] = nullptr;
    if (e.estimated)
      p["error_estimate"] = {{"signals", e.signal_error}, {"sensitivities", e.sensitivity_error},
                             {"worst_signal", e.worst_signal}, {"worst_sensitivity", e.worst_sensitivity},
                             {"how", e.how}};
    p["warnings"] = pt.stats.warnings;
    for (size_t o = 0; o < r.objectives.size(); ++o) {
      nlohmann::ordered_json obj = {{"value", pt.psi[o]}, {"sensitivity", pt.dpsi[o]},
                                    {"normalised", pt.psi[o] != 0 ? pt.p / pt.psi[o] * pt.dpsi[o] : 0.0}};
      for (size_t s = 0; s < r.fd_steps.size(); ++s) obj["fd"].push_back({{"step", r.fd_steps[s]}, {"value", pt.fd[s][o]}});
      p["objectives"][r.objectives[o]] = obj;
    }
    j["points"].push_back(p);
  }
  io::write_file_atomically(args.out + "/sweep.csv", csv);
  io::write_file_atomically(args.out + "/sweep.json", j.dump(2) + "\n");
  if (args.format == "mat") io::write_table_mat(args.out + "/sweep.mat", csv, {{"sweep", j.dump()}});
  if (args.report) write_sweep_report(args.out, args.scene, r, args.delta);

  std::cout << std::setprecision(6);
  for (size_t o = 0; o < r.objectives.size(); ++o) {
    std::cout << r.objectives[o] << (r.objective_units[o].empty() ? "" : " [" + r.objective_units[o] + "]")
              << " against " << r.parameter << (r.unit.empty() ? "" : " [" + r.unit + "]") << ":\n";
    std::cout << "  " << std::setw(12) << "p" << std::setw(14) << "psi" << std::setw(14) << "dpsi/dp"
              << std::setw(14) << "% per %";
    if (args.delta > 0) std::cout << std::setw(14) << ("for +" + std::to_string(args.delta).substr(0, 6));
    std::cout << "\n";
    for (const auto& pt : r.points) {
      std::cout << "  " << std::setw(12) << pt.p << std::setw(14) << pt.psi[o] << std::setw(14) << pt.dpsi[o]
                << std::setw(14) << (pt.psi[o] != 0 ? pt.p / pt.psi[o] * pt.dpsi[o] : 0.0);
      if (args.delta > 0) std::cout << std::setw(14) << pt.dpsi[o] * args.delta;
      std::cout << "\n";
    }
  }
  // Each point's own error estimate: the worst of them, and every point above the target on stderr.
  const engine::SweepPoint* worst_signal = nullptr;
  const engine::SweepPoint* worst_sens = nullptr;
  for (const auto& pt : r.points) {
    const engine::ErrorEstimate& e = pt.stats.error_estimate;
    if (!e.estimated) continue;
    if (!worst_signal || e.signal_error > worst_signal->stats.error_estimate.signal_error) worst_signal = &pt;
    if (!worst_sens || e.sensitivity_error > worst_sens->stats.error_estimate.sensitivity_error) worst_sens = &pt;
    for (const std::string& w : pt.stats.warnings) std::cerr << "warning: at " << r.parameter << " = " << pt.p << ": " << w << "\n";
  }
  if (worst_signal)
    std::cout << "  estimated error (each run's own, " << worst_signal->stats.error_estimate.how << "): signals up to "
              << std::setprecision(2) << 100 * worst_signal->stats.error_estimate.signal_error << " % (at "
              << r.parameter << " = " << std::setprecision(6) << worst_signal->p << "), sensitivities up to "
              << std::setprecision(2) << 100 * worst_sens->stats.error_estimate.sensitivity_error << " % (at "
              << std::setprecision(6) << worst_sens->p << ")\n";
  else if (args.no_estimate)
    std::cout << "  no error estimates (--no-estimate)\n";
  std::cout << "results in " << args.out << "/ (sweep.csv, sweep.json" << (args.format == "mat" ? ", sweep.mat" : "")
            << (args.report ? ", report.md" : "") << ")\n";
  return 0;
}

}  // namespace dydp::apps
