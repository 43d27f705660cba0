// dydp-gen for multibody models (see generate_mbs.hpp): the model's functions, built in order and
// written by translation unit; the descriptor is model_descriptor.cpp's.
#include "generate_mbs.hpp"

#include <Eigen/Dense>
#include <algorithm>

#include "mass_loops_cpp.hpp"
#include "model_descriptor.hpp"
#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/emit_cpp.hpp"
#include "symbolic/expand.hpp"
#include "symbolic/grouped_tangent.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"
#include "symbolic/reverse.hpp"

namespace dydp::gen {
namespace {

using namespace dydp::symbolic;

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

// The steps of generate_mbs and what they share: the model and its lists, the emission options
// (each function's name set as it is emitted), the statistics gathered into `result`, and the
// emitted functions by the file they go to. generate_mbs calls the steps in a fixed order: the
// functions' auxiliaries are named in the order the functions are built (see build_tangent_groups).
struct MbsGenerator {
  MbsGenerator(const mbs::Model& model, const mbs::ModelLists& lists, const std::string& model_path,
               const GenerationOptions& options, MbsGeneration& result);

  EmittedFunction plain(const std::string& fn, const EquationList& list, bool expanded = false);
  // `with_primal`: the tangent also writes the list's own outputs; without it only the derivative
  // part is kept (the mass: M qdd itself is never read, only the columns M [B beta]).
  EmittedFunction tangent(const std::string& fn, const EquationList& list, std::vector<ArrayId> arrays,
                          bool with_primal = true);

  // GenerationOptions::expand: the point Jacobians in extenso, NAME_expanded.hpp and NAME_expanded.cpp.
  void write_expanded(const GenerationOptions& options);
  // The trig table, M, the residual and the mass matrix; the residual's tangent and velocity tangent.
  void build_dynamics();
  // MbsGeneration::parts.
  void measure_parts();
  // The residual's vector-Jacobian product (symbolic/reverse.hpp) measured as a part beside its
  // tangent: one weight vector on r and the constraint accelerations, products for every seeded
  // array. Not emitted yet; run last, so that the nodes it adds cannot touch the code written.
  void measure_adjoint();
  // The constraints and their tangents.
  void build_kinematics();
  // The sensors, all and in two groups, with their tangents; the point Jacobians.
  void build_sensors();
  // NAME_residual_tangent_groups (its entry and its blocks) and each coordinate's group.
  void build_tangent_groups(const std::vector<int>& jacobian_nonzero);
  // NAME.hpp and every source file but the descriptor.
  void write_sources(const GenerationOptions& options, const std::string& header) const;

  const mbs::Model& model;
  const mbs::ModelLists& lists;
  const std::string name;
  MbsGeneration& result;
  EmitOptions emit;
  std::vector<ArrayId> all_seeded;
  const std::size_t n, m;
  // Six translation units, so that a large model's code compiles in parallel: dynamics (M and
  // the residual), its tangent, its velocity tangent, its tangent in blocks (empty for a model
  // without groups), kinematics (constraints), sensors and Jacobians.
  std::vector<EmittedFunction> dynamics, residual_tangent, kinematics, sensors;
  std::vector<EmittedFunction> velocity_tangent;
  std::vector<EmittedFunction> tangent_groups_tu;  // its own file: the entry of the grouped tangent
  // its blocks' functions, kTangentBlockFiles files balanced by assignments (the sedan's blocks
  // together are 28 000 assignments: one file of them took 6.5 minutes to compile under ASan)
  std::vector<std::vector<EmittedFunction>> tangent_block_files =
      std::vector<std::vector<EmittedFunction>>(kTangentBlockFiles);
  std::vector<int> tangent_group;  // each coordinate's group in the grouped tangent, -1 for none
  int tangent_groups = 0;
};

MbsGenerator::MbsGenerator(const mbs::Model& model, const mbs::ModelLists& lists, const std::string& model_path,
                           const GenerationOptions& options, MbsGeneration& result)
    : model(model), lists(lists), name(model.name), result(result), n(model.coordinates()),
      m(model.constraint_count()), tangent_group(n, -1) {
  emit.namespace_name = "dydp::generated";
  emit.origin = model_path + (options.expand ? " (in extenso)" : " (recursive)");
  all_seeded = mbs::tangent_arrays(lists);
}

EmittedFunction MbsGenerator::plain(const std::string& fn, const EquationList& list, bool expanded) {
  emit.function_name = fn;
  const EquationList written = expanded ? expand(list) : compact(list);
  result.functions.push_back({fn, lists.assignments_built, expanded ? written.outputs().size() : written.size(),
                              count_ops(written)});
  EmittedFunction f = emit_function(written, emit);
  measure_text(f.definition, result.functions.back());
  return f;
}

EmittedFunction MbsGenerator::tangent(const std::string& fn, const EquationList& list, std::vector<ArrayId> arrays,
                                      bool with_primal) {
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
}

void MbsGenerator::write_expanded(const GenerationOptions& options) {
  std::vector<EmittedFunction> fs;
  for (const auto& j : lists.jacobians) fs.push_back(plain(j.name, *j.list, true));
  const std::string header = name + "_expanded.hpp";
  write_atomically(options.out_dir / header, emit_header_file(fs, emit));
  write_atomically(options.out_dir / (name + "_expanded.cpp"), emit_source_file(fs, header, emit));
}

void MbsGenerator::build_dynamics() {
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
  velocity_tangent.push_back(
      tangent(name + "_residual_velocity_tangent", *lists.residual, {lists.qd, lists.qdd, lists.inp, lists.p}));
}

void MbsGenerator::measure_parts() {
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
}

void MbsGenerator::measure_adjoint() {
  const EquationList adjoint = compact(adjoint_list(*lists.residual, all_seeded));
  const EquationList primal = compact(eliminate(*lists.residual));
  FunctionStats part{name + "_residual_adjoint", adjoint.size(), adjoint.size(), count_ops(adjoint)};
  // what the reverse sweep adds to the primal: the cost of one more weight vector
  part.ops_per_direction = part.ops.total() - std::min(part.ops.total(), count_ops(primal).total());
  result.parts.push_back(part);
}

void MbsGenerator::build_kinematics() {
  kinematics.push_back(plain(name + "_constraints", *lists.constraints));
  kinematics.push_back(tangent(name + "_constraints_tangent", *lists.position_constraints, all_seeded));
  kinematics.push_back(tangent(name + "_velocity_constraints_tangent", *lists.velocity_constraints, all_seeded));
}

void MbsGenerator::build_sensors() {
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
}

void MbsGenerator::build_tangent_groups(const std::vector<int>& jacobian_nonzero) {
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
}

void MbsGenerator::write_sources(const GenerationOptions& options, const std::string& header) const {
  std::vector<EmittedFunction> all = dynamics;
  for (const auto* part : {&residual_tangent, &velocity_tangent, &tangent_groups_tu, &kinematics, &sensors})
    all.insert(all.end(), part->begin(), part->end());
  for (const auto& file : tangent_block_files) all.insert(all.end(), file.begin(), file.end());
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
}

}  // namespace

MbsGeneration generate_mbs(const std::string& model_path, const GenerationOptions& options) {
  const mbs::Model model = mbs::load_model(model_path);
  const mbs::ModelLists lists = mbs::build_model_lists(model);
  const std::string name = model.name;
  MbsGeneration result;
  result.scheme_assignments = lists.assignments_built;
  MbsGenerator g(model, lists, model_path, options, result);

  std::filesystem::create_directories(options.out_dir);
  if (options.expand) {
    g.write_expanded(options);
    return result;
  }

  g.build_dynamics();
  // (jacobian_nonzero: the descriptor's, and the coupling of the tangent's coordinate groups)
  const std::vector<int> jacobian_nonzero = jacobian_structure(lists, static_cast<int>(g.m), static_cast<int>(g.n));
  g.measure_parts();
  g.build_kinematics();
  g.build_sensors();
  g.build_tangent_groups(jacobian_nonzero);

  bool automatic = false;
  const std::vector<int> independent = choose_independent(model, automatic);
  result.independent_automatic = automatic;
  for (int j : independent) result.independent.push_back(model.joints[j].name);

  const std::string header = name + ".hpp";
  g.write_sources(options, header);
  DescriptorChoices choices;
  choices.origin = g.emit.origin;
  choices.header = header;
  choices.independent = independent;
  choices.independent_automatic = automatic;
  choices.jacobian_nonzero = jacobian_nonzero;
  choices.tangent_group = g.tangent_group;
  choices.tangent_groups = g.tangent_groups;
  write_atomically(options.out_dir / (name + "_model.cpp"), model_descriptor(model, lists, choices));
  g.measure_adjoint();
  return result;
}

}  // namespace dydp::gen
