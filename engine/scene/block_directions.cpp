#include "engine/scene/block_directions.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>

#include "engine/framework/errors.hpp"
#include "engine/scene/block_reader.hpp"
#include "engine/scene/scene_keys.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) throw InputError(file, line_of(n), field, "expected a single value");
  return n.Scalar();
}

bool has_wildcard(const std::string& path) { return path.find('*') != std::string::npos; }

/// The known parameters of the block a path names (its longest block-name prefix), for messages.
std::string parameters_of_prefix(const std::string& path, const std::vector<Node>& nodes) {
  const Node* best = nullptr;
  for (const Node& n : nodes)
    if (path.rfind(n.name + ".", 0) == 0 && (!best || n.name.size() > best->name.size())) best = &n;
  if (!best) return "no block of that name";
  std::string known;
  for (const auto& p : best->type->parameters) known += (known.empty() ? "" : " ") + p.name;
  return "block '" + best->name + "' has parameters: " + (known.empty() ? "none" : known);
}

}  // namespace

std::vector<DirectionEntry> read_direction_entries(const YAML::Node& list, const std::string& file,
                                                   const std::string& field, const Diagram& d,
                                                   const std::vector<DirectionEntry>& declared) {
  const bool computed = field == "sensitivities";
  auto is_declared = [&](const std::string& name) {
    return std::any_of(declared.begin(), declared.end(), [&](const DirectionEntry& e) { return e.name == name; });
  };
  std::vector<DirectionEntry> entries;
  if (!list) return entries;
  if (!list.IsSequence())
    throw InputError(file, line_of(list), field,
                     computed ? "expected a list of scene parameters, block parameters or groups"
                              : "expected a list of block parameters or groups");
  for (auto item : list) {
    DirectionEntry e;
    e.line = line_of(item);
    if (item.IsScalar()) {
      e.name = item.Scalar();
      e.scene_parameter = d.find_parameter(e.name) >= 0 || is_declared(e.name);
      if (e.scene_parameter && !computed)
        throw InputError(file, e.line, field, "'" + e.name + "' is a scene parameter already");
      if (!e.scene_parameter) {
        // Not a scene parameter: a block parameter path, or nothing at all.
        if (e.name.find('.') == std::string::npos)
          throw InputError(file, e.line, field,
                           "unknown scene parameter '" + e.name + "' (a block parameter is written block.parameter)");
        e.members = {e.name};
        e.member_lines = {e.line};
      }
      entries.push_back(std::move(e));
      continue;
    }
    if (!item.IsMap())
      throw InputError(file, e.line, field, "expected a name or a mapping {name, of, range, unit}");
    for (auto kv : item) {
      const std::string key = kv.first.Scalar();
      if (std::find(kDirectionKeys.begin(), kDirectionKeys.end(), key) == kDirectionKeys.end())
        throw InputError(file, line_of(kv.first), field + "." + key, "unknown key (name, of, range, unit)");
    }
    const YAML::Node of = item["of"];
    if (!of) throw InputError(file, e.line, field + ".of", "missing: the block parameters of the direction");
    if (of.IsScalar()) {
      e.members = {of.Scalar()};
      e.member_lines = {line_of(of)};
    } else if (of.IsSequence() && of.size() > 0) {
      for (auto m : of) {
        e.members.push_back(scalar(m, file, field + ".of"));
        e.member_lines.push_back(line_of(m));
      }
    } else {
      throw InputError(file, line_of(of), field + ".of", "expected block.parameter or a list of them");
    }
    const bool single = e.members.size() == 1 && !has_wildcard(e.members[0]);
    if (item["name"]) {
      e.name = scalar(item["name"], file, field + ".name");
    } else if (single) {
      e.name = e.members[0];
    } else {
      throw InputError(file, e.line, field + ".name", "missing: a group of block parameters needs a name");
    }
    if (e.name.empty() || e.name.front() == '$')
      throw InputError(file, e.line, field + ".name", "expected a plain name");
    if (d.find_parameter(e.name) >= 0 || is_declared(e.name))
      throw InputError(file, item["name"] ? line_of(item["name"]) : e.line, field + ".name",
                       "'" + e.name + "' is a scene parameter already");
    if (const YAML::Node r = item["range"]) {
      if (!r.IsSequence() || r.size() != 2)
        throw InputError(file, line_of(r), field + ".range", "expected [low, high]");
      e.lower = scene_number(scalar(r[0], file, field + ".range"), file, line_of(r[0]), field + ".range");
      e.upper = scene_number(scalar(r[1], file, field + ".range"), file, line_of(r[1]), field + ".range");
      if (!(e.lower <= e.upper)) throw InputError(file, line_of(r), field + ".range", "low is above high");
      e.has_range = true;
    }
    if (item["unit"]) e.unit = scalar(item["unit"], file, field + ".unit");
    entries.push_back(std::move(e));
  }
  for (size_t a = 0; a < entries.size(); ++a)
    for (size_t b = 0; b < a; ++b)
      if (entries[a].name == entries[b].name)
        throw InputError(file, entries[a].line, field,
                         "'" + entries[a].name + "' listed twice (also line " + std::to_string(entries[b].line) + ")");
  return entries;
}

void bind_directions(const std::vector<DirectionEntry>& entries, const std::string& file,
                     std::vector<Node>& nodes, Diagram& d, bool compute) {
  const std::string list = compute ? "sensitivities" : "directions";
  // Block parameter (node, index) -> the entry that claimed it, to refuse naming one twice.
  std::vector<std::vector<int>> claimed(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i) claimed[i].assign(nodes[i].p.size(), -1);

  for (size_t k = 0; k < entries.size(); ++k) {
    const DirectionEntry& e = entries[k];
    if (e.scene_parameter) {
      if (compute) d.sensitivities.push_back(d.find_parameter(e.name));
      continue;
    }
    const std::string field = list + "." + e.name;
    SceneParameter sp;
    sp.name = e.name;
    sp.line = e.line;
    sp.direction_list = list;
    bool first = true;
    std::string first_path;
    std::vector<std::pair<size_t, size_t>> bound;
    for (size_t m = 0; m < e.members.size(); ++m) {
      const std::string& pattern = e.members[m];
      const int line = e.member_lines[m];
      int matches = 0;
      for (size_t i = 0; i < nodes.size(); ++i)
        for (size_t j = 0; j < nodes[i].p.size(); ++j) {
          const ParamSpec& ps = nodes[i].type->parameters[j];
          const std::string path = nodes[i].name + "." + ps.name;
          if (fnmatch(pattern.c_str(), path.c_str(), 0) != 0) continue;
          ++matches;
          const Node& n = nodes[i];
          if (claimed[i][j] >= 0)
            throw InputError(file, line, field,
                             path + " is already in direction '" + entries[claimed[i][j]].name + "' (line " +
                                 std::to_string(entries[claimed[i][j]].line) + ")");
          if (n.p_scene[j] >= 0 && !d.parameters[n.p_scene[j]].direction_list.empty())
            throw InputError(file, line, field,
                             path + " is already in direction '" + d.parameters[n.p_scene[j]].name + "' (line " +
                                 std::to_string(d.parameters[n.p_scene[j]].line) + ")");
          if (n.p_scene[j] >= 0)
            throw InputError(file, line, field,
                             path + " is driven by scene parameter '" + d.parameters[n.p_scene[j]].name + "' (" +
                                 place(n.parameter_file(j, file), n.p_line[j]) + "): name '" +
                                 d.parameters[n.p_scene[j]].name + "' as the direction");
          if (!ps.differentiable)
            throw InputError(file, line, field, path + " is not differentiable, it cannot be a direction");
          if (first) {
            sp.value = n.p[j];
            sp.unit = ps.unit;
            sp.lower = ps.lower;
            sp.upper = ps.upper;
            first_path = path;
            first = false;
          } else {
            // One direction moves one value: the members must start from it.
            if (n.p[j] != sp.value)
              throw InputError(file, line, field,
                               path + " is " + format_number(n.p[j]) + " (" + place(n.parameter_file(j, file), n.p_line[j]) +
                                   "), " + first_path + " is " + format_number(sp.value) +
                                   ": the members of a direction share one value");
            if (ps.unit != sp.unit)
              throw InputError(file, line, field,
                               path + " is in " + (ps.unit.empty() ? "no unit" : ps.unit) + ", " + first_path +
                                   " in " + (sp.unit.empty() ? "no unit" : sp.unit));
            sp.lower = std::max(sp.lower, ps.lower);
            sp.upper = std::min(sp.upper, ps.upper);
          }
          claimed[i][j] = static_cast<int>(k);
          bound.emplace_back(i, j);
        }
      if (matches == 0)
        throw InputError(file, line, field,
                         "no block parameter '" + pattern + "' (" + parameters_of_prefix(pattern, nodes) + ")");
    }
    if (!e.unit.empty() && e.unit != sp.unit)
      throw InputError(file, e.line, field + ".unit",
                       "'" + e.unit + "' but " + first_path + " is in " + (sp.unit.empty() ? "no unit" : sp.unit));
    if (e.has_range) {
      // The range is what a study may visit: it must stay inside every member's bounds.
      if (e.lower < sp.lower || e.upper > sp.upper)
        throw InputError(file, e.line, field + ".range",
                         "[" + format_number(e.lower) + ", " + format_number(e.upper) + "] leaves the bounds [" +
                             format_number(sp.lower) + ", " + format_number(sp.upper) + "] of " + first_path);
      if (sp.value < e.lower || sp.value > e.upper)
        throw InputError(file, e.line, field + ".range",
                         "the value " + format_number(sp.value) + " of " + first_path + " is outside the range");
      sp.lower = e.lower;
      sp.upper = e.upper;
    }
    const int index = static_cast<int>(d.parameters.size());
    d.parameters.push_back(sp);
    for (auto [i, j] : bound) nodes[i].p_scene[j] = index;
    if (compute) d.sensitivities.push_back(index);
  }
}

}  // namespace dydp::engine
