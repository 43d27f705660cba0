// dydp-gen for multibody models (see generate_mbs.hpp).
#include "generate_mbs.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <sstream>

#include "mass_loops_cpp.hpp"
#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/emit_cpp.hpp"
#include "symbolic/expand.hpp"
#include "symbolic/grouped_tangent.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"

namespace dydp::gen {
namespace {

using namespace dydp::symbolic;

std::string string_array(const std::string& name, const std::vector<std::string>& items) {
  std::string s = "const char* const " + name + "[] = {";
  for (std::size_t k = 0; k < items.size(); ++k) s += std::string(k % 6 ? "" : "\n    ") + "\"" + items[k] + "\", ";
  if (items.empty()) s += "nullptr";
  return s + "};\n";
}

/// The SI unit of a sensor port; components of different units are listed, comma-separated.
std::string sensor_unit(const mbs::Model& model, const mbs::Sensor& sensor) {
  using Type = mbs::Sensor::Type;
  std::vector<std::string> units;
  for (int c : sensor.components) {
    std::string u;
    switch (sensor.type) {
      case Type::Position: u = "m"; break;
      case Type::Velocity: u = "m/s"; break;
      case Type::Acceleration: u = "m/s^2"; break;
      case Type::AngularVelocity: u = "rad/s"; break;
      case Type::Length: u = c == 0 ? "m" : "m/s"; break;
      case Type::Joint: {
        const bool rotation = mbs::is_revolute(model.joints[sensor.joint].type);
        u = std::string(rotation ? "rad" : "m") + (c == 0 ? "" : c == 1 ? "/s" : "/s^2");
        break;
      }
    }
    if (std::find(units.begin(), units.end(), u) == units.end()) units.push_back(u);
  }
  std::string out;
  for (const auto& u : units) out += (out.empty() ? "" : ", ") + u;
  return out;
}

template <class T>
std::string number_array(const std::string& type, const std::string& name, const std::vector<T>& items) {
  std::ostringstream s;
  s.precision(17);
  s << "const " << type << " " << name << "[] = {";
  for (std::size_t k = 0; k < items.size(); ++k) s << (k % 8 ? "" : "\n    ") << items[k] << ", ";
  if (items.empty()) s << "0";
  s << "};\n";
  return s.str();
}

// A tangent list without its primal outputs: what only the derivatives read stays of the
// primal part (elimination drops the rest).
EquationList derivative_outputs_only(const EquationList& tangent) {
  EquationList list(tangent.context());
  for (const auto& a : tangent.assignments()) list.append(a);
  for (std::size_t k = tangent.primal_outputs(); k < tangent.outputs().size(); ++k) list.add_output(tangent.outputs()[k]);
  list.set_primal_split(tangent.primal_assignments(), 0);
  return list;
}

// The operations of one derivative part of a tangent list: assignments [first_assignment,
// end_assignment) and outputs [first_output, end_output), what each of its directions costs.
OpCount part_ops(const EquationList& list, std::size_t first_assignment, std::size_t end_assignment,
                       std::size_t first_output, std::size_t end_output) {
  EquationList part(list.context());
  for (std::size_t k = first_assignment; k < end_assignment; ++k) part.append(list.assignments()[k]);
  for (std::size_t k = first_output; k < end_output; ++k) part.add_output(list.outputs()[k]);
  return count_ops(part);
}

// Independent coordinates: the model's, or the columns a pivoted QR of J (free columns, at the
// initial configuration) leaves after picking the m best conditioned dependent ones.
std::vector<int> choose_independent(const mbs::Model& model, bool& automatic) {
  automatic = false;
  if (!model.independent.empty() || model.constraint_count() == 0) {
    if (!model.independent.empty()) return model.independent;
    std::vector<int> u;
    for (int j = 0; j < model.coordinates(); ++j)
      if (!model.joints[j].driven) u.push_back(j);
    return u;
  }
  automatic = true;
  mbs::NumericDynamics numeric(model);
  Eigen::VectorXd q0(model.coordinates());
  for (int j = 0; j < model.coordinates(); ++j) q0[j] = model.joints[j].initial;
  const Eigen::MatrixXd J = numeric.constraint_jacobian(q0);
  std::vector<int> free;
  for (int j = 0; j < model.coordinates(); ++j)
    if (!model.joints[j].driven) free.push_back(j);
  Eigen::MatrixXd Jf(J.rows(), static_cast<Eigen::Index>(free.size()));
  for (std::size_t i = 0; i < free.size(); ++i) Jf.col(i) = J.col(free[i]);
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Jf);
  if (qr.rank() < J.rows())
    throw std::runtime_error(model.file + ": the constraint Jacobian has rank " + std::to_string(qr.rank()) +
                             " < " + std::to_string(J.rows()) + " constraints at the initial configuration");
  std::vector<bool> dependent(free.size(), false);
  for (Eigen::Index i = 0; i < J.rows(); ++i) dependent[qr.colsPermutation().indices()[i]] = true;
  std::vector<int> u;
  for (std::size_t i = 0; i < free.size(); ++i)
    if (!dependent[i]) u.push_back(free[i]);
  return u;
}

// J's structural nonzeros, m x n row-major: 0 where J is zero whatever the state.
std::vector<int> jacobian_structure(const mbs::ModelLists& lists, int m, int n) {
  const Context& ctx = lists.constraints->context();
  std::vector<int> nonzero;
  for (int k = 0; k < m * n; ++k) {
    const NodeId v = lists.constraints->outputs()[m + k].value;
    nonzero.push_back(!(ctx.op(v) == Op::Constant && ctx.value(v) == 0.0));
  }
  return nonzero;
}

// The coordinates that move together: those a constraint row couples (J's structure) are one
// group, every other coordinate a group alone; driven coordinates are in none. The seeds of a
// direction along an independent coordinate (dq = B du) stay inside its group.
std::vector<std::vector<int>> coupled_coordinates(const mbs::Model& model, const std::vector<int>& nonzero) {
  const int n = model.coordinates(), m = model.constraint_count();
  std::vector<int> root(n);
  for (int i = 0; i < n; ++i) root[i] = i;
  const auto find = [&](int i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  std::vector<bool> driven(n, false);
  for (int j : model.driven_joints()) driven[j] = true;
  for (int r = 0; r < m; ++r) {
    int first = -1;
    for (int c = 0; c < n; ++c) {
      if (!nonzero[r * n + c] || driven[c]) continue;
      if (first < 0) first = c;
      else root[find(c)] = find(first);
    }
  }
  std::vector<std::vector<int>> groups;
  std::vector<int> group_of_root(n, -1);
  for (int c = 0; c < n; ++c) {
    if (driven[c]) continue;
    int& g = group_of_root[find(c)];
    if (g < 0) g = static_cast<int>(groups.size()), groups.emplace_back();
    groups[g].push_back(c);
  }
  return groups;
}

// Whether a sensor's outputs depend on qdd: acceleration sensors, and joint sensors that report
// the joint's acceleration.
bool reads_acceleration(const mbs::Sensor& sensor) {
  const bool reads_qdd = std::find(sensor.components.begin(), sensor.components.end(), 2) != sensor.components.end();
  return sensor.type == mbs::Sensor::Type::Acceleration || (sensor.type == mbs::Sensor::Type::Joint && reads_qdd);
}

// Items of the given sizes in `bins` bins of about equal total: the largest first into the bin
// with the least so far; each bin's items in their own order.
std::vector<std::vector<std::size_t>> balanced(const std::vector<std::size_t>& sizes, std::size_t bins) {
  std::vector<std::size_t> order(sizes.size()), load(bins, 0);
  for (std::size_t b = 0; b < order.size(); ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return sizes[a] > sizes[b]; });
  std::vector<std::vector<std::size_t>> members(bins);
  for (std::size_t b : order) {
    const auto bin = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[bin] += sizes[b];
    members[bin].push_back(b);
  }
  for (auto& m : members) std::sort(m.begin(), m.end());
  return members;
}

}  // namespace

MbsGeneration generate_mbs(const std::string& model_path, const GenerationOptions& options) {
  const mbs::Model model = mbs::load_model(model_path);
  const mbs::ModelLists lists = mbs::build_model_lists(model);
  const std::string name = model.name;
  MbsGeneration result;
  result.scheme_assignments = lists.assignments_built;

  EmitOptions emit;
  emit.namespace_name = "dydp::generated";
  emit.origin = model_path + (options.expand ? " (in extenso)" : " (recursive)");
  const std::vector<ArrayId> all_seeded = mbs::tangent_arrays(lists);

  auto plain = [&](const std::string& fn, const EquationList& list, bool expanded = false) {
    emit.function_name = fn;
    const EquationList written = expanded ? expand(list) : compact(list);
    result.functions.push_back({fn, lists.assignments_built, expanded ? written.outputs().size() : written.size(),
                                count_ops(written)});
    EmittedFunction f = emit_function(written, emit);
    measure_text(f.definition, result.functions.back());
    return f;
  };
  // `with_primal`: the tangent also writes the list's own outputs; without it only the derivative
  // part is kept (the mass: M qdd itself is never read, only the columns M [B beta]).
  auto tangent = [&](const std::string& fn, const EquationList& list, std::vector<ArrayId> arrays,
                     bool with_primal = true) {
    const Direction direction = seeded(list.context(), arrays);
    EliminationStats stats;
    // differentiated from the compact scheme, so the tangent's size follows the primal's
    EquationList d = differentiate(compact(list), std::span<const Direction>(&direction, 1));
    if (!with_primal) d = derivative_outputs_only(d);
    const EquationList t = compact(eliminate(d, &stats));
    emit.function_name = fn;
    result.functions.push_back({fn, stats.before, t.size(), count_ops(t)});
    result.functions.back().ops_per_direction =
        part_ops(t, t.primal_assignments(), t.size(), t.primal_outputs(), t.outputs().size()).total();
    EmittedFunction f = emit_tangent(t, arrays, emit);
    measure_text(f.definition, result.functions.back());
    return f;
  };

  std::filesystem::create_directories(options.out_dir);
  if (options.expand) {
    std::vector<EmittedFunction> fs;
    for (const auto& j : lists.jacobians) fs.push_back(plain(j.name, *j.list, true));
    const std::string header = name + "_expanded.hpp";
    write_atomically(options.out_dir / header, emit_header_file(fs, emit));
    write_atomically(options.out_dir / (name + "_expanded.cpp"), emit_source_file(fs, header, emit));
    return result;
  }

  // Six translation units, so that a large model's code compiles in parallel: dynamics (M and
  // the residual), its tangent, its velocity tangent, its tangent in blocks (empty for a model
  // without groups), kinematics (constraints), sensors and Jacobians.
  std::vector<EmittedFunction> dynamics, residual_tangent, kinematics, sensors;
  // sin and cos of the coordinates once per state, shared by every function below
  emit.trig_table = name + "_trig";
  dynamics.push_back(emit_trig_table(static_cast<std::size_t>(model.coordinates()), emit));
  dynamics.push_back(tangent(name + "_mass", *lists.inertial, {lists.qdd}, /*with_primal=*/false));
  dynamics.push_back(plain(name + "_residual", *lists.applied));
  if (lists.mass_matrix) dynamics.push_back(plain(name + "_mass_matrix", *lists.mass_matrix));
  if (lists.mass_loops) {
    std::vector<std::string> joints;
    for (const auto& j : model.joints) joints.push_back(j.name);
    for (auto& f : emit_mass_loops(*lists.mass_loops, name, joints, emit, result.functions)) dynamics.push_back(std::move(f));
  }
  residual_tangent.push_back(tangent(name + "_residual_tangent", *lists.residual, all_seeded));
  // The same, not seeded on q: for directions that leave the positions alone (a velocity, load
  // or acceleration seed), every derivative through the rotations and positions is zero and
  // the scheme keeps only what the velocities reach (on the sedan 58 % of the operations per
  // direction). Its own file, so that it compiles beside the full tangent.
  std::vector<EmittedFunction> velocity_tangent;
  velocity_tangent.push_back(
      tangent(name + "_residual_velocity_tangent", *lists.residual, {lists.qd, lists.qdd, lists.inp, lists.p}));
  const std::size_t n = model.coordinates(), m = model.constraint_count();
  std::vector<EmittedFunction> tangent_groups_tu;  // its own file: the entry of the grouped tangent
  // its blocks' functions, kTangentBlockFiles files balanced by assignments (the sedan's blocks
  // together are 28 000 assignments: one file of them took 6.5 minutes to compile under ASan)
  std::vector<std::vector<EmittedFunction>> tangent_block_files(kTangentBlockFiles);
  // (jacobian_nonzero: the descriptor's, and the coupling of the tangent's coordinate groups)
  const std::vector<int> jacobian_nonzero = jacobian_structure(lists, static_cast<int>(m), static_cast<int>(n));
  std::vector<int> tangent_group(n, -1);
  int tangent_groups = 0;
  auto part = [&](const std::string& label, const EquationList& list, std::size_t from, std::size_t to) {
    EquationList alone(list.context());
    for (const auto& a : list.assignments()) alone.append(a);
    for (std::size_t k = from; k < to; ++k) alone.add_output(list.outputs()[k]);
    const EquationList c = compact(eliminate(alone));
    result.parts.push_back({label, list.size(), c.size(), count_ops(c)});
  };
  part(name + "_residual.inverse_dynamics", *lists.applied, 0, n);
  part(name + "_residual.constraint_accelerations", *lists.applied, n, n + m);
  part(name + "_residual_tangent.primal_with_cut_forces", *lists.residual, 0, n);
  if (lists.constraint_kinematics) {
    part(name + "_constraints.h_J_Jdot_qd", *lists.constraint_kinematics, 0, m + m * n + m);
    part(name + "_constraints.Jdot_qd", *lists.constraint_kinematics, m + m * n, m + m * n + m);
  }
  kinematics.push_back(plain(name + "_constraints", *lists.constraints));
  kinematics.push_back(tangent(name + "_constraints_tangent", *lists.position_constraints, all_seeded));
  kinematics.push_back(tangent(name + "_velocity_constraints_tangent", *lists.velocity_constraints, all_seeded));
  sensors.push_back(plain(name + "_sensors", *lists.sensors));
  sensors.push_back(tangent(name + "_sensors_tangent", *lists.sensors, all_seeded));
  // The sensors in two groups, for a block that asks for positions and velocities before the
  // loads are known and for accelerations after: each call computes its own group only.
  for (const bool acceleration : {false, true}) {
    EquationList group(lists.sensors->context());
    for (const auto& a : lists.sensors->assignments()) group.append(a);
    std::size_t at = 0;
    for (const auto& sensor : model.sensors) {
      const std::size_t width = static_cast<std::size_t>(sensor.width());
      if (reads_acceleration(sensor) == acceleration)
        for (std::size_t k = 0; k < width; ++k) group.add_output(lists.sensors->outputs()[at + k]);
      at += width;
    }
    const EquationList reduced = symbolic::eliminate(group);
    const std::string fn = name + (acceleration ? "_sensors_acceleration" : "_sensors_kinematic");
    sensors.push_back(plain(fn, reduced));
    sensors.push_back(tangent(fn + "_tangent", reduced, all_seeded));
  }
  for (const auto& j : lists.jacobians) sensors.push_back(plain(j.name, *j.list));
  // The residual's tangent in blocks (symbolic/grouped_tangent.hpp): a full block and a velocity
  // block (as the residual's two tangents above), then for each group of coordinates that move
  // together a position block (q, qd, qdd seeded in the group) and a velocity block (qd, qdd in
  // the group), all after one primal. A group is kept when its position block costs at most half
  // of the full one per direction; models without constraints have none (the groups of a chain
  // are its single joints, whose blocks the full tangent serves). Built last, so that the other
  // functions' auxiliaries keep the names they had without it.
  if (m > 0) {
    auto specs_for = [&](const std::vector<std::vector<int>>& groups) {
      std::vector<BlockSeeds> specs{{"full", {{lists.q, {}}, {lists.qd, {}}, {lists.qdd, {}}, {lists.inp, {}}, {lists.p, {}}}},
                                    {"velocity", {{lists.qd, {}}, {lists.qdd, {}}, {lists.inp, {}}, {lists.p, {}}}}};
      for (std::size_t g = 0; g < groups.size(); ++g) {
        std::vector<std::uint32_t> e(groups[g].begin(), groups[g].end());
        std::string names;
        for (int c : groups[g]) names += (names.empty() ? "" : " ") + model.joints[c].name;
        specs.push_back({"group " + std::to_string(g) + " position (" + names + ")", {{lists.q, e}, {lists.qd, e}, {lists.qdd, e}}});
        specs.push_back({"group " + std::to_string(g) + " velocity (" + names + ")", {{lists.qd, e}, {lists.qdd, e}}});
      }
      return specs;
    };
    auto block_ops = [](const GroupedTangent& t, std::size_t b) {
      const TangentBlock& block = t.blocks[b];
      return part_ops(t.list, block.assignments_begin, block.assignments_end, block.outputs_begin, block.outputs_end);
    };
    const std::vector<std::vector<int>> candidates = coupled_coordinates(model, jacobian_nonzero);
    const GroupedTangent trial = grouped_tangent(*lists.residual, specs_for(candidates));
    std::vector<std::vector<int>> kept;
    for (std::size_t g = 0; g < candidates.size(); ++g)
      if (2 * block_ops(trial, 2 + 2 * g).total() <= block_ops(trial, 0).total()) kept.push_back(candidates[g]);
    if (!kept.empty()) {
      const GroupedTangent grouped = grouped_tangent(*lists.residual, specs_for(kept));
      const std::string fn = name + "_residual_tangent_groups";
      emit.function_name = fn;
      result.functions.push_back({fn, lists.residual->size(), grouped.list.size(), count_ops(grouped.list)});
      // each block's part (what one of its directions costs)
      for (std::size_t b = 0; b < grouped.blocks.size(); ++b) {
        const std::size_t size = grouped.blocks[b].assignments_end - grouped.blocks[b].assignments_begin;
        result.parts.push_back({fn + "." + grouped.blocks[b].label, size, size, block_ops(grouped, b)});
      }
      GroupedTangentFunctions f = emit_grouped_tangent(grouped, all_seeded, emit);
      std::string text = f.entry.definition;
      for (const auto& block : f.blocks) text += block.definition;
      measure_text(text, result.functions.back());
      tangent_groups_tu.push_back(std::move(f.entry));
      std::vector<std::size_t> sizes;
      for (const TangentBlock& block : grouped.blocks) sizes.push_back(block.assignments_end - block.assignments_begin);
      const std::vector<std::vector<std::size_t>> members = balanced(sizes, kTangentBlockFiles);
      for (std::size_t file = 0; file < members.size(); ++file)
        for (std::size_t b : members[file]) tangent_block_files[file].push_back(std::move(f.blocks[b]));
      tangent_groups = static_cast<int>(kept.size());
      for (std::size_t g = 0; g < kept.size(); ++g)
        for (int c : kept[g]) tangent_group[c] = static_cast<int>(g);
    }
  }

  bool automatic = false;
  const std::vector<int> independent = choose_independent(model, automatic);
  result.independent_automatic = automatic;
  for (int j : independent) result.independent.push_back(model.joints[j].name);

  std::vector<EmittedFunction> all = dynamics;
  for (const auto* part : {&residual_tangent, &velocity_tangent, &tangent_groups_tu, &kinematics, &sensors})
    all.insert(all.end(), part->begin(), part->end());
  for (const auto& file : tangent_block_files) all.insert(all.end(), file.begin(), file.end());
  const std::string header = name + ".hpp";
  std::string header_text = emit_header_file(all, emit);
  header_text += "\n#include \"symbolic/mbs/generated_model.hpp\"\n\nnamespace dydp::generated {\nextern const dydp::mbs::GeneratedModel " +
                 name + "_model;\n}  // namespace dydp::generated\n";
  write_atomically(options.out_dir / header, header_text);
  write_atomically(options.out_dir / (name + "_dynamics.cpp"), emit_source_file(dynamics, header, emit));
  write_atomically(options.out_dir / (name + "_residual_tangent.cpp"), emit_source_file(residual_tangent, header, emit));
  write_atomically(options.out_dir / (name + "_velocity_tangent.cpp"), emit_source_file(velocity_tangent, header, emit));
  write_atomically(options.out_dir / (name + "_tangent_groups.cpp"), emit_source_file(tangent_groups_tu, header, emit));
  for (std::size_t file = 0; file < tangent_block_files.size(); ++file)
    write_atomically(options.out_dir / (name + "_tangent_blocks_" + std::to_string(file) + ".cpp"),
                     emit_source_file(tangent_block_files[file], header, emit));
  write_atomically(options.out_dir / (name + "_kinematics.cpp"), emit_source_file(kinematics, header, emit));
  write_atomically(options.out_dir / (name + "_sensors.cpp"), emit_source_file(sensors, header, emit));

  // The descriptor.
  std::vector<std::string> coordinates, parameters, parameter_units;
  std::vector<double> parameter_values, q0;
  for (const auto& j : model.joints) {
    coordinates.push_back(j.name);
    q0.push_back(j.initial);
  }
  for (const auto& p : model.parameters)
    if (p.symbolic) {
      parameters.push_back(p.name);
      parameter_values.push_back(p.value);
      parameter_units.push_back(p.unit);
    }
  const std::vector<int> driven = model.driven_joints();
  std::string d = "// Generated by dydp-gen; do not edit.\n// Source: " + emit.origin + "\n#include \"" + header +
                  "\"\n\nnamespace dydp::generated {\nnamespace {\n";
  d += string_array("coordinate_names", coordinates);
  d += string_array("input_names", model.input_names());
  d += string_array("parameter_names", parameters);
  d += number_array("double", "parameter_values", parameter_values);
  d += string_array("parameter_units", parameter_units);
  d += string_array("sensor_names", model.sensor_output_names());
  std::vector<std::string> sensor_ports;
  std::vector<int> sensor_widths, sensor_acc;
  std::vector<std::string> sensor_units;
  for (const auto& sensor : model.sensors) {
    sensor_ports.push_back(sensor.name);
    sensor_units.push_back(sensor_unit(model, sensor));
    sensor_widths.push_back(sensor.width());
    sensor_acc.push_back(reads_acceleration(sensor));
  }
  std::vector<std::string> load_names;
  std::vector<int> load_widths;
  for (const auto& load : model.loads) {
    load_names.push_back(load.name);
    load_widths.push_back(load.width());
  }
  d += string_array("load_names", load_names);
  d += number_array("int", "load_widths", load_widths);
  d += string_array("sensor_ports", sensor_ports);
  d += number_array("int", "sensor_widths", sensor_widths);
  d += number_array("int", "sensor_reads_acceleration", sensor_acc);
  d += string_array("sensor_units", sensor_units);
  d += number_array("double", "initial_q", q0);
  d += number_array("int", "driven", driven);
  d += number_array("int", "independent", independent);
  d += number_array("int", "jacobian_nonzero", jacobian_nonzero);
  d += number_array("int", "tangent_group", tangent_group);
  // the mass matrix's entries: (row, col) of each output of NAME_mass_matrix, read off its names
  std::vector<int> mass_rows, mass_cols;
  if (lists.mass_loops) mass_loops_entries(*lists.mass_loops, mass_rows, mass_cols);
  for (const auto& o : lists.mass_matrix ? lists.mass_matrix->outputs() : std::vector<symbolic::Output>{}) {
    const auto comma = o.name.find(',');
    mass_rows.push_back(std::stoi(o.name.substr(2, comma - 2)));
    mass_cols.push_back(std::stoi(o.name.substr(comma + 1)));
  }
  d += number_array("int", "mass_rows", mass_rows);
  d += number_array("int", "mass_cols", mass_cols);
  d += "}  // namespace\n\n";
  d += "// independent coordinates" + std::string(automatic ? " (automatic, pivoted QR of J at q0)" : "") + ":";
  for (const auto& u : result.independent) d += " " + u;
  d += "\nextern const dydp::mbs::GeneratedModel " + name + "_model = {\n";
  d += "    \"" + name + "\", " + std::to_string(model.coordinates()) + ", " + std::to_string(model.constraint_count()) +
       ", " + std::to_string(model.input_count()) + ", " + std::to_string(model.loads.size()) + ", " +
       std::to_string(parameters.size()) + ", " + std::to_string(model.sensor_output_names().size()) + ",\n";
  d += "    coordinate_names, input_names, parameter_names, parameter_values, sensor_names,\n";
  d += "    " + std::to_string(sensor_ports.size()) + ", sensor_ports, sensor_widths, sensor_reads_acceleration, initial_q,\n";
  d += "    " + std::to_string(driven.size()) + ", driven, " + std::to_string(independent.size()) + ", independent,\n";
  d += "    " + name + "_mass, " + name + "_residual, " + name + "_residual_tangent, " + name + "_constraints,\n";
  d += "    " + name + "_velocity_constraints_tangent, " + name + "_sensors, " + name + "_sensors_tangent,\n";
  d += "    " + std::to_string(model.load_input_count()) + ", load_names, load_widths, sensor_units,\n";
  d += "    jacobian_nonzero, " + name + "_constraints_tangent,\n";
  d += "    " + std::to_string(mass_rows.size()) + ", mass_rows, mass_cols, " +
       (lists.mass_matrix || lists.mass_loops ? name + "_mass_matrix" : std::string("nullptr")) + ",\n    parameter_units,\n";
  d += "    " + name + "_sensors_kinematic, " + name + "_sensors_kinematic_tangent, " + name + "_sensors_acceleration, " +
       name + "_sensors_acceleration_tangent,\n    " + name + "_residual_velocity_tangent,\n";
  d += "    " + std::to_string(tangent_groups) + ", tangent_group, " +
       (tangent_groups > 0 ? name + "_residual_tangent_groups" : std::string("nullptr")) + "};\n\n";
  d += "}  // namespace dydp::generated\n";
  write_atomically(options.out_dir / (name + "_model.cpp"), d);
  return result;
}

}  // namespace dydp::gen
