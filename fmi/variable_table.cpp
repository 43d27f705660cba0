#include "fmi/variable_table.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "engine/analysis/run_result.hpp"
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

/// The table of one FMU being built: the scene, its description and what the steps share.
class TableBuilder {
 public:
  TableBuilder(Diagram& d, const Exposure& e) : d_(d), e_(e) {}

  VariableTable build() {
    add(variable("time", Role::time, 0, "s", "simulation time"));
    add_parameters();
    add_inputs();
    add_states();
    add_dependencies();
    add_outputs();
    add_event_indicators();
    t_.token = token_of(t_);
    return std::move(t_);
  }

 private:
  // v appended with the next value reference, which it returns.
  uint32_t add(Variable v) {
    v.value_reference = static_cast<uint32_t>(t_.variables.size());
    t_.variables.push_back(std::move(v));
    return t_.variables.back().value_reference;
  }

  // The exposed scene parameters, and those differentiable made the scene's sensitivities.
  void add_parameters() {
    // Parameters: the scene's (all by default), tunable, with their units and ranges.
    if (e_.default_parameters) {
      for (int i = 0; i < static_cast<int>(d_.parameters.size()); ++i) t_.parameters.push_back(i);
    } else {
      for (const ExposedName& p : e_.parameters) {
        const int i = d_.find_parameter(p.name);
        if (i < 0) {
          std::string names;
          for (const auto& sp : d_.parameters) names += (names.empty() ? "" : ", ") + sp.name;
          throw InputError(e_.spec_file, p.line, "parameters",
                           "no scene parameter " + p.name + " (the scene's: " + (names.empty() ? "none" : names) + ")");
        }
        t_.parameters.push_back(i);
      }
    }
    const std::vector<int> differentiable = engine::differentiable_parameters(d_);
    for (int i : t_.parameters) {
      const engine::SceneParameter& sp = d_.parameters[i];
      Variable v = variable(sp.name, Role::parameter, i, sp.unit, "scene parameter");
      v.has_start = true;
      v.start = sp.value;
      v.min = sp.lower;
      v.max = sp.upper;
      add(v);
      if (std::find(differentiable.begin(), differentiable.end(), i) != differentiable.end())
        t_.differentiable.push_back(i);
    }
    add_sensitivity_directions(differentiable);
  }

  // The description's sensitivity directions (scene parameters or declared directions, each one
  // its blocks can differentiate), then the differentiable knowns: the diagram's directions.
  void add_sensitivity_directions(const std::vector<int>& differentiable) {
    for (const ExposedName& s : e_.sensitivities) {
      const int i = d_.find_parameter(s.name);
      if (i < 0) {
        std::string names;
        for (const auto& sp : d_.parameters) names += (names.empty() ? "" : ", ") + sp.name;
        throw InputError(e_.spec_file, s.line, "sensitivities",
                         "no scene parameter or direction " + s.name + " (the scene's: " +
                             (names.empty() ? "none" : names) + ")");
      }
      if (std::find(differentiable.begin(), differentiable.end(), i) == differentiable.end()) {
        try {
          engine::check_differentiable(d_.nodes, d_, {i});
        } catch (const InputError& error) {
          rethrow_at(e_, s.line, "sensitivities", error);
        }
      }
      t_.sensitivities.push_back(i);
    }
    std::vector<int> directions = t_.sensitivities;
    for (int i : t_.differentiable)
      if (std::find(directions.begin(), directions.end(), i) == directions.end()) directions.push_back(i);
    d_.set_sensitivities(directions);
  }

  // The exposed inputs, each starting at the scene's value of its signal.
  void add_inputs() {
    // Inputs: signals whose wire is cut, their value the importer's; the start value is the
    // scene's own at time.start.
    engine::Evaluator ev(d_, false);
    std::vector<double> x0(std::max(d_.num_states, 1), 0.0);
    ev.set_segment_start(d_.time.start);
    ev.initial_state(d_.time.start, x0.data());
    ev.outputs(d_.time.start, x0.data());
    std::set<int> input_set;
    for (const ExposedName& in : e_.inputs) {
      std::vector<int> offsets;
      try {
        offsets = engine::signal_offsets(d_, in.name, "inputs");
      } catch (const InputError& error) {
        rethrow_at(e_, in.line, "inputs", error);
      }
      for (int offset : offsets) {
        if (!input_set.insert(offset).second)
          throw InputError(e_.spec_file, in.line, "inputs", engine::signal_name(d_, offset) + " is an input twice");
        Variable v = variable(engine::signal_name(d_, offset), Role::input, static_cast<int>(t_.input_offsets.size()),
                              d_.signal_unit(offset), "input (the scene's signal, its wire cut)");
        v.has_start = true;
        v.start = ev.signals()[offset];
        t_.input_offsets.push_back(offset);
        add(v);
      }
    }
  }

  // The states with their names and nominal magnitudes, then their derivatives.
  void add_states() {
    // States: the blocks', then the objectives' quadratures (their integrals).
    t_.num_block_states = d_.num_states;
    t_.num_quadratures = d_.num_quadratures;
    std::vector<std::string> state_names(t_.num_states());
    t_.nominals.assign(t_.num_states(), 1.0);
    for (const Node& n : d_.nodes) {
      for (int k = 0; k < n.block->num_states(); ++k) {
        state_names[n.state_offset + k] = n.name + ".state." + n.block->state_names()[k];
        t_.nominals[n.state_offset + k] =
            k < static_cast<int>(n.state_nominal.size()) ? n.state_nominal[k] : n.block->state_nominals()[k];
      }
      for (int k = 0; k < n.block->num_quadratures(); ++k) {
        state_names[d_.num_states + n.quad_offset + k] = n.name + ".integral[" + std::to_string(k) + "]";
        t_.nominals[d_.num_states + n.quad_offset + k] = n.block->quadrature_nominals()[k];
      }
    }
    t_.first_state = static_cast<uint32_t>(t_.variables.size());
    for (int i = 0; i < t_.num_states(); ++i) {
      add(variable(state_names[i], Role::state, i, "",
                   i < d_.num_states ? "continuous state" : "integral of an objective's integrand"));
    }
    t_.first_derivative = static_cast<uint32_t>(t_.variables.size());
    for (int i = 0; i < t_.num_states(); ++i) add(variable("der(" + state_names[i] + ")", Role::derivative, i));
  }

  // The value references of n's own states.
  std::set<uint32_t> own_states(const Node& n) const {
    std::set<uint32_t> deps;
    for (int k = 0; k < n.block->num_states(); ++k) deps.insert(t_.first_state + n.state_offset + k);
    return deps;
  }

  // Each signal's dependencies (kept for the outputs) and each derivative's.
  void add_dependencies() {
    // Dependencies from the diagram's structure: an output step's outputs read its block's own
    // states and the inputs it reads (Block::output_reads); a held input depends on itself only.
    signal_deps_.assign(d_.num_signals, {});
    std::vector<int> input_of(d_.num_signals, -1);
    for (size_t j = 0; j < t_.input_offsets.size(); ++j) input_of[t_.input_offsets[j]] = static_cast<int>(j);
    const uint32_t first_input = static_cast<uint32_t>(1 + t_.parameters.size());
    for (const engine::OutputStep& step : d_.output_steps) {
      const Node& n = d_.nodes[step.node];
      std::set<uint32_t> deps = own_states(n);
      for (int k : step.reads)
        deps.insert(signal_deps_[n.input_source[k]].begin(), signal_deps_[n.input_source[k]].end());
      for (int k : step.outputs)
        for (int w = 0; w < n.block->outputs()[k].width; ++w) {
          const int offset = n.output_offset[k] + w;
          signal_deps_[offset] = input_of[offset] >= 0 ? std::set<uint32_t>{first_input + input_of[offset]} : deps;
        }
    }
    std::vector<std::set<uint32_t>> state_deps(t_.num_states());
    for (const Node& n : d_.nodes) {
      std::set<uint32_t> deps = own_states(n);
      for (int src : n.input_source) deps.insert(signal_deps_[src].begin(), signal_deps_[src].end());
      for (int k = 0; k < n.block->num_states(); ++k) state_deps[n.state_offset + k] = deps;
      for (int k = 0; k < n.block->num_quadratures(); ++k) state_deps[d_.num_states + n.quad_offset + k] = deps;
    }
    for (int i = 0; i < t_.num_states(); ++i)
      t_.variables[t_.first_derivative + i].dependencies.assign(state_deps[i].begin(), state_deps[i].end());
  }

  // The signal at offset as an output, with its dependencies.
  void add_signal_output(int offset) {
    Variable v =
        variable(engine::signal_name(d_, offset), Role::output_signal, offset, d_.signal_unit(offset), "signal");
    v.dependencies.assign(signal_deps_[offset].begin(), signal_deps_[offset].end());
    add(v);
  }

  // The objective of node `node` as an output (refused at the description's line unless made of integrals).
  void add_objective_output(int node, int line) {
    const Node& n = d_.nodes[node];
    if (n.objective->needs_samples())
      throw InputError(e_.spec_file, line, "outputs",
                       "objective " + n.name + " needs its input sampled over the run (" + n.type->name +
                           "): an FMU gives only objectives made of integrals");
    Variable v = variable(n.name, Role::output_objective, node, d_.objective_unit(n),
                          "objective from its integrals so far (the run's value at the stop time)");
    for (int k = 0; k < n.block->num_quadratures(); ++k)
      v.dependencies.push_back(t_.first_state + d_.num_states + n.quad_offset + k);
    add(v);
  }

  // The outputs, and the check that no two variables share a name.
  void add_outputs() {
    // Outputs: the logged signals and requested objectives by default, else the named ones.
    std::set<std::string> output_names;
    if (e_.default_outputs) {
      for (const engine::LoggedSignal& s : d_.logged) add_signal_output(s.offset);
      for (int node : d_.objectives) add_objective_output(node, 0);
    } else {
      for (const ExposedName& out : e_.outputs) {
        const int node = find_objective(d_, out.name);
        if (node >= 0) {
          add_objective_output(node, out.line);
          continue;
        }
        std::vector<int> offsets;
        try {
          offsets = engine::signal_offsets(d_, out.name, "outputs");
        } catch (const InputError& error) {
          rethrow_at(e_, out.line, "outputs", error);
        }
        for (int offset : offsets) add_signal_output(offset);
      }
    }
    add_sensitivity_outputs();
    for (const Variable& v : t_.variables)
      if (!output_names.insert(v.name).second)
        throw InputError(e_.spec_file, 0, "outputs", "two variables of the FMU are named " + v.name);
  }

  // d(OUTPUT)/d(NAME) for each output and each sensitivity direction (the names of dydp's
  // signals.csv and objectives.json), depending on what its output depends on.
  void add_sensitivity_outputs() {
    if (t_.sensitivities.empty()) return;
    const size_t outputs = t_.variables.size();
    for (size_t o = 0; o < outputs; ++o) {
      const Variable out = t_.variables[o];
      if (out.role != Role::output_signal && out.role != Role::output_objective) continue;
      for (size_t k = 0; k < t_.sensitivities.size(); ++k) {
        const engine::SceneParameter& p = d_.parameters[t_.sensitivities[k]];
        Variable v = variable("d(" + out.name + ")/d(" + p.name + ")", Role::output_sensitivity,
                              static_cast<int>(out.value_reference), engine::unit_per(out.unit, p.unit),
                              "sensitivity of " + out.name + " to " + p.name + " (integrated with the states)");
        v.direction = static_cast<int>(k);
        v.dependencies = out.dependencies;
        add(v);
      }
    }
  }

  // One event indicator per breakpoint.
  void add_event_indicators() {
    // Event indicators: t - t_b for each breakpoint of the blocks over the scene's time span.
    t_.breakpoints = d_.breakpoints(d_.time.start, d_.time.stop);
    for (size_t k = 0; k < t_.breakpoints.size(); ++k) {
      add(variable("breakpoint[" + std::to_string(k) + "]", Role::event_indicator, static_cast<int>(k), "s",
                   "time minus a block's breakpoint (" + engine::format_number(t_.breakpoints[k]) + " s)"));
    }
  }

  Diagram& d_;
  const Exposure& e_;
  VariableTable t_;
  std::vector<std::set<uint32_t>> signal_deps_;  // per signal: the value references it depends on
};

}  // namespace

VariableTable build_variables(Diagram& d, const Exposure& e) { return TableBuilder(d, e).build(); }

}  // namespace dydp::fmi
