// dydp equilibrium, linearize, modes and frf: the analyses about one operating point
// (engine/linear/), each written as JSON/CSV (and MAT with --format mat) once everything is
// computed, so a failure leaves nothing half written.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "apps/dydp/commands.hpp"
#include "apps/dydp/gnuplot.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/linear/equilibrium.hpp"
#include "engine/linear/frequency_response.hpp"
#include "engine/linear/modes.hpp"
#include "engine/linear/signal_lookup.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "io/files.hpp"
#include "io/mat_file.hpp"

namespace dydp::apps {
namespace {

using Json = nlohmann::ordered_json;
constexpr double kDegrees = 57.29577951308232;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

engine::Diagram load(const LinearArgs& args) {
  engine::Diagram d = engine::load_scene(args.scene, parse_sets(args.sets));
  print_warnings(d.warnings);
  return d;
}

/// The scene's `initial.hold`, then --hold (which replaces the scene's value of the same signal).
std::vector<std::pair<int, double>> scene_and_option_holds(const engine::Diagram& d, const LinearArgs& args) {
  std::vector<std::pair<int, double>> held = d.initial.held;
  for (const auto& [offset, value] : engine::held_signals(d, args.holds, "--hold")) {
    auto same = std::find_if(held.begin(), held.end(), [o = offset](const auto& h) { return h.first == o; });
    if (same != held.end()) same->second = value;
    else held.push_back({offset, value});
  }
  return held;
}

engine::EquilibriumOptions equilibrium_options(const engine::Diagram& d, const LinearArgs& args) {
  engine::EquilibriumOptions o;
  o.time = std::isnan(args.time) ? d.time.start : args.time;
  o.held = scene_and_option_holds(d, args);
  if (o.time < d.time.start || o.time > d.time.stop)
    throw engine::InputError("--time", 0, engine::format_number(o.time),
                             "outside the scene's time [" + engine::format_number(d.time.start) + ", " +
                                 engine::format_number(d.time.stop) + "]");
  return o;
}

Json matrix_json(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

std::vector<double> column_major(const Eigen::MatrixXd& m) { return {m.data(), m.data() + m.size()}; }

std::string matrix_csv(const Eigen::MatrixXd& m, const std::vector<std::string>& rows, const std::vector<std::string>& cols) {
  std::ostringstream s;
  s << std::setprecision(17) << "row";
  for (const std::string& c : cols) s << "," << c;
  s << "\n";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    s << rows[r];
    for (Eigen::Index c = 0; c < m.cols(); ++c) s << "," << m(r, c);
    s << "\n";
  }
  return s.str();
}

/// The equilibrium and the model about it, with dA/dp (and dB, dC, dD) along dx*/dp.
struct Point {
  engine::Equilibrium eq;
  engine::LinearModel model;
  std::vector<engine::LinearModelDerivative> derivatives;
};

Point linearize_at_equilibrium(engine::Diagram& d, const LinearArgs& args, bool with_derivatives) {
  Point p;
  p.eq = engine::find_equilibrium(d, equilibrium_options(d, args));
  p.model = engine::linearize(d, p.eq.t, p.eq.x, args.inputs, args.outputs, p.eq.held);
  if (with_derivatives)
    for (int j = 0; j < static_cast<int>(p.eq.parameters.size()); ++j)
      p.derivatives.push_back(engine::linear_model_derivative(d, p.model, p.eq.parameters[j], p.eq.dx_dp.col(j)));
  return p;
}

std::vector<std::string> parameter_names(const engine::Diagram& d, const std::vector<int>& indices) {
  std::vector<std::string> names;
  for (int i : indices) names.push_back(d.parameters[i].name);
  return names;
}

void print_done(const std::string& what, double seconds, const std::string& out, const std::string& files) {
  std::cout << "  " << what << " in " << std::setprecision(3) << seconds << " s; results in " << out << "/ (" << files << ")\n";
}

}  // namespace

int equilibrium_command(const LinearArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  engine::Diagram d = load(args);
  const engine::Equilibrium eq = engine::find_equilibrium(d, equilibrium_options(d, args));
  std::vector<std::string> logged;
  for (const engine::LoggedSignal& l : d.logged) logged.push_back(l.name);
  Json j;
  j["scene"] = d.scene_name;
  j["time"] = eq.t;
  j["residual"] = eq.residual;
  j["residual_unit"] = "nominal units per second (max over states of |xdot| / nominal)";
  j["iterations"] = eq.iterations;
  Json held = Json::object();
  for (const auto& [offset, value] : eq.held) held[engine::signal_name(d, offset)] = value;
  j["held"] = held;
  j["rank_deficiency"] = eq.rank_deficiency;
  Json state = Json::object(), moved = Json::object();
  for (size_t i = 0; i < eq.x.size(); ++i) {
    state[eq.states[i]] = eq.x[i];
    moved[eq.states[i]] = eq.x[i] - eq.initial[i];
  }
  j["state"] = state;
  j["moved_from_initial"] = moved;
  Json signals = Json::object();
  const std::vector<double> values = engine::signal_values(d, eq.t, eq.x, logged, eq.held);
  for (size_t k = 0; k < values.size(); ++k) signals[logged[k]] = values[k];
  j["signals"] = signals;
  Json sens = Json::object();
  for (size_t c = 0; c < eq.parameters.size(); ++c) {
    Json col = Json::object();
    for (size_t i = 0; i < eq.x.size(); ++i) col[eq.states[i]] = eq.dx_dp(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c));
    sens[d.parameters[eq.parameters[c]].name] = col;
  }
  j["sensitivity"] = sens;
  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/equilibrium.json", j.dump(2) + "\n");
  if (args.format == "mat") {
    io::MatFile mat(args.out + "/equilibrium.mat");
    mat.json("equilibrium", j);
    mat.commit();
  }
  std::cout << d.scene_name << ": equilibrium at t = " << eq.t << " s after " << eq.iterations
            << " Newton iterations, residual " << std::setprecision(3) << eq.residual << " nominal units/s";
  if (eq.rank_deficiency)
    std::cout << " (" << eq.rank_deficiency << " conserved quantities or free coordinates: kept where a run from the initial state leaves them)";
  std::cout << "\n";
  for (size_t k = 0; k < values.size(); ++k) {
    const std::string unit = d.signal_unit(d.logged[k].offset);
    std::cout << "  " << std::left << std::setw(32) << logged[k] << std::right << std::setw(14)
              << std::setprecision(6) << values[k] << " " << unit << "\n";
  }
  print_done("equilibrium and dx*/dp for " + std::to_string(eq.parameters.size()) + " parameters", seconds_since(start),
             args.out, std::string("equilibrium.json") + (args.format == "mat" ? ", equilibrium.mat" : ""));
  return 0;
}

int linearize_command(const LinearArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  engine::Diagram d = load(args);
  engine::LinearModel m;
  std::string about;
  if (std::isnan(args.at)) {
    m = linearize_at_equilibrium(d, args, false).model;
    about = "the equilibrium";
  } else {
    if (!(args.at >= d.time.start && args.at <= d.time.stop))
      throw engine::InputError("--at", 0, engine::format_number(args.at), "outside the scene's time");
    // The names checked before the run.
    const auto held = engine::held_signals(d, args.holds, "--hold");
    for (const std::string& name : args.inputs) engine::signal_offsets(d, name, "--input");
    for (const std::string& name : args.outputs) engine::signal_offsets(d, name, "--output");
    engine::Diagram to = engine::load_scene(args.scene, parse_sets(args.sets));
    to.time.stop = args.at;
    engine::RunOptions o;
    o.sensitivities = false;
    const engine::RunResult r = engine::run_from_initial(to, o);
    m = engine::linearize(d, args.at, r.final_state, args.inputs, args.outputs, held);
    about = "the run's state at t = " + engine::format_number(args.at) + " s";
  }
  Json j;
  j["scene"] = d.scene_name;
  j["about"] = about;
  j["time"] = m.t;
  j["states"] = m.states;
  j["inputs"] = m.inputs;
  j["outputs"] = m.outputs;
  j["x"] = m.x;
  j["A"] = matrix_json(m.A);
  j["B"] = matrix_json(m.B);
  j["C"] = matrix_json(m.C);
  j["D"] = matrix_json(m.D);
  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/linearization.json", j.dump(1) + "\n");
  io::write_file_atomically(args.out + "/A.csv", matrix_csv(m.A, m.states, m.states));
  io::write_file_atomically(args.out + "/B.csv", matrix_csv(m.B, m.states, m.inputs));
  io::write_file_atomically(args.out + "/C.csv", matrix_csv(m.C, m.outputs, m.states));
  io::write_file_atomically(args.out + "/D.csv", matrix_csv(m.D, m.outputs, m.inputs));
  if (args.format == "mat") {
    io::MatFile mat(args.out + "/linearization.mat");
    mat.matrix("A", m.A.rows(), m.A.cols(), column_major(m.A));
    mat.matrix("B", m.B.rows(), m.B.cols(), column_major(m.B));
    mat.matrix("C", m.C.rows(), m.C.cols(), column_major(m.C));
    mat.matrix("D", m.D.rows(), m.D.cols(), column_major(m.D));
    mat.strings("states", m.states);
    mat.strings("inputs", m.inputs);
    mat.strings("outputs", m.outputs);
    mat.commit();
  }
  std::cout << d.scene_name << ": linearised about " << about << ": " << m.states.size() << " states, "
            << m.inputs.size() << " inputs, " << m.outputs.size() << " outputs\n";
  print_done("linearisation", seconds_since(start), args.out,
             std::string("linearization.json, A.csv, B.csv, C.csv, D.csv") + (args.format == "mat" ? ", linearization.mat" : ""));
  return 0;
}

int modes_command(const LinearArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  engine::Diagram d = load(args);
  LinearArgs a = args;
  a.inputs.clear();
  a.outputs = {};
  Point p = linearize_at_equilibrium(d, a, true);
  std::vector<Eigen::MatrixXd> dA;
  for (const auto& dm : p.derivatives) dA.push_back(dm.A);
  const std::vector<engine::Mode> modes = engine::modes(p.model, dA);
  const std::vector<std::string> names = parameter_names(d, p.eq.parameters);
  Json list = Json::array();
  for (const engine::Mode& m : modes) {
    Json e;
    e["eigenvalue"] = {m.eigenvalue.real(), m.eigenvalue.imag()};
    e["frequency_hz"] = m.frequency_hz;
    e["damping_ratio"] = m.damping_ratio;
    Json dom = Json::array(), share = Json::array();
    for (const auto& [state, s] : m.dominant) dom.push_back(state), share.push_back(s);
    e["dominant"] = dom;
    e["dominant_share"] = share;
    Json sens = Json::object();
    for (size_t k = 0; k < names.size(); ++k)
      sens[names[k]] = {{"eigenvalue", {m.sensitivity[k].eigenvalue.real(), m.sensitivity[k].eigenvalue.imag()}},
                        {"frequency_hz", m.sensitivity[k].frequency_hz},
                        {"damping_ratio", m.sensitivity[k].damping_ratio}};
    e["sensitivity"] = sens;
    list.push_back(e);
  }
  Json j;
  j["scene"] = d.scene_name;
  j["about"] = "the equilibrium at t = " + engine::format_number(p.eq.t) + " s";
  j["derivatives"] = "d(lambda)/dp = w^H (dA/dp) v / (w^H v); dA/dp a central difference of exact Jacobians along dx*/dp";
  j["modes"] = list;
  std::ostringstream csv;
  csv << std::setprecision(12) << "frequency_hz,damping_ratio,real,imag,dominant";
  for (const std::string& n : names) csv << ",d(frequency_hz)/d(" << n << "),d(damping_ratio)/d(" << n << ")";
  csv << "\n";
  for (const engine::Mode& m : modes) {
    csv << m.frequency_hz << "," << m.damping_ratio << "," << m.eigenvalue.real() << "," << m.eigenvalue.imag() << ",";
    for (size_t k = 0; k < m.dominant.size(); ++k) csv << (k ? " " : "") << m.dominant[k].first;
    for (const auto& s : m.sensitivity) csv << "," << s.frequency_hz << "," << s.damping_ratio;
    csv << "\n";
  }
  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/modes.json", j.dump(2) + "\n");
  io::write_file_atomically(args.out + "/modes.csv", csv.str());
  if (args.format == "mat") {
    io::MatFile mat(args.out + "/modes.mat");
    mat.json("modes", j);
    mat.commit();
  }
  std::cout << d.scene_name << ": " << modes.size() << " modes of " << p.model.states.size()
            << " states about the equilibrium\n";
  int above = 0, rigid = 0;
  std::cout << "  " << std::setw(10) << "f [Hz]" << std::setw(9) << "zeta" << "  dominant states\n";
  for (const engine::Mode& m : modes) {
    if (m.frequency_hz > args.max_frequency) {
      ++above;
      continue;
    }
    // |lambda| below 1e-3 1/s: a coordinate no force holds (a free body's position, a wheel's
    // spin) or a conserved quantity (the oil in a damper), not a mode of the car.
    if (std::abs(m.eigenvalue) < 1e-3) {
      ++rigid;
      continue;
    }
    std::cout << "  " << std::fixed << std::setw(10) << std::setprecision(3) << m.frequency_hz << std::setw(9)
              << std::setprecision(3) << m.damping_ratio << std::defaultfloat << "  ";
    for (size_t k = 0; k < m.dominant.size(); ++k)
      std::cout << (k ? ", " : "") << m.dominant[k].first << " " << std::setprecision(2) << 100 * m.dominant[k].second << " %";
    std::cout << "\n";
  }
  if (rigid) std::cout << "  (" << rigid << " eigenvalues below 1e-3 1/s: coordinates no force holds, conserved quantities; in modes.json)\n";
  if (above) std::cout << "  (" << above << " modes above " << args.max_frequency << " Hz in modes.json)\n";
  print_done("equilibrium, linearisation, modes and d(lambda)/dp for " + std::to_string(names.size()) + " parameters",
             seconds_since(start), args.out, std::string("modes.json, modes.csv") + (args.format == "mat" ? ", modes.mat" : ""));
  return 0;
}

int frf_command(const LinearArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  engine::Diagram d = load(args);
  if (args.inputs.size() != 1) throw engine::InputError("--input", 0, "", "frf takes one input: SIGNAL or SIGNAL:RATE_SIGNAL");
  if (args.outputs.empty()) throw engine::InputError("--output", 0, "", "name at least one output signal");
  // SIGNAL:RATE: two inputs of the linear model, combined as u and s u.
  LinearArgs a = args;
  const std::string spec = args.inputs[0];
  const auto colon = spec.find(':');
  a.inputs = {spec.substr(0, colon)};
  if (colon != std::string::npos) a.inputs.push_back(spec.substr(colon + 1));
  double lo = 0.0, hi = 0.0, points = 0.0;
  if (!split_range(args.frequencies, lo, hi, points) || !(lo > 0) || !(hi > lo) || points < 2 || points != std::floor(points))
    throw engine::InputError("--frequencies", 0, args.frequencies, "expected LO:HI:N with 0 < LO < HI, N >= 2 [Hz]");
  const int count = static_cast<int>(points);
  const Point p = linearize_at_equilibrium(d, a, true);
  const std::vector<std::string> names = parameter_names(d, p.eq.parameters);
  const engine::FrequencyResponse h = engine::frequency_response(
      p.model, {0, colon == std::string::npos ? -1 : 1}, engine::log_frequencies(lo, hi, count), p.derivatives);
  const std::string in = a.inputs[0];
  std::ostringstream csv;
  csv << std::setprecision(12) << "frequency_hz";
  for (const std::string& o : p.model.outputs) csv << ",magnitude(" << o << "/" << in << "),phase_deg(" << o << "/" << in << ")";
  for (const std::string& n : names)
    for (const std::string& o : p.model.outputs) csv << ",d(magnitude(" << o << "/" << in << "))/d(" << n << ")";
  csv << "\n";
  for (size_t f = 0; f < h.frequency_hz.size(); ++f) {
    csv << h.frequency_hz[f];
    for (const auto& z : h.H[f]) csv << "," << std::abs(z) << "," << std::arg(z) * kDegrees;
    for (size_t k = 0; k < names.size(); ++k)
      for (double v : h.dmagnitude[k][f]) csv << "," << v;
    csv << "\n";
  }
  // The band's rms of each |H| (with a filter.iso2631 output, the ISO 2631 weighted
  // transmissibility) and its derivatives: the frequency response's objectives.
  const engine::BandRms band = engine::band_rms(h);
  Json objectives = Json::object();
  for (size_t o = 0; o < p.model.outputs.size(); ++o) {
    Json sens = Json::object();
    for (size_t k = 0; k < names.size(); ++k) sens[names[k]] = band.sensitivity[k][o];
    objectives["rms(|" + p.model.outputs[o] + "/" + in + "|)"] = Json{{"value", band.value[o]}, {"sensitivity", sens}};
  }
  const Json frf_json{{"input", in},
                      {"band_hz", {lo, hi}},
                      {"definition", "sqrt(integral of |H|^2 df / (hi - lo)), trapezoid rule on the grid of frf.csv"},
                      {"objectives", objectives}};
  std::filesystem::create_directories(args.out);
  io::write_file_atomically(args.out + "/frf.csv", csv.str());
  io::write_file_atomically(args.out + "/frf.json", frf_json.dump(2) + "\n");
  std::string files = "frf.csv, frf.json";
  if (args.report) {
    std::ostringstream md;
    md << "# " << d.scene_name << ": frequency response from " << in << "\n\n"
       << "About the equilibrium at t = " << p.eq.t << " s; linear model of " << p.model.states.size() << " states.\n\n";
    if (have_gnuplot()) {
      std::ostringstream gp;
      gp << "set terminal pngcairo size 900,560\nset output '" << args.out << "/plots/frf.png'\n"
         << "set termoption noenhanced\nset logscale xy\nset grid\nset xlabel 'frequency [Hz]'\nset ylabel '|H|'\n"
         << "set datafile separator ','\nset key top right\nplot ";
      for (size_t o = 0; o < p.model.outputs.size(); ++o)
        gp << (o ? ", " : "") << "'" << args.out << "/frf.csv' using 1:" << 2 + 2 * o << " with lines lw 2 title '"
           << p.model.outputs[o] << " / " << in << "'";
      gp << "\n";
      if (run_gnuplot(args.out, "frf", gp.str())) md << "![frf](plots/frf.png)\n\n";
    }
    md << "| f [Hz] |";
    for (const std::string& o : p.model.outputs) md << " |" << o << "/" << in << "| |";
    md << "\n|---|";
    for (size_t o = 0; o < p.model.outputs.size(); ++o) md << "---|";
    md << "\n";
    for (size_t f = 0; f < h.frequency_hz.size(); f += std::max<size_t>(1, h.frequency_hz.size() / 12)) {
      md << "| " << std::setprecision(3) << h.frequency_hz[f] << " |";
      for (const auto& z : h.H[f]) md << " " << std::setprecision(4) << std::abs(z) << " |";
      md << "\n";
    }
    io::write_file_atomically(args.out + "/report.md", md.str());
    files += ", report.md";
  }
  std::cout << d.scene_name << ": frequency response from " << in << " to " << p.model.outputs.size() << " outputs at "
            << count << " frequencies, " << lo << " to " << hi << " Hz, with d|H|/dp for " << names.size() << " parameters\n";
  for (size_t o = 0; o < p.model.outputs.size(); ++o) {
    size_t peak = 0;
    for (size_t f = 0; f < h.H.size(); ++f)
      if (std::abs(h.H[f][o]) > std::abs(h.H[peak][o])) peak = f;
    std::cout << "  " << p.model.outputs[o] << ": peak |H| " << std::setprecision(4) << std::abs(h.H[peak][o]) << " at "
              << h.frequency_hz[peak] << " Hz, band rms " << band.value[o] << "\n";
  }
  print_done("frequency response", seconds_since(start), args.out, files);
  return 0;
}

}  // namespace dydp::apps
