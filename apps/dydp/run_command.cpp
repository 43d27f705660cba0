#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/report.hpp"
#include "engine/analysis/cvodes_adjoint.hpp"
#include "engine/analysis/error_estimate.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/numbers.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "io/mat_outputs.hpp"
#include "io/output_writer.hpp"

namespace dydp::apps {

std::vector<std::pair<std::string, std::string>> parse_sets(const std::vector<std::string>& sets) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& s : sets) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw engine::InputError("--set", 0, s, "expected NAME=VALUE");
    out.emplace_back(s.substr(0, eq), s.substr(eq + 1));
  }
  return out;
}

void print_limiting_states(std::ostream& out, const engine::RunStats& stats) {
  if (stats.limiting_states.empty()) return;
  out << "  step limited by:";
  const char* separator = " ";
  for (const engine::LimitingState& l : stats.limiting_states) {
    out << separator << l.state << " " << std::fixed << std::setprecision(0) << 100 * l.share << " %";
    separator = ", ";
  }
  out << std::defaultfloat << "\n";
}

void print_error_estimate(std::ostream& out, const engine::RunStats& stats) {
  const engine::ErrorEstimate& e = stats.error_estimate;
  if (!e.estimated) return;
  out << "  estimated error: signals " << std::setprecision(2) << 100 * e.signal_error << " %";
  if (!e.worst_sensitivity.empty()) out << ", sensitivities " << 100 * e.sensitivity_error << " %";
  out << " (" << e.how << ", " << std::setprecision(3) << e.cpu_seconds << " CPU s in a second thread)\n";
}

void print_run_warnings(const engine::Diagram& d, const engine::RunResult& r) {
  for (const std::string& w : r.stats.warnings)
    if (std::find(d.warnings.begin(), d.warnings.end(), w) == d.warnings.end()) std::cerr << "warning: " << w << "\n";
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::cerr << "warning: " << w << "\n";
}

bool split_range(const std::string& text, double& lo, double& hi, double& n) {
  std::stringstream ss(text);
  std::string a, b, c;
  return std::getline(ss, a, ':') && std::getline(ss, b, ':') && std::getline(ss, c) && engine::parse_number(a, lo) &&
         engine::parse_number(b, hi) && engine::parse_number(c, n);
}

int run_command(const RunArgs& args) {
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets));
  engine::apply_solver_overrides(d, args.solver);
  print_warnings(d.warnings);
  if (args.adjoint) {
    if (args.no_sens) throw engine::InputError("--adjoint", 0, "--no-sens", "--adjoint computes sensitivities: drop --no-sens");
    engine::check_adjoint_possible(d);
    d.set_sensitivities(engine::differentiable_parameters(d));  // every declared one that has a tangent
  }

  engine::RunOptions options;
  options.sensitivities = !args.no_sens;
  options.adjoint = args.adjoint;
  const bool tty = isatty(fileno(stderr));
  int last_percent = -1;
  options.progress = [&](double t) {
    const int percent = static_cast<int>(100 * (t - d.time.start) / (d.time.stop - d.time.start));
    if (!tty || percent == last_percent) return;
    last_percent = percent;
    std::cerr << "\r" << d.scene_name << ": t = " << std::fixed << std::setprecision(2) << t
              << " s  [" << percent << "%]" << std::flush;
  };
  engine::start_at_equilibrium(d);  // `initial: equilibrium`; the shadow run starts there too
  engine::RunResult r;
  if (args.no_estimate) {
    r = engine::run(d, options);
  } else {
    engine::Diagram shadow = engine::load_scene(args.scene, parse_sets(args.sets));
    engine::apply_solver_overrides(shadow, args.solver);
    r = engine::run_with_error_estimate(d, shadow, options);
  }
  if (tty) std::cerr << "\r" << std::string(60, ' ') << "\r";

  io::write_outputs(args.out, d, r);
  if (args.format == "mat") io::write_run_mat(args.out + "/run.mat", d, r);
  if (args.report) write_report(args.out, d, r);

  std::cout << d.scene_name << ": " << r.stats.method << ", " << r.stats.steps << " steps, "
            << std::setprecision(3) << r.stats.cpu_seconds << " CPU s for "
            << r.stats.simulated_seconds << " s simulated (" << std::setprecision(4)
            << r.stats.realtime_factor << "x real time)\n";
  print_limiting_states(std::cout, r.stats);
  print_error_estimate(std::cout, r.stats);
  print_run_warnings(d, r);
  for (const auto& o : r.objectives) {
    std::cout << "  " << o.name << " = " << std::setprecision(6) << o.value << (o.unit.empty() ? "" : " " + o.unit);
    for (size_t k = 0; k < o.sensitivity.size(); ++k) {
      const std::string& punit = d.parameters[d.find_parameter(r.sensitivity_names[k])].unit;
      const std::string u = engine::unit_per(o.unit, punit);
      std::cout << "   d/d" << r.sensitivity_names[k] << " = " << o.sensitivity[k] << (u.empty() ? "" : " " + u);
    }
    std::cout << "\n";
  }
  if (!d.pruned.empty()) {
    std::cout << "  pruned (no requested output needs them):";
    for (const auto& p : d.pruned) std::cout << " " << p;
    std::cout << "\n";
  }
  std::cout << "  results in " << args.out << "/ (signals.csv, objectives.json, run.json"
            << (args.format == "mat" ? ", run.mat" : "") << (args.report ? ", report.md" : "") << ")\n";
  return 0;
}

}  // namespace dydp::apps
