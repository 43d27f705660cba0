#include "apps/dydp/report.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "apps/dydp/gnuplot.hpp"
#include "io/files.hpp"

namespace dydp::apps {
namespace {

std::string unit_of(const engine::Diagram& d, const std::string& signal) {
  const std::string port = signal.substr(0, signal.find('['));
  const auto dot = port.find('.');
  for (const auto& n : d.nodes)
    if (n.name == port.substr(0, dot))
      for (const auto& p : n.block->outputs())
        if (p.name == port.substr(dot + 1)) return p.unit;
  return "";
}

}  // namespace

void write_report(const std::string& dir, const engine::Diagram& d, const engine::RunResult& r) {
  const int nsig = r.num_signals();
  const int ns = static_cast<int>(r.sensitivity_names.size());
  std::ostringstream md;
  md << std::setprecision(6);
  md << "# " << d.scene_name << "\n\n";
  md << "Scene `" << d.file << "`, " << r.stats.method << " (rtol " << r.stats.rtol << ", atol "
     << r.stats.atol << "): " << r.stats.steps << " steps, " << r.stats.cpu_seconds
     << " CPU s for " << r.stats.simulated_seconds << " s simulated, " << r.stats.realtime_factor
     << "x real time.\n\n";

  md << "## Parameters\n\n| parameter | value | unit | sensitivity direction |\n|---|---|---|---|\n";
  for (size_t i = 0; i < d.parameters.size(); ++i) {
    const auto& p = d.parameters[i];
    bool dir = false;
    for (const auto& s : r.sensitivity_names) dir = dir || s == p.name;
    md << "| " << p.name << " | " << p.value << " | " << p.unit << " | " << (dir ? "yes" : "") << " |\n";
  }

  if (!r.objectives.empty()) {
    md << "\n## Objectives\n\nNormalised sensitivity: (p / psi) d(psi)/dp, the % change of psi for "
          "1 % change of p.\n\n| objective | psi | parameter | d(psi)/dp | normalised |\n|---|---|---|---|---|\n";
    const auto with_unit = [](double v, const std::string& u) {
      std::ostringstream s;
      s << std::setprecision(6) << v << (u.empty() ? "" : " " + u);
      return s.str();
    };
    for (const auto& o : r.objectives) {
      if (ns == 0) md << "| " << o.name << " | " << with_unit(o.value, o.unit) << " | | | |\n";
      for (int k = 0; k < ns; ++k) {
        const auto& sp = d.parameters[d.find_parameter(r.sensitivity_names[k])];
        md << "| " << o.name << " | " << with_unit(o.value, o.unit) << " | " << r.sensitivity_names[k]
           << (sp.unit.empty() ? "" : " [" + sp.unit + "]") << " | "
           << with_unit(o.sensitivity[k], engine::unit_per(o.unit, sp.unit)) << " | "
           << (o.value != 0 ? sp.value / o.value * o.sensitivity[k] : 0.0) << " |\n";
      }
    }
  }

  md << "\n## Signals\n\n";
  if (!have_gnuplot()) {
    md << "gnuplot was not found on the PATH: no plots were made (install gnuplot-nox).\n";
  } else {
    std::ostringstream gp;
    gp << "set terminal pngcairo noenhanced size 900,640 font 'Sans,10'\nset datafile separator ','\n"
          "set grid\nset key outside right top\n";
    for (int i = 0; i < nsig; ++i) {
      const std::string& name = r.signal_names[i];
      const std::string unit = unit_of(d, name);
      const std::string png = "plots/" + file_safe(name) + ".png";
      gp << "set output '" << dir << "/" << png << "'\n";
      gp << "set multiplot layout " << (ns > 0 ? 2 : 1) << ",1 title '" << name << "'\n";
      gp << "set xlabel 't [s]'\nset ylabel '" << name << (unit.empty() ? "" : " [" + unit + "]") << "'\n";
      gp << "plot '" << dir << "/signals.csv' every ::1 using 1:" << i + 2 << " with lines lw 1.5 title 'value'\n";
      if (ns > 0) {
        gp << "set ylabel 'p * d(" << name << ")/dp" << (unit.empty() ? "" : " [" + unit + "]") << "'\n";
        gp << "plot ";
        for (int k = 0; k < ns; ++k) {
          const double p = d.parameters[d.find_parameter(r.sensitivity_names[k])].value;
          gp << (k ? ", " : "") << "'" << dir << "/signals.csv' every ::1 using 1:($"
             << 2 + nsig * (k + 1) + i << "*" << std::setprecision(17) << p << ") with lines lw 1.5 title '"
             << r.sensitivity_names[k] << "'";
        }
        gp << "\n";
      }
      gp << "unset multiplot\n";
      md << "### " << name << "\n\n![" << name << "](" << png << ")\n\n";
    }
    if (!run_gnuplot(dir, "signals", gp.str())) md << "gnuplot failed: see plots/signals.log.\n";
  }
  if (ns > 0)
    md << "Lower panels: sensitivities scaled by their parameter's value, p * dS/dp, the change of S "
          "(in its unit) for a 100 % change of p, to first order.\n";
  io::write_file_atomically(dir + "/report.md", md.str());
}

}  // namespace dydp::apps
