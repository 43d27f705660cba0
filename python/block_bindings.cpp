// The block library's metadata in Python, as `dydp blocks` prints it: per type its group,
// summary, parameters (unit, default, bounds), settings, check rules and, for types whose
// settings all have defaults, the ports of a default instance.
#include <pybind11/stl.h>

#include "engine/framework/registry.hpp"
#include "engine/scene/consistency_checks.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

namespace dydp::python {
namespace {

py::list ports_of(const std::vector<engine::PortDecl>& ports) {
  py::list out;
  for (const auto& p : ports) {
    py::dict entry;
    entry["name"] = p.name;
    entry["width"] = p.width;
    entry["unit"] = p.unit;
    out.append(entry);
  }
  return out;
}

py::dict metadata(const engine::BlockType& t) {
  py::dict entry;
  entry["name"] = t.name;
  entry["group"] = t.group;
  entry["summary"] = t.summary;
  py::list parameters, settings;
  for (const auto& p : t.parameters) {
    py::dict e;
    e["name"] = p.name;
    e["unit"] = p.unit;
    e["default"] = p.default_value;
    e["required"] = p.required;
    e["range"] = py::make_tuple(p.lower, p.upper);
    e["description"] = p.description;
    e["differentiable"] = p.differentiable;
    parameters.append(e);
  }
  engine::BlockSettings defaults(t.name, "", 0);
  bool complete = true;
  for (const auto& s : t.settings) {
    py::dict e;
    e["name"] = s.name;
    e["description"] = s.description;
    e["default"] = s.default_value;
    e["required"] = s.required;
    settings.append(e);
    if (s.required) complete = false;
    else defaults.set(s.name, {{s.default_value}, false, 0});
  }
  entry["parameters"] = parameters;
  entry["settings"] = settings;
  entry["checks"] = engine::check_rules(t);
  // Ports depend on the settings: known here only for an instance of the defaults.
  if (complete) {
    const auto block = t.make(defaults);
    entry["inputs"] = ports_of(block->inputs());
    entry["outputs"] = ports_of(block->outputs());
  } else {
    entry["inputs"] = py::none();
    entry["outputs"] = py::none();
  }
  return entry;
}

}  // namespace

void add_block_bindings(py::module_& m) {
  m.def(
      "blocks",
      [] {
        py::list out;
        for (const engine::BlockType* t : engine::Registry::global().all()) out.append(metadata(*t));
        return out;
      },
      "The block types: [{name, group, summary, parameters, settings, checks, inputs, outputs}] "
      "(inputs and outputs None when they depend on required settings).");
}

}  // namespace dydp::python
