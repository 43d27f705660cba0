#include "fmi/variable_table.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/linear/linearization.hpp"
#include "engine/linear/signal_lookup.hpp"

namespace dydp::fmi {
namespace {

using engine::Diagram;
using engine::InputError;
using engine::Node;

/// A name's lookup error re-thrown at the description file's line.
[[noreturn]] void rethrow_at(const Exposure& e, int line, const std::string& field, const InputError& error) {
  throw InputError(e.spec_file, line, field, error.what());
}

Variable variable(std::string name, Role role, int index = 0, std::string unit = "", std::string description = "") {
  Variable v;
  v.name = std::move(name);
  v.role = role;
  v.index = index;
  v.unit = std::move(unit);
  v.description = std::move(description);
  return v;
}

int find_objective(const Diagram& d, const std::string& name) {
  for (int i = 0; i < static_cast<int>(d.nodes.size()); ++i)
    if (d.nodes[i].name == name && d.nodes[i].objective) return i;
  return -1;
}

/// FNV-1a over the table's names, roles and the scene's text: the instantiation token.
std::string token_of(const VariableTable& t) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const std::string& s) {
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  };
  for (const Variable& v : t.variables) mix(v.name + "#" + std::to_string(static_cast<int>(v.role)));
  char text[40];
  std::snprintf(text, sizeof text, "{dydp-%016llx}", static_cast<unsigned long long>(h));
  return text;
}

}  // namespace

VariableTable build_variables(Diagram& d, const Exposure& e) {
  VariableTable t;
  auto add = [&t](Variable v) {
    v.value_reference = static_cast<uint32_t>(t.variables.size());
    t.variables.push_back(std::move(v));
    return t.variables.back().value_reference;
  };
  add(variable("time", Role::time, 0, "s", "simulation time"));

  // Parameters: the scene's (all by default), tunable, with their units and ranges.
  if (e.default_parameters) {
    for (int i = 0; i < static_cast<int>(d.parameters.size()); ++i) t.parameters.push_back(i);
  } else {
    for (const ExposedName& p : e.parameters) {
      const int i = d.find_parameter(p.name);
      if (i < 0) {
        std::string names;
        for (const auto& sp : d.parameters) names += (names.empty() ? "" : ", ") + sp.name;
        throw InputError(e.spec_file, p.line, "parameters",
                         "no scene parameter " + p.name + " (the scene's: " + (names.empty() ? "none" : names) + ")");
      }
      t.parameters.push_back(i);
    }
  }
  const std::vector<int> differentiable = engine::differentiable_parameters(d);
  for (int i : t.parameters) {
    const engine::SceneParameter& sp = d.parameters[i];
    Variable v = variable(sp.name, Role::parameter, i, sp.unit, "scene parameter");
    v.has_start = true;
    v.start = sp.value;
    v.min = sp.lower;
    v.max = sp.upper;
    add(v);
    if (std::find(differentiable.begin(), differentiable.end(), i) != differentiable.end())
      t.differentiable.push_back(i);
  }
  d.set_sensitivities(t.differentiable);

  // Inputs: signals whose wire is cut, their value the importer's; the start value is the
  // scene's own at time.start.
  engine::Evaluator ev(d, false);
  std::vector<double> x0(std::max(d.num_states, 1), 0.0);
  ev.set_segment_start(d.time.start);
  ev.initial_state(d.time.start, x0.data());
  ev.outputs(d.time.start, x0.data());
  std::set<int> input_set;
  for (const ExposedName& in : e.inputs) {
    std::vector<int> offsets;
    try {
      offsets = engine::signal_offsets(d, in.name, "inputs");
    } catch (const InputError& error) {
      rethrow_at(e, in.line, "inputs", error);
    }
    for (int offset : offsets) {
      if (!input_set.insert(offset).second)
        throw InputError(e.spec_file, in.line, "inputs", engine::signal_name(d, offset) + " is an input twice");
      Variable v = variable(engine::signal_name(d, offset), Role::input, static_cast<int>(t.input_offsets.size()),
                            d.signal_unit(offset), "input (the scene's signal, its wire cut)");
      v.has_start = true;
      v.start = ev.signals()[offset];
      t.input_offsets.push_back(offset);
      add(v);
    }
  }

  // States: the blocks', then the objectives' quadratures (their integrals).
  t.num_block_states = d.num_states;
  t.num_quadratures = d.num_quadratures;
  std::vector<std::string> state_names(t.num_states());
  t.nominals.assign(t.num_states(), 1.0);
  for (const Node& n : d.nodes) {
    for (int k = 0; k < n.block->num_states(); ++k) {
      state_names[n.state_offset + k] = n.name + ".state." + n.block->state_names()[k];
      t.nominals[n.state_offset + k] =
          k < static_cast<int>(n.state_nominal.size()) ? n.state_nominal[k] : n.block->state_nominals()[k];
    }
    for (int k = 0; k < n.block->num_quadratures(); ++k) {
      state_names[d.num_states + n.quad_offset + k] = n.name + ".integral[" + std::to_string(k) + "]";
      t.nominals[d.num_states + n.quad_offset + k] = n.block->quadrature_nominals()[k];
    }
  }
  t.first_state = static_cast<uint32_t>(t.variables.size());
  for (int i = 0; i < t.num_states(); ++i) {
    add(variable(state_names[i], Role::state, i, "",
                 i < d.num_states ? "continuous state" : "integral of an objective's integrand"));
  }
  t.first_derivative = static_cast<uint32_t>(t.variables.size());
  for (int i = 0; i < t.num_states(); ++i) add(variable("der(" + state_names[i] + ")", Role::derivative, i));

  // Dependencies from the diagram's structure: an output step's outputs read its block's own
  // states and the inputs it reads (Block::output_reads); a held input depends on itself only.
  std::vector<std::set<uint32_t>> signal_deps(d.num_signals);
  std::vector<int> input_of(d.num_signals, -1);
  for (size_t j = 0; j < t.input_offsets.size(); ++j) input_of[t.input_offsets[j]] = static_cast<int>(j);
  const uint32_t first_input = static_cast<uint32_t>(1 + t.parameters.size());
  auto own_states = [&](const Node& n) {
    std::set<uint32_t> deps;
    for (int k = 0; k < n.block->num_states(); ++k) deps.insert(t.first_state + n.state_offset + k);
    return deps;
  };
  for (const engine::OutputStep& step : d.output_steps) {
    const Node& n = d.nodes[step.node];
    std::set<uint32_t> deps = own_states(n);
    for (int k : step.reads) deps.insert(signal_deps[n.input_source[k]].begin(), signal_deps[n.input_source[k]].end());
    for (int k : step.outputs)
      for (int w = 0; w < n.block->outputs()[k].width; ++w) {
        const int offset = n.output_offset[k] + w;
        signal_deps[offset] = input_of[offset] >= 0 ? std::set<uint32_t>{first_input + input_of[offset]} : deps;
      }
  }
  std::vector<std::set<uint32_t>> state_deps(t.num_states());
  for (const Node& n : d.nodes) {
    std::set<uint32_t> deps = own_states(n);
    for (int src : n.input_source) deps.insert(signal_deps[src].begin(), signal_deps[src].end());
    for (int k = 0; k < n.block->num_states(); ++k) state_deps[n.state_offset + k] = deps;
    for (int k = 0; k < n.block->num_quadratures(); ++k) state_deps[d.num_states + n.quad_offset + k] = deps;
  }
  for (int i = 0; i < t.num_states(); ++i)
    t.variables[t.first_derivative + i].dependencies.assign(state_deps[i].begin(), state_deps[i].end());

  // Outputs: the logged signals and requested objectives by default, else the named ones.
  auto add_signal_output = [&](int offset) {
    Variable v = variable(engine::signal_name(d, offset), Role::output_signal, offset, d.signal_unit(offset), "signal");
    v.dependencies.assign(signal_deps[offset].begin(), signal_deps[offset].end());
    add(v);
  };
  auto add_objective_output = [&](int node, int line) {
    const Node& n = d.nodes[node];
    if (n.objective->needs_samples())
      throw InputError(e.spec_file, line, "outputs",
                       "objective " + n.name + " needs its input sampled over the run (" + n.type->name +
                           "): an FMU gives only objectives made of integrals");
    Variable v = variable(n.name, Role::output_objective, node, d.objective_unit(n),
                          "objective from its integrals so far (the run's value at the stop time)");
    for (int k = 0; k < n.block->num_quadratures(); ++k)
      v.dependencies.push_back(t.first_state + d.num_states + n.quad_offset + k);
    add(v);
  };
  std::set<std::string> output_names;
  if (e.default_outputs) {
    for (const engine::LoggedSignal& s : d.logged) add_signal_output(s.offset);
    for (int node : d.objectives) add_objective_output(node, 0);
  } else {
    for (const ExposedName& out : e.outputs) {
      const int node = find_objective(d, out.name);
      if (node >= 0) {
        add_objective_output(node, out.line);
        continue;
      }
      std::vector<int> offsets;
      try {
        offsets = engine::signal_offsets(d, out.name, "outputs");
      } catch (const InputError& error) {
        rethrow_at(e, out.line, "outputs", error);
      }
      for (int offset : offsets) add_signal_output(offset);
    }
  }
  for (const Variable& v : t.variables)
    if (!output_names.insert(v.name).second)
      throw InputError(e.spec_file, 0, "outputs", "two variables of the FMU are named " + v.name);

  // Event indicators: t - t_b for each breakpoint of the blocks over the scene's time span.
  t.breakpoints = d.breakpoints(d.time.start, d.time.stop);
  for (size_t k = 0; k < t.breakpoints.size(); ++k) {
    add(variable("breakpoint[" + std::to_string(k) + "]", Role::event_indicator, static_cast<int>(k), "s",
                 "time minus a block's breakpoint (" + engine::format_number(t.breakpoints[k]) + " s)"));
  }
  t.token = token_of(t);
  return t;
}

}  // namespace dydp::fmi
