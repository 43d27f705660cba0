#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/gnuplot.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/accuracy.hpp"
#include "io/files.hpp"

namespace dydp::apps {
namespace {

std::string accuracy_csv(const engine::AccuracyReport& r) {
  std::ostringstream out;
  out << std::setprecision(6);
  out << "method,setting,ok,cpu_seconds,steps,rhs_evaluations,sensitivity_rhs_evaluations,"
         "jacobian_evaluations,signal_error,objective_error,sensitivity_error,signal_sensitivity_error,failure\n";
  for (const auto& row : r.rows) {
    out << row.method << ',' << row.setting << ',' << (row.ok ? 1 : 0) << ',' << row.stats.cpu_seconds << ','
        << row.stats.steps << ',' << row.stats.rhs_evals << ',' << row.stats.sens_rhs_evals << ','
        << row.stats.jac_evals << ',' << row.signal_error << ',' << row.objective_error << ','
        << row.sensitivity_error << ',' << row.signal_sensitivity_error << ",\"";
    for (char c : row.failure) out << (c == '"' ? '\'' : c);
    out << "\"\n";
  }
  return out.str();
}

}  // namespace

int accuracy_command(const AccuracyArgs& args) {
  // A relative accuracy: above 0 (none is reached exactly), below 1 (100 % says nothing).
  if (!(args.target > 0 && args.target < 1))
    throw engine::InputError("--target", 0, engine::format_number(args.target),
                             "outside (0, 1): a relative accuracy");
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets));
  engine::apply_solver_overrides(d, args.solver);
  print_warnings(d.warnings);
  engine::AccuracySpec spec;
  spec.methods = args.methods;
  // With a setting on the command line, the study measures that setting (one row beside the
  // reference), and the ladder only over methods named with --methods.
  if (!args.solver.empty()) {
    spec.given_setting = true;
    if (!args.methods_given) spec.methods.clear();
  }
  std::cerr << "accuracy: reference run (bdf, rtol " << spec.reference_rtol << ") and its check...\n";
  const engine::AccuracyReport r = engine::accuracy_study(d, spec, [](const engine::AccuracyRow& row) {
    std::cerr << "  " << std::left << std::setw(7) << row.method << std::setw(10) << row.setting
              << std::right << std::setprecision(3);
    if (row.ok)
      std::cerr << std::setw(8) << row.stats.cpu_seconds << " CPU s, signal error " << std::setw(9) << row.signal_error
                << ", sensitivity error " << std::setw(9) << row.sensitivity_error << "\n";
    else
      std::cerr << "failed: " << row.failure << "\n";
  });

  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/accuracy.csv", accuracy_csv(r));

  std::ostringstream md;
  md << std::setprecision(3);
  md << "# Error against run time: " << d.scene_name << "\n\n"
     << "Reference: BDF at rtol " << r.reference_rtol << " (" << r.reference_stats.cpu_seconds
     << " CPU s). Tightened tenfold it changes by " << r.reference_check
     << " (relative), the floor below which errors are not resolved.\n\n"
     << "Errors are relative: signals to each signal's largest magnitude, objectives and their "
        "sensitivities to their reference values; the worst over the output grid.\n\n"
     << "| method | rtol or step [s] | CPU s | steps | signals | objectives | d(psi)/dp | d(signals)/dp |\n"
     << "|---|---|---|---|---|---|---|---|\n";
  for (const auto& row : r.rows) {
    md << "| " << row.method << " | " << row.setting << " | ";
    if (!row.ok) {
      md << "failed: " << row.failure << " | | | | | |\n";
      continue;
    }
    md << row.stats.cpu_seconds << " | " << row.stats.steps << " | " << row.signal_error << " | "
       << row.objective_error << " | " << row.sensitivity_error << " | " << row.signal_sensitivity_error << " |\n";
  }
  const engine::AccuracyRow* best = engine::cheapest_for(r, args.target);
  std::ostringstream verdict;
  verdict << std::setprecision(3);
  if (best)
    verdict << "Cheapest setting for errors below " << args.target << ": " << best->method
            << (best->method.rfind("bdf", 0) == 0 || best->method.rfind("adams", 0) == 0 ? " at rtol " : " at step ") << best->setting
            << " (" << best->stats.cpu_seconds << " CPU s).";
  else
    verdict << "No setting of the ladder reaches errors below " << args.target << ".";
  md << "\n" << verdict.str() << "\n";

  if (have_gnuplot()) {
    std::ostringstream gp;
    gp << "set terminal pngcairo noenhanced size 900,640 font 'Sans,10'\nset datafile separator ','\n"
       << "set grid\nset logscale xy\nset format x '%.0e'\nset format y '%.0e'\n"
       << "set xlabel 'CPU time [s]'\nset key outside right top\n"
       << "set output '" << args.out << "/plots/accuracy.png'\nset multiplot layout 2,1\n";
    for (const char* what : {"objective", "sensitivity"}) {
      const int column = std::string(what) == "objective" ? 10 : 11;
      gp << "set ylabel '" << what << " error (relative)'\nplot ";
      bool first = true;
      for (const char* method : {"bdf", "adams", "rk4", "sdirk2", "rosw"}) {
        gp << (first ? "" : ", ") << "'" << args.out << "/accuracy.csv' every ::1 using "
           << "(strcol(1) eq '" << method << "' && $3 == 1 ? $4 : 1/0):(($" << column << ") > 1e-16 ? $"
           << column << " : 1e-16) with linespoints title '" << method << "'";
        first = false;
      }
      gp << "\n";
    }
    gp << "unset multiplot\n";
    if (run_gnuplot(args.out, "accuracy", gp.str())) md << "\n![error against CPU time](plots/accuracy.png)\n";
  }
  io::write_file_atomically(args.out + "/accuracy.md", md.str());
  std::cout << md.str();
  return 0;
}

}  // namespace dydp::apps
