// dydp kc: the suspension kinematics of a scene's car (symbolic/mbs/suspension_kinematics.hpp)
// with the curves' derivatives with respect to the scene's parameters and directions that move
// the car's geometry; kc.json, one CSV per sweep, and with --report the K&C plots.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/gnuplot.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/block_settings.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/registry.hpp"
#include "generated_models/registry.hpp"
#include "io/files.hpp"
#include "io/mat_file.hpp"
#include "symbolic/mbs/suspension_kinematics.hpp"

namespace dydp::apps {
namespace {

using Json = nlohmann::ordered_json;

struct CarBlock {
  const engine::Node* node = nullptr;
  const mbs::GeneratedModel* model = nullptr;
};

CarBlock find_car(const engine::Diagram& d, const std::string& name) {
  for (const auto& n : d.nodes) {
    // multibody.MODEL, or multibody with a model: setting
    const std::string type = n.type ? n.type->name : "";
    std::string model;
    if (type.rfind("multibody.", 0) == 0) model = type.substr(std::string("multibody.").size());
    if (type == "multibody" && n.settings && n.settings->has("model")) model = n.settings->text("model");
    if (model.empty() || (!name.empty() && n.name != name)) continue;
    if (const mbs::GeneratedModel* g = generated::find_model(model)) return {&n, g};
  }
  if (!name.empty()) throw engine::InputError("--block", 0, name, "no multibody block of that name in " + d.file);
  throw engine::InputError(d.file, 0, "blocks", "no multibody block: kc analyses a generated car model");
}

// The derivative directions: the scene's parameters and directions driving the car's model
// parameters (a direction over several sums their derivatives), or, when none does, every model
// parameter by its own name.
struct Direction {
  std::string name;
  std::vector<int> model_parameters;
};

std::vector<Direction> directions(const engine::Diagram& d, const CarBlock& car) {
  const mbs::GeneratedModel& g = *car.model;
  std::vector<Direction> out;
  const auto& n = *car.node;
  for (size_t k = 0; k < d.parameters.size(); ++k) {
    Direction dir{d.parameters[k].name, {}};
    for (int j = 0; j < g.parameters && j < static_cast<int>(n.p_scene.size()); ++j)
      if (n.p_scene[static_cast<size_t>(j)] == static_cast<int>(k)) dir.model_parameters.push_back(j);
    if (!dir.model_parameters.empty()) out.push_back(dir);
  }
  if (out.empty())
    for (int j = 0; j < g.parameters; ++j) out.push_back({g.parameter_names[j], {j}});
  return out;
}

std::string column(const mbs::KinematicsCurve& c) { return c.quantity + "_" + c.corner; }

std::string format(double v, int digits = 4) {
  if (v == 0.0) v = 0.0;  // no "-0"
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

// The curve's value at the sweep's middle (the design position).
double at_design(const mbs::KinematicsCurve& c) { return c.values[c.values.size() / 2]; }

const mbs::KinematicsCurve* find_curve(const mbs::KinematicsSweep& s, const std::string& quantity,
                                       const std::string& corner) {
  for (const auto& c : s.curves)
    if (c.quantity == quantity && c.corner == corner) return &c;
  return nullptr;
}

std::string plot_script(const std::string& out, const std::string& name, const std::string& title,
                        const std::string& xlabel, const std::string& ylabel, const std::string& csv,
                        const std::vector<std::pair<int, std::string>>& columns, bool travel_vertical,
                        double x_scale) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 900,560\nset output '" << out << "/plots/" << name << ".png'\n"
     << "set termoption noenhanced\nset grid\nset datafile separator ','\nset key outside right\n"
     << "set title '" << title << "'\n";
  if (travel_vertical)
    gp << "set xlabel '" << ylabel << "'\nset ylabel '" << xlabel << "'\n";
  else
    gp << "set xlabel '" << xlabel << "'\nset ylabel '" << ylabel << "'\n";
  gp << "plot ";
  for (size_t i = 0; i < columns.size(); ++i) {
    const int c = columns[i].first;
    gp << (i ? ", " : "") << "'" << out << "/" << csv << "' using ";
    if (travel_vertical)
      gp << c << ":($1*" << x_scale << ")";
    else
      gp << "($1*" << x_scale << "):" << c;
    gp << " every ::1 with linespoints lw 2 pt 7 ps 0.5 title '" << columns[i].second << "'";
  }
  gp << "\n";
  return gp.str();
}

/// One kc invocation: the scene's car, its kinematics and what is written, shared by the steps.
class KcRun {
 public:
  explicit KcRun(const KcArgs& args) : args_(args), d_(engine::load_scene(args.scene, parse_sets(args.sets))) {}

  int run() {
    set_up();
    compute();
    document();
    write();
    for (const auto& s : r_.sweeps) (s.name == "bump" ? bump_ : s.name == "roll" ? roll_ : steer_) = &s;
    if (args_.report) report();
    print_summary();
    return 0;
  }

 private:
  // The car block, its model parameters and the sweep's settings checked.
  void set_up() {
    print_warnings(d_.warnings);
    car_ = find_car(d_, args_.block);
    const mbs::GeneratedModel& g = *car_.model;
    p_.assign(g.parameter_values, g.parameter_values + g.parameters);
    if (static_cast<int>(car_.node->p.size()) >= g.parameters)
      std::copy_n(car_.node->p.begin(), g.parameters, p_.begin());
    if (!(args_.travel > 0) || args_.travel > 0.3)
      throw engine::InputError("--travel", 0, format(args_.travel), "expected a wheel travel in (0, 0.3] m");
    if (args_.points < 3 || args_.points % 2 == 0)
      throw engine::InputError("--points", 0, std::to_string(args_.points),
                               "expected an odd number of points, at least 3");
  }

  // The derivative directions and the sweeps with the derivatives of their curves.
  void compute() {
    dirs_ = directions(d_, car_);
    mbs::KinematicsOptions o;
    o.bump = args_.travel;
    o.bump_points = args_.points;
    for (const auto& dir : dirs_)
      for (const int j : dir.model_parameters)
        if (column_of_.emplace(j, static_cast<int>(o.parameters.size())).second) o.parameters.push_back(j);

    try {
      r_ = mbs::suspension_kinematics(*car_.model, p_, o);
    } catch (const std::runtime_error& e) {
      throw engine::InputError(d_.file, car_.node->line, car_.node->name, e.what());
    }
  }

  // Derivatives per direction (summed over the model parameters it moves).
  std::vector<double> sensitivity(const mbs::KinematicsCurve& c, const Direction& dir) const {
    std::vector<double> s(c.values.size(), 0.0);
    for (const int j : dir.model_parameters)
      for (size_t i = 0; i < s.size(); ++i) s[i] += c.sensitivity[static_cast<size_t>(column_of_.at(j))][i];
    return s;
  }

  // kc.json's document and the sweeps' CSV texts.
  void document() {
    const mbs::GeneratedModel& g = *car_.model;
    doc_["scene"] = d_.file;
    doc_["block"] = car_.node->name;
    doc_["model"] = g.name;
    Json names = Json::array();
    for (const auto& dir : dirs_) names.push_back(dir.name);
    doc_["parameters"] = names;
    doc_["body"] = "held in its design attitude; wheel travel is the wheel centre's height from the design position";
    Json corners = Json::array();
    for (const auto& c : r_.corners)
      corners.push_back({{"name", c.name},
                         {"side", c.side > 0 ? "left" : "right"},
                         {"travel", g.coordinate_names[c.travel]}});
    doc_["corners"] = corners;
    Json sweeps = Json::array();
    for (const auto& s : r_.sweeps) sweeps.push_back(sweep(s));
    doc_["sweeps"] = sweeps;
    doc_["notes"] = r_.notes;
    doc_["poses"] = r_.poses;
  }

  // One sweep's part of kc.json, its CSV text kept in csvs_.
  Json sweep(const mbs::KinematicsSweep& s) {
    Json js{{"name", s.name}, {"variable", s.variable}, {"unit", s.unit}, {"x", s.x}};
    Json curves = Json::array();
    std::ostringstream csv;
    csv << std::setprecision(12) << s.variable << "_" << s.unit;
    for (const auto& c : s.curves) csv << "," << column(c) << "_" << c.unit;
    for (const auto& dir : dirs_)
      for (const auto& c : s.curves) csv << ",d(" << column(c) << ")/d(" << dir.name << ")";
    csv << "\n";
    std::vector<std::vector<std::vector<double>>> sens;  // [curve][direction][point]
    for (const auto& c : s.curves) {
      Json jc{{"corner", c.corner}, {"quantity", c.quantity}, {"unit", c.unit}, {"values", c.values},
              {"derivative", c.exact ? "exact" : "central differences of the exact rate"}};
      Json js_sens = Json::object();
      sens.emplace_back();
      for (const auto& dir : dirs_) {
        sens.back().push_back(sensitivity(c, dir));
        js_sens[dir.name] = sens.back().back();
      }
      jc["sensitivity"] = js_sens;
      curves.push_back(jc);
    }
    for (size_t i = 0; i < s.x.size(); ++i) {
      csv << s.x[i];
      for (const auto& c : s.curves) csv << "," << c.values[i];
      for (size_t k = 0; k < dirs_.size(); ++k)
        for (size_t c = 0; c < s.curves.size(); ++c) csv << "," << sens[c][k][i];
      csv << "\n";
    }
    js["curves"] = curves;
    csvs_["kc_" + s.name + ".csv"] = csv.str();
    return js;
  }

  // kc.json, the CSVs and with --format mat kc.mat written; their names kept in files_.
  void write() {
    // Everything computed: write.
    std::filesystem::create_directories(args_.out);
    io::write_file_atomically(args_.out + "/kc.json", doc_.dump(2) + "\n");
    files_ = "kc.json";
    for (const auto& [name, text] : csvs_) {
      io::write_file_atomically(args_.out + "/" + name, text);
      files_ += ", " + name;
    }
    if (args_.format == "mat") {
      io::MatFile mat(args_.out + "/kc.mat");
      mat.json("kc", doc_);
      mat.commit();
      files_ += ", kc.mat";
    }
  }

  // report.md: the plots, the design position's table and the derivatives' table.
  void report() {
    const mbs::GeneratedModel& g = *car_.model;
    std::ostringstream md;
    md << "# " << d_.scene_name << ": suspension kinematics of " << car_.node->name << " (" << g.name << ")\n\n"
       << "The body held in its design attitude; wheel travel is the wheel centre's height from the design "
          "position, all wheels together (bump +, rebound -). Toe-in and camber (top out) positive.\n\n";
    if (have_gnuplot() && bump_) report_plots(md);
    if (bump_) report_design(md);
    report_derivatives(md);
    io::write_file_atomically(args_.out + "/report.md", md.str());
    files_ += ", report.md";
  }

  // The bump sweep's plots drawn by gnuplot, each that was drawn linked in md.
  void report_plots(std::ostringstream& md) const {
    std::filesystem::create_directories(args_.out + "/plots");
    auto columns_of = [&](const mbs::KinematicsSweep& s, const std::string& quantity) {
      std::vector<std::pair<int, std::string>> cols;
      for (size_t c = 0; c < s.curves.size(); ++c)
        if (s.curves[c].quantity == quantity) cols.push_back({static_cast<int>(c) + 2, s.curves[c].corner});
      return cols;
    };
    const std::vector<std::tuple<std::string, std::string, std::string, bool>> plots = {
        {"toe", "bump steer: toe-in [deg]", "kc_bump_steer", true},
        {"camber", "camber [deg]", "kc_camber", true},
        {"spring_ratio", "spring motion ratio [-]", "kc_spring_ratio", false},
        {"roll_centre_height", "roll centre height above the contact [m]", "kc_roll_centre", false}};
    for (const auto& [quantity, label, name, vertical] : plots) {
      const auto cols = columns_of(*bump_, quantity);
      if (cols.empty()) continue;
      if (run_gnuplot(args_.out, name, plot_script(args_.out, name, label + " against wheel travel",
                                                   "wheel travel [mm]", label, "kc_bump.csv", cols, vertical, 1000.0)))
        md << "![" << name << "](plots/" << name << ".png)\n\n";
    }
  }

  // The table of each corner's bump curves at the design position.
  void report_design(std::ostringstream& md) const {
    md << "| corner | toe [deg] | camber [deg] | bump steer [deg/m] | camber gain [deg/m] | spring ratio | "
          "damper ratio | roll centre [mm] |\n|---|---|---|---|---|---|---|---|\n";
    for (const auto& c : r_.corners) {
      auto value = [&](const std::string& q) {
        const auto* curve = find_curve(*bump_, q, c.name);
        return curve ? format(at_design(*curve)) : std::string("-");
      };
      const auto* rch = find_curve(*bump_, "roll_centre_height", c.name);
      md << "| " << c.name << " | " << value("toe") << " | " << value("camber") << " | " << value("bump_steer") << " | "
         << value("camber_gain") << " | " << value("spring_ratio") << " | " << value("damper_ratio") << " | "
         << (rch ? format(1000 * at_design(*rch)) : "-") << " |\n";
    }
    md << "\n";
  }

  // The table of the bump curves' derivatives at the design position, per direction.
  void report_derivatives(std::ostringstream& md) const {
    md << "Derivatives at the design position with respect to the scene's geometry parameters and directions "
          "(position-level curves exact; rates by central differences of their exact values); the quantities "
          "no direction moves are left out:\n\n"
       << "| quantity | corner |";
    for (const auto& dir : dirs_) md << " d/d(" << dir.name << ") |";
    md << "\n|---|---|";
    for (size_t k = 0; k < dirs_.size(); ++k) md << "---|";
    md << "\n";
    if (bump_)
      for (const auto& c : bump_->curves) {
        const bool moved = std::any_of(dirs_.begin(), dirs_.end(), [&](const Direction& dir) {
          return sensitivity(c, dir)[c.values.size() / 2] != 0.0;
        });
        if (!moved) continue;  // toe and camber: no direction of the scene moves the linkage
        md << "| " << c.quantity << " [" << c.unit << "] | " << c.corner << " |";
        for (const auto& dir : dirs_) md << " " << format(sensitivity(c, dir)[c.values.size() / 2], 3) << " |";
        md << "\n";
      }
  }

  // The summary on stdout: the design position, roll and steering gains, notes and the files written.
  void print_summary() const {
    const mbs::GeneratedModel& g = *car_.model;
    std::cout << d_.scene_name << ": suspension kinematics of " << car_.node->name << " (" << g.name << "), "
              << r_.corners.size() << " corners, " << r_.sweeps.size() << " sweeps, " << r_.poses << " poses\n";
    if (bump_) {
      std::cout << "  at the design position          toe     camber  bump steer  camber gain  spring  damper  "
                   "roll centre\n"
                   "                                  [deg]   [deg]   [deg/m]     [deg/m]      ratio   ratio   [mm]\n";
      for (const auto& c : r_.corners) {
        auto value = [&](const std::string& q, double scale = 1.0) {
          const auto* curve = find_curve(*bump_, q, c.name);
          return curve ? at_design(*curve) * scale : std::nan("");
        };
        std::cout << "  " << std::left << std::setw(30) << c.name << std::right << std::fixed << std::setprecision(3)
                  << std::setw(8) << value("toe") << std::setw(8) << value("camber") << std::setw(10)
                  << value("bump_steer") << std::setw(13) << value("camber_gain") << std::setw(9)
                  << value("spring_ratio") << std::setw(8) << value("damper_ratio") << std::setw(11)
                  << value("roll_centre_height", 1000.0) << "\n"
                  << std::defaultfloat;
      }
    }
    if (roll_)
      for (const auto& c : r_.corners) {
        const auto* st = find_curve(*roll_, "roll_steer", c.name);
        const auto* ca = find_curve(*roll_, "roll_camber", c.name);
        if (st && ca)
          std::cout << "  roll " << c.name << ": roll steer " << format(at_design(*st), 3) << " deg/deg, roll camber "
                    << format(at_design(*ca), 3) << " deg/deg\n";
      }
    if (steer_)
      for (const auto& curve : steer_->curves)
        if (curve.quantity == "steering_gain")
          std::cout << "  steer " << curve.corner << ": " << format(at_design(curve) / 1000.0, 4) << " deg per mm of "
                    << steer_->variable << "\n";
    for (const auto& note : r_.notes) std::cout << "  note: " << note << "\n";
    std::cout << "wrote " << args_.out << "/: " << files_ << "\n";
  }

  const KcArgs& args_;
  engine::Diagram d_;
  CarBlock car_;
  std::vector<double> p_;  // the car model's parameter values in the scene
  std::vector<Direction> dirs_;
  std::map<int, int> column_of_;  // model parameter -> derivative column
  mbs::KinematicsResult r_;
  Json doc_;
  std::map<std::string, std::string> csvs_;  // file name -> text
  std::string files_;                        // the files written, for the summary
  const mbs::KinematicsSweep* bump_ = nullptr;
  const mbs::KinematicsSweep* roll_ = nullptr;
  const mbs::KinematicsSweep* steer_ = nullptr;
};

}  // namespace

int kc_command(const KcArgs& args) { return KcRun(args).run(); }

}  // namespace dydp::apps
