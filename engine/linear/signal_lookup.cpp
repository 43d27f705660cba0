#include "engine/linear/signal_lookup.hpp"

#include <cctype>

#include "engine/framework/errors.hpp"

namespace dydp::engine {

std::vector<int> signal_offsets(const Diagram& d, const std::string& name, const std::string& field) {
  std::string path = name;
  int element = -1;
  if (!path.empty() && path.back() == ']') {
    const auto open = path.rfind('[');
    const std::string digits = open == std::string::npos ? "" : path.substr(open + 1, path.size() - open - 2);
    bool number = !digits.empty();
    for (char c : digits) number = number && std::isdigit(static_cast<unsigned char>(c));
    if (!number) throw InputError(field, 0, name, "expected BLOCK.PORT or BLOCK.PORT[i]");
    element = std::stoi(digits);
    path = path.substr(0, open);
  }
  const auto dot = path.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == path.size())
    throw InputError(field, 0, name, "expected BLOCK.PORT or BLOCK.PORT[i]");
  const std::string block = path.substr(0, dot), port = path.substr(dot + 1);
  for (const Node& n : d.nodes) {
    if (n.name != block) continue;
    const auto& ports = n.block->outputs();
    std::string names;
    for (size_t k = 0; k < ports.size(); ++k) {
      names += (k ? ", " : "") + ports[k].name;
      if (ports[k].name != port) continue;
      const int width = ports[k].width;
      if (element >= width)
        throw InputError(field, 0, name, "port " + path + " has " + std::to_string(width) + " element(s)");
      std::vector<int> offsets;
      for (int c = 0; c < width; ++c)
        if (element < 0 || c == element) offsets.push_back(n.output_offset[k] + c);
      return offsets;
    }
    throw InputError(field, 0, name, "block " + block + " has no output " + port + " (its outputs: " + names + ")");
  }
  for (const std::string& p : d.pruned)
    if (p == block)
      throw InputError(field, 0, name, "block " + block + " is pruned: no output of the scene needs it (log one of its signals under outputs:)");
  throw InputError(field, 0, name, "no block " + block + " in the scene");
}

std::string signal_name(const Diagram& d, int offset) {
  for (const Node& n : d.nodes) {
    const auto& ports = n.block->outputs();
    for (size_t k = 0; k < ports.size(); ++k) {
      const int first = n.output_offset[k];
      if (offset < first || offset >= first + ports[k].width) continue;
      const std::string base = n.name + "." + ports[k].name;
      return ports[k].width == 1 ? base : base + "[" + std::to_string(offset - first) + "]";
    }
  }
  return "signal " + std::to_string(offset);
}

}  // namespace dydp::engine
