#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/progress_bar.hpp"
#include "apps/dydp/report.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/run_sharing.hpp"
#include "engine/studies/screen_study.hpp"
#include "io/files.hpp"

namespace dydp::apps {
namespace {

constexpr int kMaxSamples = 1000000;

/// E[dpsi/dp_i] (b_i - a_i): the change of psi across the range at the mean slope.
double swing(const engine::ScreenResult& r, int o, int i) {
  return r.estimates[o].parameters[i].mean_gradient * (r.ranges[i].upper - r.ranges[i].lower);
}

/// One row per objective and parameter, ranked.
std::string measures_csv(const engine::ScreenResult& r) {
  std::ostringstream out;
  out.precision(12);
  out << "objective,parameter,unit,lower,upper,nominal,rank,nu,normalised,total_index_bound,mean_gradient,"
         "swing,local_normalised\n";
  for (size_t o = 0; o < r.objectives.size(); ++o)
    for (int i : r.estimates[o].ranking) {
      const auto& m = r.estimates[o].parameters[i];
      const auto& g = r.ranges[i];
      out << r.objectives[o] << ',' << g.name << ',' << r.units[i] << ',' << g.lower << ',' << g.upper << ','
          << g.nominal << ',' << m.rank << ',' << m.nu << ',' << m.normalised << ',' << m.total_index_bound << ','
          << m.mean_gradient << ',' << swing(r, static_cast<int>(o), i) << ',' << m.local_normalised << '\n';
    }
  return out.str();
}

/// Every run (run 0: the nominal point, then the samples): its point, psi and gradient per objective.
std::string samples_csv(const engine::ScreenResult& r) {
  std::ostringstream out;
  out.precision(17);
  out << "run";
  for (const auto& g : r.ranges) out << ',' << g.name;
  for (const auto& o : r.objectives) {
    out << ',' << o;
    for (const auto& g : r.ranges) out << ",d(" << o << ")/d(" << g.name << ")";
  }
  out << ",cpu_seconds,error_estimate_signals,error_estimate_sensitivities\n";
  auto row = [&](const engine::ScreenRun& s) {
    out << s.index;
    for (double p : s.p) out << ',' << p;
    for (size_t o = 0; o < r.objectives.size(); ++o) {
      out << ',' << s.psi[o];
      for (double g : s.gradient[o]) out << ',' << g;
    }
    out << ',' << s.cpu_seconds << ',' << s.error_signals << ',' << s.error_sensitivities << '\n';
  };
  row(r.nominal);
  for (const auto& s : r.samples) row(s);
  return out.str();
}

std::vector<const engine::ScreenRun*> all_runs(const engine::ScreenResult& r) {
  std::vector<const engine::ScreenRun*> runs{&r.nominal};
  for (const auto& s : r.samples) runs.push_back(&s);
  return runs;
}

nlohmann::ordered_json screen_json(const engine::ScreenResult& r, const std::string& scene) {
  nlohmann::ordered_json j;
  j["scene"] = scene;
  j["samples"] = r.samples.size();
  for (size_t i = 0; i < r.ranges.size(); ++i)
    j["parameters"].push_back({{"name", r.ranges[i].name}, {"unit", r.units[i]}, {"lower", r.ranges[i].lower},
                               {"upper", r.ranges[i].upper}, {"nominal", r.ranges[i].nominal}});
  for (size_t o = 0; o < r.objectives.size(); ++o) {
    const auto& e = r.estimates[o];
    nlohmann::ordered_json obj = {{"unit", r.objective_units[o]}, {"mean", e.mean}, {"variance", e.variance},
                                  {"nominal", {{"value", r.nominal.psi[o]}, {"gradient", r.nominal.gradient[o]}}}};
    for (int i : e.ranking) obj["ranking"].push_back(r.ranges[i].name);
    for (size_t i = 0; i < r.ranges.size(); ++i) {
      const auto& m = e.parameters[i];
      obj["parameters"][r.ranges[i].name] = {
          {"rank", m.rank}, {"nu", m.nu}, {"normalised", m.normalised},
          {"total_index_bound", std::isfinite(m.total_index_bound) ? nlohmann::ordered_json(m.total_index_bound)
                                                                   : nlohmann::ordered_json("inf")},
          {"mean_gradient", m.mean_gradient}, {"swing", swing(r, static_cast<int>(o), static_cast<int>(i))},
          {"local_normalised", m.local_normalised}};
    }
    j["objectives"][r.objectives[o]] = obj;
  }
  double cpu = r.nominal.cpu_seconds;
  long steps = r.nominal.steps;
  for (const auto& s : r.samples) cpu += s.cpu_seconds, steps += s.steps;
  j["runs"] = {{"count", r.samples.size() + 1}, {"recorded_before", r.recorded_before}, {"cpu_seconds", cpu},
               {"steps", steps}};
  // The runs' own error estimates: the worst of them (samples.csv has each).
  const engine::ScreenRun* worst_signal = nullptr;
  const engine::ScreenRun* worst_sens = nullptr;
  int estimated = 0;
  for (const engine::ScreenRun* s : all_runs(r)) {
    if (!std::isfinite(s->error_signals)) continue;
    ++estimated;
    if (!worst_signal || s->error_signals > worst_signal->error_signals) worst_signal = s;
    if (!worst_sens || s->error_sensitivities > worst_sens->error_sensitivities) worst_sens = s;
  }
  j["runs"]["error_estimate"] = nullptr;
  if (worst_signal)
    j["runs"]["error_estimate"] = {{"estimated_runs", estimated},
                                   {"signals", worst_signal->error_signals},
                                   {"signals_run", worst_signal->index},
                                   {"sensitivities", worst_sens->error_sensitivities},
                                   {"sensitivities_run", worst_sens->index}};
  return j;
}

}  // namespace

int screen_command(const ScreenArgs& args) {
  engine::ScreenSpec spec;
  spec.scene = args.scene;
  spec.overrides = parse_sets(args.sets);
  spec.solver = args.solver;
  spec.parameters = args.parameters;
  if (args.samples > kMaxSamples)
    throw engine::InputError("--samples", 0, std::to_string(args.samples), "more than " + std::to_string(kMaxSamples) + " runs");
  spec.samples = args.samples;
  spec.out = args.out;
  spec.resume = args.resume;
  spec.threads = args.threads;
  spec.estimate = !args.no_estimate;
  spec.adjoint = args.adjoint;
  const bool speaker = engine::world_rank() == 0;
  ProgressBar bar("screen");
  spec.progress = [&](int done, int todo) { bar.update(done, todo); };
  if (speaker)
    std::cerr << "screen: " << args.samples << " Sobol' points and the nominal point of " << args.scene << " over "
              << args.parameters.size() << " parameters"
              << (engine::world_size() > 1 ? ", shared among " + std::to_string(engine::world_size()) + " MPI ranks" : "")
              << (args.resume ? ", resuming the records in " + args.out + "/runs" : "") << "\n";
  const engine::ScreenResult r = engine::screen(spec);
  if (!r.complete) return 0;  // another rank writes the results
  bar.finish();
  if (r.recorded_before > 0)
    std::cerr << "screen: " << r.recorded_before << " runs taken from the records, "
              << r.samples.size() + 1 - r.recorded_before << " run now\n";

  io::write_file_atomically(args.out + "/screen.csv", measures_csv(r));
  io::write_file_atomically(args.out + "/samples.csv", samples_csv(r));
  const nlohmann::ordered_json sj = screen_json(r, args.scene);
  io::write_file_atomically(args.out + "/screen.json", sj.dump(2) + "\n");
  for (const engine::ScreenRun* s : all_runs(r))
    for (const std::string& w : s->warnings) std::cerr << "warning: run " << s->index << ": " << w << "\n";
  if (args.report) write_screen_report(args.out, args.scene, r);

  std::cout << std::setprecision(4);
  for (size_t o = 0; o < r.objectives.size(); ++o) {
    const auto& e = r.estimates[o];
    const std::string& ou = r.objective_units[o];
    std::cout << r.objectives[o] << (ou.empty() ? "" : " [" + ou + "]") << ": mean " << e.mean << ", std "
              << std::sqrt(e.variance) << " over " << r.samples.size() << " samples; nominal " << r.nominal.psi[o] << "\n";
    std::cout << "  " << std::left << std::setw(5) << "rank" << std::setw(34) << "parameter" << std::right
              << std::setw(12) << "S_T <=" << std::setw(10) << "share" << std::setw(14) << "swing" << std::setw(12)
              << "% per %" << "\n";
    for (int i : e.ranking) {
      const auto& m = e.parameters[i];
      std::cout << "  " << std::left << std::setw(5) << m.rank << std::setw(34) << r.ranges[i].name << std::right
                << std::setw(12) << m.total_index_bound << std::setw(10) << m.normalised << std::setw(14)
                << swing(r, static_cast<int>(o), i) << std::setw(12) << m.local_normalised << "\n";
    }
  }
  const auto& est = sj["runs"]["error_estimate"];
  if (est.is_object())
    std::cout << "estimated error (each run's own, " << est["estimated_runs"].get<int>() << " runs): signals up to "
              << std::setprecision(2) << 100 * est["signals"].get<double>() << " % (run " << est["signals_run"].get<int>()
              << "), sensitivities up to " << 100 * est["sensitivities"].get<double>() << " % (run "
              << est["sensitivities_run"].get<int>() << ")\n";
  std::cout << "results in " << args.out << "/ (screen.csv, samples.csv, screen.json" << (args.report ? ", report.md" : "")
            << "; one record per run in runs/)\n";
  return 0;
}

}  // namespace dydp::apps
