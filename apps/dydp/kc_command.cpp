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

}  // namespace

int kc_command(const KcArgs& args) {
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets));
  print_warnings(d.warnings);
  const CarBlock car = find_car(d, args.block);
  const mbs::GeneratedModel& g = *car.model;
  std::vector<double> p(g.parameter_values, g.parameter_values + g.parameters);
  if (static_cast<int>(car.node->p.size()) >= g.parameters) std::copy_n(car.node->p.begin(), g.parameters, p.begin());
  if (!(args.travel > 0) || args.travel > 0.3)
    throw engine::InputError("--travel", 0, format(args.travel), "expected a wheel travel in (0, 0.3] m");
  if (args.points < 3 || args.points % 2 == 0)
    throw engine::InputError("--points", 0, std::to_string(args.points), "expected an odd number of points, at least 3");

  const std::vector<Direction> dirs = directions(d, car);
  mbs::KinematicsOptions o;
  o.bump = args.travel;
  o.bump_points = args.points;
  std::map<int, int> column_of;  // model parameter -> derivative column
  for (const auto& dir : dirs)
    for (const int j : dir.model_parameters)
      if (column_of.emplace(j, static_cast<int>(o.parameters.size())).second) o.parameters.push_back(j);

  mbs::KinematicsResult r;
  try {
    r = mbs::suspension_kinematics(g, p, o);
  } catch (const std::runtime_error& e) {
    throw engine::InputError(d.file, car.node->line, car.node->name, e.what());
  }
  // Derivatives per direction (summed over the model parameters it moves).
  auto sensitivity = [&](const mbs::KinematicsCurve& c, const Direction& dir) {
    std::vector<double> s(c.values.size(), 0.0);
    for (const int j : dir.model_parameters)
      for (size_t i = 0; i < s.size(); ++i) s[i] += c.sensitivity[static_cast<size_t>(column_of.at(j))][i];
    return s;
  };

  Json doc;
  doc["scene"] = d.file;
  doc["block"] = car.node->name;
  doc["model"] = g.name;
  Json names = Json::array();
  for (const auto& dir : dirs) names.push_back(dir.name);
  doc["parameters"] = names;
  doc["body"] = "held in its design attitude; wheel travel is the wheel centre's height from the design position";
  Json corners = Json::array();
  for (const auto& c : r.corners)
    corners.push_back({{"name", c.name}, {"side", c.side > 0 ? "left" : "right"}, {"travel", g.coordinate_names[c.travel]}});
  doc["corners"] = corners;
  Json sweeps = Json::array();
  std::map<std::string, std::string> csvs;
  for (const auto& s : r.sweeps) {
    Json js{{"name", s.name}, {"variable", s.variable}, {"unit", s.unit}, {"x", s.x}};
    Json curves = Json::array();
    std::ostringstream csv;
    csv << std::setprecision(12) << s.variable << "_" << s.unit;
    for (const auto& c : s.curves) csv << "," << column(c) << "_" << c.unit;
    for (const auto& dir : dirs)
      for (const auto& c : s.curves) csv << ",d(" << column(c) << ")/d(" << dir.name << ")";
    csv << "\n";
    std::vector<std::vector<std::vector<double>>> sens;  // [curve][direction][point]
    for (const auto& c : s.curves) {
      Json jc{{"corner", c.corner}, {"quantity", c.quantity}, {"unit", c.unit}, {"values", c.values},
              {"derivative", c.exact ? "exact" : "central differences of the exact rate"}};
      Json js_sens = Json::object();
      sens.emplace_back();
      for (const auto& dir : dirs) {
        sens.back().push_back(sensitivity(c, dir));
        js_sens[dir.name] = sens.back().back();
      }
      jc["sensitivity"] = js_sens;
      curves.push_back(jc);
    }
    for (size_t i = 0; i < s.x.size(); ++i) {
      csv << s.x[i];
      for (const auto& c : s.curves) csv << "," << c.values[i];
      for (size_t k = 0; k < dirs.size(); ++k)
        for (size_t c = 0; c < s.curves.size(); ++c) csv << "," << sens[c][k][i];
      csv << "\n";
    }
    js["curves"] = curves;
    sweeps.push_back(js);
    csvs["kc_" + s.name + ".csv"] = csv.str();
  }
  doc["sweeps"] = sweeps;
  doc["notes"] = r.notes;
  doc["poses"] = r.poses;

  // Everything computed: write.
  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/kc.json", doc.dump(2) + "\n");
  std::string files = "kc.json";
  for (const auto& [name, text] : csvs) {
    io::write_file_atomically(args.out + "/" + name, text);
    files += ", " + name;
  }
  if (args.format == "mat") {
    io::MatFile mat(args.out + "/kc.mat");
    mat.json("kc", doc);
    mat.commit();
    files += ", kc.mat";
  }

  const mbs::KinematicsSweep* bump = nullptr;
  const mbs::KinematicsSweep* roll = nullptr;
  const mbs::KinematicsSweep* steer = nullptr;
  for (const auto& s : r.sweeps) (s.name == "bump" ? bump : s.name == "roll" ? roll : steer) = &s;

  if (args.report) {
    std::ostringstream md;
    md << "# " << d.scene_name << ": suspension kinematics of " << car.node->name << " (" << g.name << ")\n\n"
       << "The body held in its design attitude; wheel travel is the wheel centre's height from the design "
          "position, all wheels together (bump +, rebound -). Toe-in and camber (top out) positive.\n\n";
    if (have_gnuplot() && bump) {
      std::filesystem::create_directories(args.out + "/plots");
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
        const auto cols = columns_of(*bump, quantity);
        if (cols.empty()) continue;
        if (run_gnuplot(args.out, name, plot_script(args.out, name, label + " against wheel travel",
                                                    "wheel travel [mm]", label, "kc_bump.csv", cols, vertical, 1000.0)))
          md << "![" << name << "](plots/" << name << ".png)\n\n";
      }
    }
    if (bump) {
      md << "| corner | toe [deg] | camber [deg] | bump steer [deg/m] | camber gain [deg/m] | spring ratio | damper ratio | "
            "roll centre [mm] |\n|---|---|---|---|---|---|---|---|\n";
      for (const auto& c : r.corners) {
        auto value = [&](const std::string& q) {
          const auto* curve = find_curve(*bump, q, c.name);
          return curve ? format(at_design(*curve)) : std::string("-");
        };
        const auto* rch = find_curve(*bump, "roll_centre_height", c.name);
        md << "| " << c.name << " | " << value("toe") << " | " << value("camber") << " | " << value("bump_steer") << " | "
           << value("camber_gain") << " | " << value("spring_ratio") << " | " << value("damper_ratio") << " | "
           << (rch ? format(1000 * at_design(*rch)) : "-") << " |\n";
      }
      md << "\n";
    }
    md << "Derivatives at the design position with respect to the scene's geometry parameters and directions "
          "(position-level curves exact; rates by central differences of their exact values); the quantities "
          "no direction moves are left out:\n\n"
       << "| quantity | corner |";
    for (const auto& dir : dirs) md << " d/d(" << dir.name << ") |";
    md << "\n|---|---|";
    for (size_t k = 0; k < dirs.size(); ++k) md << "---|";
    md << "\n";
    if (bump)
      for (const auto& c : bump->curves) {
        const bool moved = std::any_of(dirs.begin(), dirs.end(), [&](const Direction& dir) {
          return sensitivity(c, dir)[c.values.size() / 2] != 0.0;
        });
        if (!moved) continue;  // toe and camber: no direction of the scene moves the linkage
        md << "| " << c.quantity << " [" << c.unit << "] | " << c.corner << " |";
        for (const auto& dir : dirs) md << " " << format(sensitivity(c, dir)[c.values.size() / 2], 3) << " |";
        md << "\n";
      }
    io::write_file_atomically(args.out + "/report.md", md.str());
    files += ", report.md";
  }

  std::cout << d.scene_name << ": suspension kinematics of " << car.node->name << " (" << g.name << "), "
            << r.corners.size() << " corners, " << r.sweeps.size() << " sweeps, " << r.poses << " poses\n";
  if (bump) {
    std::cout << "  at the design position          toe     camber  bump steer  camber gain  spring  damper  roll centre\n"
                 "                                  [deg]   [deg]   [deg/m]     [deg/m]      ratio   ratio   [mm]\n";
    for (const auto& c : r.corners) {
      auto value = [&](const std::string& q, double scale = 1.0) {
        const auto* curve = find_curve(*bump, q, c.name);
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
  if (roll)
    for (const auto& c : r.corners) {
      const auto* st = find_curve(*roll, "roll_steer", c.name);
      const auto* ca = find_curve(*roll, "roll_camber", c.name);
      if (st && ca)
        std::cout << "  roll " << c.name << ": roll steer " << format(at_design(*st), 3) << " deg/deg, roll camber "
                  << format(at_design(*ca), 3) << " deg/deg\n";
    }
  if (steer)
    for (const auto& curve : steer->curves)
      if (curve.quantity == "steering_gain")
        std::cout << "  steer " << curve.corner << ": " << format(at_design(curve) / 1000.0, 4) << " deg per mm of "
                  << steer->variable << "\n";
  for (const auto& note : r.notes) std::cout << "  note: " << note << "\n";
  std::cout << "wrote " << args.out << "/: " << files << "\n";
  return 0;
}

}  // namespace dydp::apps
