#include "engine/scene/initial_section.hpp"

#include <algorithm>
#include <cctype>

#include "engine/framework/errors.hpp"
#include "engine/scene/block_reader.hpp"
#include "engine/scene/scene_keys.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

bool read_state(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) throw InputError(file, line_of(n), field, "expected equilibrium or declared");
  const std::string v = n.Scalar();
  if (v == "equilibrium") return true;
  if (v == "declared") return false;
  throw InputError(file, line_of(n), field, "unknown value '" + v + "' (equilibrium, declared)");
}

/// The signal offsets of `name` among the kept blocks' outputs; a message in `why` otherwise.
std::vector<int> offsets_of(const Diagram& d, const std::string& name, std::string& why) {
  std::string path = name;
  int element = -1;
  if (!path.empty() && path.back() == ']') {
    const auto open = path.rfind('[');
    const std::string digits = open == std::string::npos ? "" : path.substr(open + 1, path.size() - open - 2);
    bool number = !digits.empty() && digits.size() < 9;
    for (char c : digits) number = number && std::isdigit(static_cast<unsigned char>(c));
    if (!number) return why = "expected BLOCK.PORT or BLOCK.PORT[i]", std::vector<int>{};
    element = std::stoi(digits);
    path = path.substr(0, open);
  }
  const auto dot = path.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == path.size())
    return why = "expected BLOCK.PORT or BLOCK.PORT[i]", std::vector<int>{};
  const std::string block = path.substr(0, dot), port = path.substr(dot + 1);
  for (const Node& n : d.nodes) {
    if (n.name != block) continue;
    const auto& ports = n.block->outputs();
    std::string names;
    for (size_t k = 0; k < ports.size(); ++k) {
      names += (k ? ", " : "") + ports[k].name;
      if (ports[k].name != port) continue;
      if (element >= ports[k].width)
        return why = "port " + path + " has " + std::to_string(ports[k].width) + " element(s)", std::vector<int>{};
      std::vector<int> out;
      for (int c = 0; c < ports[k].width; ++c)
        if (element < 0 || c == element) out.push_back(n.output_offset[k] + c);
      return out;
    }
    return why = "block " + block + " has no output " + port + " (its outputs: " + names + ")", std::vector<int>{};
  }
  if (std::find(d.pruned.begin(), d.pruned.end(), block) != d.pruned.end())
    return why = "block " + block + " is pruned: no output of the scene needs it", std::vector<int>{};
  return why = "no block " + block + " in the scene", std::vector<int>{};
}

}  // namespace

InitialSection read_initial_section(const YAML::Node& n, const std::string& file) {
  InitialSection s;
  if (!n) return s;
  s.line = line_of(n);
  if (n.IsScalar()) {
    s.equilibrium = read_state(n, file, "initial");
    return s;
  }
  if (!n.IsMap()) throw InputError(file, line_of(n), "initial", "expected equilibrium, declared or {state, hold}");
  for (auto kv : n) {
    const std::string key = kv.first.Scalar();
    if (std::none_of(kInitialKeys.begin(), kInitialKeys.end(), [&](const char* k) { return key == k; }))
      throw InputError(file, line_of(kv.first), "initial." + key, "unknown key");
  }
  if (n["state"]) s.equilibrium = read_state(n["state"], file, "initial.state");
  if (const YAML::Node hold = n["hold"]) {
    if (!hold.IsMap()) throw InputError(file, line_of(hold), "initial.hold", "expected a mapping SIGNAL: VALUE");
    for (auto kv : hold) {
      InitialSection::Hold h;
      h.signal = kv.first.Scalar();
      h.line = line_of(kv.first);
      const std::string field = "initial.hold." + h.signal;
      if (!kv.second.IsScalar()) throw InputError(file, line_of(kv.second), field, "expected a number");
      h.value = scene_number(kv.second.Scalar(), file, line_of(kv.second), field);
      s.holds.push_back(h);
    }
  }
  return s;
}

void bind_initial_section(const InitialSection& s, const std::string& file, Diagram& d) {
  d.initial = InitialSpec{};
  d.initial.equilibrium = s.equilibrium;
  d.initial.line = s.line;
  for (const InitialSection::Hold& h : s.holds) {
    std::string why;
    const std::vector<int> offsets = offsets_of(d, h.signal, why);
    if (offsets.empty()) throw InputError(file, h.line, "initial.hold." + h.signal, why);
    for (int o : offsets) d.initial.held.push_back({o, h.value});
    d.initial.hold_names.push_back(h.signal);
  }
}

}  // namespace dydp::engine
