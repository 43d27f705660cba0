// Reads a scene YAML file into a Diagram: every value checked where it was written, so each
// error names file, line and field. Graph checks and ordering live in graph_builder.cpp.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/scene/block_directions.hpp"
#include "engine/scene/block_reader.hpp"
#include "engine/scene/consistency_checks.hpp"
#include "engine/scene/duplicate_keys.hpp"
#include "engine/scene/graph_builder.hpp"
#include "engine/scene/initial_section.hpp"
#include "engine/scene/scene_flattener.hpp"
#include "engine/scene/scene_keys.hpp"
#include "engine/scene/scene_relations.hpp"
#include "engine/scene/subsystem_definition.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

class SceneReader {
 public:
  explicit SceneReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& field,
                         const std::string& message) const {
    throw InputError(file_, line_of(at), field, message);
  }
  [[noreturn]] void fail(int line, const std::string& field, const std::string& message) const {
    throw InputError(file_, line, field, message);
  }

  double number(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a number");
    return scene_number(n.Scalar(), file_, line_of(n), field);
  }

  std::string text(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a single value");
    return n.Scalar();
  }

  template <size_t N>
  void allow_keys(const YAML::Node& map, const std::string& field, const std::array<const char*, N>& keys) const {
    if (!map.IsMap()) fail(map, field, "expected a mapping");
    for (auto kv : map) {
      const std::string key = kv.first.Scalar();
      if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; }))
        fail(kv.first, field.empty() ? key : field + "." + key, "unknown key");
    }
  }

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

void read_time(const SceneReader& r, const YAML::Node& n, TimeSpec& time) {
  if (!n) return;
  r.allow_keys(n, "time", kTimeKeys);
  if (n["start"]) time.start = r.number(n["start"], "time.start");
  if (n["stop"]) time.stop = r.number(n["stop"], "time.stop");
  if (n["output_step"]) time.output_step = r.number(n["output_step"], "time.output_step");
  // Name the line of the offending value when it was written, else the line of `time:`.
  if (!(time.stop > time.start))
    r.fail(n["stop"] ? n["stop"] : n, "time.stop", "must be greater than time.start");
  if (!(time.output_step > 0))
    r.fail(n["output_step"] ? n["output_step"] : n, "time.output_step", "must be positive");
  check_time_relations(r.file(), n, time);
}

void read_solver(const SceneReader& r, const YAML::Node& n, const TimeSpec& time, SolverSpec& s) {
  if (!n) return check_solver_relations(r.file(), n, s, time);
  r.allow_keys(n, "solver", kSolverKeys);
  if (n["method"]) {
    s.method = r.text(n["method"], "solver.method");
    if (s.method != "bdf" && s.method != "adams" && s.method != "rk4" && s.method != "sdirk2" &&
        s.method != "rosw")
      r.fail(n["method"], "solver.method", "unknown method '" + s.method + "' (bdf, adams, rk4, sdirk2, rosw)");
  }
  if (n["rtol"]) s.rtol = r.number(n["rtol"], "solver.rtol");
  if (n["atol"]) s.atol = r.number(n["atol"], "solver.atol");
  if (n["step"]) s.step = r.number(n["step"], "solver.step");
  bool* const switches[] = {&s.sens_error_test, &s.nominal_scaling, &s.refresh_local_jacobians};
  static_assert(std::size(switches) == kSolverSwitches.size(), "one member per key of kSolverSwitches");
  for (size_t i = 0; i < kSolverSwitches.size(); ++i) {
    const YAML::Node e = n[kSolverSwitches[i]];
    if (!e) continue;
    const std::string field = std::string("solver.") + kSolverSwitches[i];
    const std::string v = r.text(e, field);
    if (v != "true" && v != "false") r.fail(e, field, "expected true or false");
    *switches[i] = v == "true";
  }
  if (n["max_steps"]) {
    const double v = r.number(n["max_steps"], "solver.max_steps");
    if (!(v >= 1 && v <= kMaxStepLimit && v == std::floor(v)))
      r.fail(n["max_steps"], "solver.max_steps",
             "value " + n["max_steps"].Scalar() + " must be a whole number in [1, " + format_number(kMaxStepLimit) + "]");
    s.max_steps = static_cast<long>(v);
  }
  if (n["max_order"]) {
    const double v = r.number(n["max_order"], "solver.max_order");
    if (!(v >= 1 && v <= 12 && v == std::floor(v)))
      r.fail(n["max_order"], "solver.max_order", "value " + n["max_order"].Scalar() + " must be a whole number in [1, 12]");
    s.max_order = static_cast<int>(v);
  }
  if (n["min_step"]) s.min_step = r.number(n["min_step"], "solver.min_step");
  if (n["newton_coefficient"]) s.newton_coefficient = r.number(n["newton_coefficient"], "solver.newton_coefficient");
  if (!(s.newton_coefficient > 0 && s.newton_coefficient <= 1))
    r.fail(n["newton_coefficient"], "solver.newton_coefficient", "must be in (0, 1]");
  if (!(s.min_step >= 0)) r.fail(n["min_step"], "solver.min_step", "must not be negative");
  if (!(s.rtol > 0)) r.fail(n["rtol"], "solver.rtol", "must be positive");
  if (!(s.atol > 0)) r.fail(n["atol"], "solver.atol", "must be positive");
  if (s.step < 0) r.fail(n["step"], "solver.step", "must be positive");
  check_solver_relations(r.file(), n, s, time);
}

void read_parameters(const SceneReader& r, const YAML::Node& n, Diagram& d) {
  if (!n) return;
  if (!n.IsMap()) r.fail(n, "parameters", "expected a mapping of name: {value, unit, range}");
  for (auto kv : n) {
    SceneParameter p;
    p.name = kv.first.Scalar();
    p.line = line_of(kv.first);
    const std::string field = "parameters." + p.name;
    const YAML::Node& body = kv.second;
    if (body.IsScalar()) {
      p.value = r.number(body, field);
    } else {
      r.allow_keys(body, field, kSceneParameterKeys);
      if (!body["value"]) r.fail(body, field + ".value", "missing");
      p.value = r.number(body["value"], field + ".value");
      if (body["unit"]) p.unit = r.text(body["unit"], field + ".unit");
      if (body["range"]) {
        const YAML::Node& range = body["range"];
        if (!range.IsSequence() || range.size() != 2)
          r.fail(range, field + ".range", "expected [low, high]");
        p.lower = r.number(range[0], field + ".range");
        p.upper = r.number(range[1], field + ".range");
        if (!(p.lower <= p.upper)) r.fail(range, field + ".range", "low is above high");
      }
    }
    if (d.find_parameter(p.name) >= 0) r.fail(kv.first, field, "defined twice");
    if (p.value < p.lower || p.value > p.upper)
      r.fail(kv.first, field, "value " + format_number(p.value) + " outside its range");
    d.parameters.push_back(p);
  }
}

}  // namespace

Diagram load_scene(const std::string& path,
                   const std::vector<std::pair<std::string, std::string>>& overrides,
                   const std::vector<std::pair<std::string, std::string>>& setting_overrides) {
  SceneReader r(path);
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, 0, "", "is a folder, not a scene file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path, 0, "", "cannot open the scene file");
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, "", "YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(path, 1, "", "a scene is a YAML mapping");
  refuse_duplicate_keys(root, path);
  r.allow_keys(root, "", kSceneKeys);

  Diagram d;
  d.file = path;
  d.scene_name = root["scene"] ? r.text(root["scene"], "scene") : "scene";
  read_time(r, root["time"], d.time);
  read_solver(r, root["solver"], d.time, d.solver);
  const InitialSection initial = read_initial_section(root["initial"], path);
  read_parameters(r, root["parameters"], d);

  // --set of a direction named by block parameters waits until the blocks are read.
  std::vector<std::pair<std::string, std::string>> direction_overrides;
  for (const auto& [name, text] : overrides) {
    const int i = d.find_parameter(name);
    if (i < 0) {
      direction_overrides.emplace_back(name, text);
      continue;
    }
    double v = 0;
    if (!parse_number(text, v)) throw InputError("--set", 0, name, "malformed number '" + text + "'");
    SceneParameter& p = d.parameters[i];
    if (v < p.lower || v > p.upper)
      throw InputError(path, p.line, "parameters." + name,
                       "--set value " + text + " outside its range");
    p.value = v;
  }

  const std::vector<DirectionEntry> declared = read_direction_entries(root["directions"], path, "directions", d);
  const std::vector<DirectionEntry> directions =
      read_direction_entries(root["sensitivities"], path, "sensitivities", d, declared);

  SubsystemLibrary library;
  read_subsystem_section(root["subsystems"], path, library);

  const YAML::Node blocks = root["blocks"];
  if (!blocks || !blocks.IsMap() || blocks.size() == 0)
    r.fail(blocks ? blocks : root, "blocks", "a scene needs a mapping of blocks");
  GraphBuilder graph(path);
  SceneFlattener flat(d, graph, setting_overrides, d.warnings);
  flat.add_scene(path, library, blocks, root["connections"]);
  bind_directions(declared, path, graph.blocks(), d, /*compute=*/false);
  bind_directions(directions, path, graph.blocks(), d, /*compute=*/true);

  check_differentiable(graph.blocks(), d, d.sensitivities);

  const YAML::Node outputs = root["outputs"];
  if (!outputs || !outputs.IsSequence() || outputs.size() == 0)
    r.fail(outputs ? outputs : root, "outputs", "a scene needs a list of outputs");
  for (auto item : outputs) flat.request_output(r.text(item, "outputs"), path, line_of(item));

  graph.build(d);
  bind_initial_section(initial, path, d);
  for (const auto& [name, text] : direction_overrides) {
    const int i = d.find_parameter(name);
    if (i < 0)
      throw InputError("--set", 0, name, "no scene parameter of that name in " + path + " (nor a direction of its sensitivities)");
    double v = 0;
    if (!parse_number(text, v)) throw InputError("--set", 0, name, "malformed number '" + text + "'");
    const SceneParameter& p = d.parameters[i];
    if (v < p.lower || v > p.upper)
      throw InputError(path, p.line, p.direction_list + "." + name, "--set value " + text + " outside its range");
    d.set_parameter(i, v);
  }
  return d;
}

std::string Diagram::signal_unit(int offset) const {
  for (int hops = 0; hops < 64; ++hops) {
    const Node* from = nullptr;
    int port = -1;
    for (const Node& n : nodes)
      for (size_t k = 0; k < n.output_offset.size(); ++k)
        if (offset >= n.output_offset[k] && offset < n.output_offset[k] + n.block->outputs()[k].width)
          from = &n, port = static_cast<int>(k);
    if (!from) return "";
    const std::string& unit = from->block->outputs()[port].unit;
    if (unit != kUnitOfFirstInput) return unit;
    if (from->input_source.empty()) return "";
    offset = from->input_source[0];
  }
  return "";
}

std::string Diagram::objective_unit(const Node& n) const {
  return n.objective->unit(n.input_source.empty() ? std::string() : signal_unit(n.input_source[0]));
}

void check_differentiable(const std::vector<Node>& nodes, const Diagram& d, const std::vector<int>& directions) {
  for (const Node& n : nodes)
    for (size_t j = 0; j < n.p.size(); ++j)
      if (n.p_scene[j] >= 0 && !n.type->parameters[j].differentiable &&
          std::find(directions.begin(), directions.end(), n.p_scene[j]) != directions.end())
        throw InputError(n.parameter_file(j, d.file), n.p_line[j], n.name + "." + n.type->parameters[j].name,
                         "not differentiable, cannot be driven by sensitivity parameter '" +
                             d.parameters[n.p_scene[j]].name + "'");
}

std::vector<int> differentiable_parameters(const Diagram& d) {
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(d.parameters.size()); ++i) {
    try {
      check_differentiable(d.nodes, d, {i});
      out.push_back(i);
    } catch (const InputError&) {
    }
  }
  return out;
}

void Diagram::set_sensitivities(const std::vector<int>& directions) {
  check_differentiable(nodes, *this, directions);
  sensitivities = directions;
}

int Diagram::find_parameter(const std::string& name) const {
  for (size_t i = 0; i < parameters.size(); ++i)
    if (parameters[i].name == name) return static_cast<int>(i);
  return -1;
}

void Diagram::set_parameter(int index, double value, bool check_range) {
  SceneParameter& sp = parameters.at(index);
  if (check_range && (value < sp.lower || value > sp.upper))
    throw InputError(file, sp.line, (sp.direction_list.empty() ? "parameters." : sp.direction_list + ".") + sp.name,
                     "value " + format_number(value) + " outside its range");
  // Check every block parameter it drives before changing any: a refused value leaves none behind.
  for (const Node& n : nodes)
    for (size_t j = 0; j < n.p.size(); ++j)
      if (n.p_scene[j] == index) {
        const ParamSpec& s = n.type->parameters[j];
        if (value < s.lower || value > s.upper)
          throw InputError(n.parameter_file(j, file), n.p_line[j], n.name + "." + s.name,
                           "value " + format_number(value) + " (from $" + sp.name +
                               ") outside its bounds");
      }
  for (const Node& n : nodes) {
    std::vector<double> p = n.p;
    bool driven = false;
    for (size_t j = 0; j < p.size(); ++j)
      if (n.p_scene[j] == index) p[j] = value, driven = true;
    if (driven) check_block(file, n, p, time, nullptr);
  }
  for (Node& n : nodes)
    for (size_t j = 0; j < n.p.size(); ++j)
      if (n.p_scene[j] == index) n.p[j] = value;
  sp.value = value;
}

std::vector<double> Diagram::block_parameter_values() const {
  std::vector<double> out;
  for (const Node& n : nodes) out.insert(out.end(), n.p.begin(), n.p.end());
  return out;
}

bool Diagram::start_is_current() const {
  return !start.x.empty() && static_cast<int>(start.x.size()) == num_states && start.t == time.start &&
         start.block_parameters == block_parameter_values();
}

std::vector<double> Diagram::breakpoints(double t0, double t1) const {
  std::vector<double> out;
  for (const Node& n : nodes)
    for (double t : n.block->breakpoints(n.p.data(), t0, t1))
      if (t > t0 && t <= t1) out.push_back(t);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace dydp::engine
