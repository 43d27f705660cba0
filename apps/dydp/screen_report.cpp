// report.md of a screening study: per objective the ranking as a table and a tornado chart, and
// per parameter psi and d(psi)/dp_i against p_i over the samples (gnuplot PNG).
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "apps/dydp/gnuplot.hpp"
#include "apps/dydp/report.hpp"
#include "io/files.hpp"

namespace dydp::apps {

void write_screen_report(const std::string& dir, const std::string& scene, const engine::ScreenResult& r) {
  std::filesystem::create_directories(dir + "/plots");
  const int P = static_cast<int>(r.ranges.size()), O = static_cast<int>(r.objectives.size());
  std::ostringstream md;
  md << std::setprecision(4);
  md << "# Screening of " << P << " parameters on " << scene << "\n\n"
     << r.samples.size() << " Sobol' points over the parameters' ranges and the nominal point, each one run with all "
     << P << " exact sensitivities (direct method). For each objective psi: nu_i = E[(dpsi/dp_i)^2] over the box, "
     << "the bound it gives on the total Sobol' index, S_Ti <= (b_i - a_i)^2 nu_i / (pi^2 Var psi) (Sobol' and "
     << "Kucherenko 2009), the share (b_i - a_i)^2 nu_i / sum_j (b_j - a_j)^2 nu_j, the swing E[dpsi/dp_i] (b_i - a_i) "
     << "(the change of psi across the range at the mean slope) and the local normalised sensitivity "
     << "(p_i / psi) dpsi/dp_i at the nominal point.\n\n";
  md << "| parameter | unit | range | nominal |\n|---|---|---|---|\n";
  for (int i = 0; i < P; ++i)
    md << "| " << r.ranges[i].name << " | " << r.units[i] << " | [" << r.ranges[i].lower << ", " << r.ranges[i].upper
       << "] | " << r.ranges[i].nominal << " |\n";
  md << "\n";

  const bool plots = have_gnuplot();
  std::ostringstream gp;
  gp << std::setprecision(12);
  gp << "set terminal pngcairo noenhanced size 900,640 font 'Sans,10'\nset grid\n";
  for (int o = 0; o < O; ++o) {
    const auto& e = r.estimates[o];
    const std::string& ou = r.objective_units[o];
    const std::string name = file_safe(r.objectives[o]);
    md << "## " << r.objectives[o] << "\n\nmean " << e.mean << (ou.empty() ? "" : " " + ou) << ", standard deviation "
       << std::sqrt(e.variance) << ", nominal " << r.nominal.psi[o] << ".\n\n"
       << "| rank | parameter | S_T bound | share | swing" << (ou.empty() ? "" : " [" + ou + "]")
       << " | % per % at nominal | nu |\n|---|---|---|---|---|---|---|\n";
    for (int i : e.ranking) {
      const auto& m = e.parameters[i];
      md << "| " << m.rank << " | " << r.ranges[i].name << " | " << m.total_index_bound << " | " << m.normalised
         << " | " << m.mean_gradient * (r.ranges[i].upper - r.ranges[i].lower) << " | " << m.local_normalised << " | "
         << m.nu << " |\n";
    }
    md << "\n";
    if (!plots) continue;

    // Tornado: one bar per parameter, largest share on top, from the nominal psi to psi at the
    // range's low and high ends at the mean slope; the label gives the bound on S_Ti.
    std::ostringstream tornado;
    tornado << std::setprecision(12);
    size_t longest = 0;
    for (int rank = 0; rank < P; ++rank) {
      const int i = e.ranking[rank];
      const auto& m = e.parameters[i];
      const double low = m.mean_gradient * (r.ranges[i].lower - r.ranges[i].nominal);
      const double high = m.mean_gradient * (r.ranges[i].upper - r.ranges[i].nominal);
      std::ostringstream label;
      label << std::setprecision(2) << r.ranges[i].name << " (S_T <= " << m.total_index_bound << ")";
      longest = std::max(longest, label.str().size());
      tornado << P - rank << ' ' << std::min(low, high) << ' ' << std::max(low, high) << ' ' << high << " \""
              << label.str() << "\"\n";
    }
    io::write_file_atomically(dir + "/plots/tornado_" + name + ".dat", tornado.str());
    gp << "set output '" << dir << "/plots/tornado_" << name << ".png'\n"
       << "set title '" << r.objectives[o] << ": psi at the ends of each range (mean slope), ranked'\n"
       << "set xlabel 'psi - psi_nominal" << (ou.empty() ? "" : " [" + ou + "]") << "'\nunset ylabel\n"
       << "set yrange [0.4:" << P + 0.6 << "]\nset ytics scale 0\nset style fill solid 0.8 border -1\nset key bottom right\n"
       << "set lmargin " << longest + 2 << "\n"
       << "plot '" << dir << "/plots/tornado_" << name << ".dat' using (($2+$3)/2):1:2:3:($1-0.35):($1+0.35):ytic(5) "
       << "with boxxyerror lc rgb '#4575b4' title 'low end to high end', '' using 4:1 with points pt 7 lc rgb '#d73027' "
       << "title 'high end'\n"
       << "unset ytics\nset ytics\nset autoscale y\nset lmargin\nset key default\n";
    md << "![tornado chart of " << r.objectives[o] << "](plots/tornado_" << name << ".png)\n\n";

    // psi and dpsi/dp_i against p_i over the samples, one row per parameter.
    std::ostringstream samples;
    samples << std::setprecision(12);
    for (const auto& s : r.samples) {
      for (int i = 0; i < P; ++i) samples << s.p[i] << ' ';
      samples << s.psi[o];
      for (int i = 0; i < P; ++i) samples << ' ' << s.gradient[o][i];
      samples << '\n';
    }
    io::write_file_atomically(dir + "/plots/samples_" + name + ".dat", samples.str());
    gp << "set output '" << dir << "/plots/samples_" << name << ".png'\n"
       << "set terminal pngcairo noenhanced size 900," << 40 + 220 * P << " font 'Sans,9'\n"
       << "set multiplot layout " << P << ",2 title '" << r.objectives[o] << " and its derivatives over the samples'\n"
       << "unset key\nunset title\n";
    for (int i = 0; i < P; ++i) {
      const std::string du = engine::unit_per(ou, r.units[i]);
      const std::string pu = r.units[i].empty() ? "" : " [" + r.units[i] + "]";
      gp << "set xlabel '" << r.ranges[i].name << pu << "'\nset ylabel 'psi'\n"
         << "plot '" << dir << "/plots/samples_" << name << ".dat' using " << i + 1 << ":" << P + 1 << " with points pt 7 ps 0.6\n"
         << "set ylabel 'd(psi)/d(p)" << (du.empty() ? "" : " [" + du + "]") << "'\n"
         << "plot '" << dir << "/plots/samples_" << name << ".dat' using " << i + 1 << ":" << P + 2 + i
         << " with points pt 7 ps 0.6 lc rgb '#d73027'\n";
    }
    gp << "unset multiplot\nset terminal pngcairo noenhanced size 900,640 font 'Sans,10'\n";
    md << "![" << r.objectives[o] << " against each parameter over the samples](plots/samples_" << name << ".png)\n\n";
  }
  if (!plots) {
    md << "gnuplot was not found on the PATH: no plots were made (install gnuplot-nox).\n";
  } else if (!run_gnuplot(dir, "screen", gp.str())) {
    md << "gnuplot failed: see plots/screen.log.\n";
  }
  io::write_file_atomically(dir + "/report.md", md.str());
}

}  // namespace dydp::apps
