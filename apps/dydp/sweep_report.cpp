#include <cmath>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "apps/dydp/gnuplot.hpp"
#include "apps/dydp/report.hpp"
#include "io/files.hpp"

namespace dydp::apps {
namespace {

/// Data files for gnuplot: one per figure, whitespace separated.
void write_data(const std::string& path, const std::string& text) { io::write_file_atomically(path, text); }

}  // namespace

void write_sweep_report(const std::string& dir, const std::string& scene, const engine::SweepResult& r,
                        double delta) {
  std::filesystem::create_directories(dir + "/plots");
  const std::string& P = r.parameter;
  const std::string unit = r.unit.empty() ? "" : " [" + r.unit + "]";
  const int no = static_cast<int>(r.objectives.size());
  std::ostringstream md;
  md << std::setprecision(6);
  md << "# Sweep of " << P << " on " << scene << "\n\n";
  md << r.points.size() << " runs over " << P << " in [" << r.points.front().p << ", " << r.points.back().p
     << "]" << unit << ", each with the exact sensitivity d(psi)/d(" << P << ") (direct method).\n\n";
  for (int o = 0; o < no; ++o) {
    const std::string& ou = r.objective_units[o];
    const std::string du = engine::unit_per(ou, r.unit);
    md << "## " << r.objectives[o] << "\n\n| " << P << unit << " | psi" << (ou.empty() ? "" : " [" + ou + "]")
       << " | d(psi)/dp" << (du.empty() ? "" : " [" + du + "]") << " | % per % |";
    if (delta > 0) md << " change for +" << delta << " |";
    md << "\n|---|---|---|---|" << (delta > 0 ? "---|" : "") << "\n";
    for (const auto& pt : r.points) {
      md << "| " << pt.p << " | " << pt.psi[o] << " | " << pt.dpsi[o] << " | "
         << (pt.psi[o] != 0 ? pt.p / pt.psi[o] * pt.dpsi[o] : 0.0) << " |";
      if (delta > 0) md << " " << pt.dpsi[o] * delta << " |";
      md << "\n";
    }
    md << "\n";
  }

  if (!have_gnuplot()) {
    md << "gnuplot was not found on the PATH: no plots were made (install gnuplot-nox).\n";
    io::write_file_atomically(dir + "/report.md", md.str());
    return;
  }
  std::ostringstream gp;
  gp << std::setprecision(12);
  gp << "set terminal pngcairo noenhanced size 900,640 font 'Sans,10'\nset grid\nset key outside right top\n";

  // psi and d(psi)/dp against p, with the tangent drawn at every point.
  for (int o = 0; o < no; ++o) {
    const std::string name = file_safe(r.objectives[o]);
    std::ostringstream data;
    data << std::setprecision(12);
    const double span = r.points.size() > 1 ? (r.points.back().p - r.points.front().p) / (r.points.size() - 1) : 1.0;
    for (const auto& pt : r.points)
      data << pt.p << ' ' << pt.psi[o] << ' ' << pt.dpsi[o] << ' ' << 0.3 * span << ' ' << 0.3 * span * pt.dpsi[o] << '\n';
    write_data(dir + "/plots/sweep_" + name + ".dat", data.str());
    const std::string& ou = r.objective_units[o];
    const std::string du = engine::unit_per(ou, r.unit);
    gp << "set output '" << dir << "/plots/sweep_" << name << ".png'\n"
       << "set multiplot layout 2,1 title '" << r.objectives[o] << " against " << P << "'\n"
       << "set xlabel '" << P << unit << "'\nset ylabel '" << r.objectives[o]
       << (ou.empty() ? "" : " [" + ou + "]") << "'\n"
       << "plot '" << dir << "/plots/sweep_" << name << ".dat' using 1:2 with linespoints pt 7 title 'psi', "
       << "'' using ($1-$4/2):($2-$5/2):4:5 with vectors nohead lw 2 title 'tangent d(psi)/dp'\n"
       << "set ylabel 'd(" << r.objectives[o] << ")/d(" << P << ")"
       << (du.empty() ? "" : " [" + du + "]") << "'\n"
       << "plot '" << dir << "/plots/sweep_" << name << ".dat' using 1:3 with linespoints pt 7 title 'exact d(psi)/dp'\n"
       << "unset multiplot\n";
    md << "![" << r.objectives[o] << "](plots/sweep_" << name << ".png)\n\n";
  }

  // Finite-difference error against step, at every point: the exact derivative has no step.
  if (!r.fd_steps.empty()) {
    for (int o = 0; o < no; ++o) {
      const std::string name = file_safe(r.objectives[o]);
      std::ostringstream data;
      data << std::setprecision(12);
      for (size_t k = 0; k < r.points.size(); ++k) {
        for (size_t s = 0; s < r.fd_steps.size(); ++s)
          data << r.fd_steps[s] << ' '
               << std::max(std::fabs(r.points[k].fd[s][o] - r.points[k].dpsi[o]) /
                               std::max(std::fabs(r.points[k].dpsi[o]), 1e-300), 1e-17)
               << '\n';
        data << "\n\n";
      }
      write_data(dir + "/plots/fd_error_" + name + ".dat", data.str());
      gp << "set output '" << dir << "/plots/fd_error_" << name << ".png'\n"
         << "set logscale xy\nset format y '%.0e'\nset format x '%.0e'\nset xlabel 'finite-difference step in " << P << unit << "'\n"
         << "set ylabel 'relative error of the central difference'\nset title '" << r.objectives[o]
         << ": central differences against the exact derivative'\nplot ";
      for (size_t k = 0; k < r.points.size(); ++k)
        gp << (k ? ", " : "") << "'" << dir << "/plots/fd_error_" << name << ".dat' index " << k
           << " using 1:2 with linespoints title '" << P << " = " << r.points[k].p << "'";
      gp << "\nunset logscale\nset format y '%g'\nset format x '%g'\nset title ''\n";
      md << "![finite-difference error](plots/fd_error_" << name << ".png)\n\n";
    }
  }

  // The first logged signal: trajectories for every p, and its sensitivity as a surface over (t, p).
  if (!r.points.front().run.signal_names.empty()) {
    const auto& first = r.points.front().run;
    const std::string sig = first.signal_names[0];
    std::ostringstream traj, surf;
    double extreme = 0;
    for (const auto& pt : r.points)
      for (size_t k = 0; k < pt.run.t.size(); ++k)
        extreme = std::max(extreme, std::fabs(pt.run.tangent(static_cast<int>(k), 0, 0)));
    traj << std::setprecision(10);
    surf << std::setprecision(10);
    for (const auto& pt : r.points) {
      for (size_t k = 0; k < pt.run.t.size(); ++k) {
        traj << pt.run.t[k] << ' ' << pt.run.value(static_cast<int>(k), 0) << '\n';
        surf << pt.run.t[k] << ' ' << pt.p << ' ' << pt.run.tangent(static_cast<int>(k), 0, 0) << '\n';
      }
      traj << "\n\n";
      surf << "\n";
    }
    write_data(dir + "/plots/trajectories.dat", traj.str());
    write_data(dir + "/plots/sensitivity_surface.dat", surf.str());
    gp << "set output '" << dir << "/plots/trajectories.png'\nset xlabel 't [s]'\nset ylabel '" << sig
       << "'\nset title '" << sig << " for several " << P << "'\nplot ";
    for (size_t k = 0; k < r.points.size(); ++k)
      gp << (k ? ", " : "") << "'" << dir << "/plots/trajectories.dat' index " << k << " with lines title '"
         << P << " = " << r.points[k].p << "'";
    gp << "\nset output '" << dir << "/plots/sensitivity_surface.png'\nset title 'd(" << sig << ")/d(" << P
       << ") over time and " << P << "'\nset xlabel 't [s]'\nset ylabel '" << P << unit
       << "'\nset view map\nset pm3d at b\nunset key\n"
       << "set palette defined (0 '#2166ac', 0.5 '#f7f7f7', 1 '#b2182b')\nset cbrange [" << -extreme << ":"
       << (extreme > 0 ? extreme : 1.0) << "]\nsplot '" << dir
       << "/plots/sensitivity_surface.dat' using 1:2:3 with pm3d\n";
    md << "![trajectories](plots/trajectories.png)\n\n![sensitivity surface](plots/sensitivity_surface.png)\n\n";
  }
  if (!run_gnuplot(dir, "sweep", gp.str())) md << "gnuplot failed: see plots/sweep.log.\n";
  io::write_file_atomically(dir + "/report.md", md.str());
}

}  // namespace dydp::apps
