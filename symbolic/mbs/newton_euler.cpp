// Symbolic recursive Newton-Euler. Kinematics forward from the ground, in the components of each
// joint frame: omega_k = R_k^T omega_p + qd_k e (revolute), accelerations likewise with the
// ground accelerating at -g so that gravity enters as an inertial force; then the wrenches
// backward: f_k = m a_G - F_ext + sum R_c f_c, n_k = I omegadot + omega x I omega + c x m a_G -
// N_ext + sum (R_c n_c + r_c x R_c f_c), joint force Q_k = e . n_k (revolute) or e . f_k.
// This file: the lists of ModelLists, taken from the scheme (run(), merged()); the scheme's parts
// in newton_euler_kinematics.cpp, _dynamics.cpp, _mass.cpp, _constraints.cpp and _sensors.cpp.
#include "symbolic/mbs/newton_euler.hpp"

#include <algorithm>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/mbs/newton_euler_generator.hpp"

namespace dydp::mbs {
namespace detail {

using symbolic::Direction;

Generator::Generator(const Model& model, ModelLists& out) : m_(model), out_(out) {
  out_.context = std::make_unique<Context>();
  Context& ctx = *out_.context;
  ctx_ = &ctx;
  const std::size_t n = model.coordinates();
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  out_.q = ctx.add_array("q", n, SymbolKind::Input);
  out_.qd = ctx.add_array("qd", n, SymbolKind::Input);
  out_.qdd = ctx.add_array("qdd", n, SymbolKind::Input);
  out_.lam = ctx.add_array("lam", std::max(1, model.constraint_count()), SymbolKind::Input);
  out_.inp = ctx.add_array("inp", std::max(1, model.input_count()), SymbolKind::Input);
  out_.p = ctx.add_array("p", std::max(1, model.symbolic_parameter_count()), SymbolKind::Parameter);
  int k = 0;
  for (const Parameter& par : model.parameters) param_index_.push_back(par.symbolic ? k++ : -1);
  all_ = std::make_unique<EquationList>(ctx);
}

void Generator::run(MassForm mass_form) {
  positions();
  velocities();
  std::vector<Expr> qdd, zero(m_.coordinates(), ctx_->zero());
  for (int j = 0; j < m_.coordinates(); ++j) qdd.push_back(ctx_->element(out_.qdd, j));

  // The inertial pass: M qdd.
  const std::vector<Expr> inertial = dynamics(qdd, /*full=*/false, "I");
  // The full pass: M qdd + c - J^T lam; and without the cut forces, M qdd + c.
  const std::vector<Expr> residual = dynamics(qdd, /*full=*/true, "");
  const std::vector<Expr> applied = dynamics(qdd, /*full=*/true, "V", /*cut_forces=*/false);
  const std::vector<Expr> h = constraint_values();
  const std::vector<Expr> sensors = sensor_values();

  const int n = m_.coordinates();
  const int mc = m_.constraint_count();
  auto outputs = [](const std::string& prefix, const std::vector<Expr>& values) {
    std::vector<Output> o;
    for (std::size_t i = 0; i < values.size(); ++i) o.push_back({prefix + "[" + std::to_string(i) + "]", values[i].id()});
    return o;
  };
  out_.inertial = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, outputs("Mqdd", inertial))));
  const bool shallow = mass_entry_count() <= kMassEntriesPerCoordinate * static_cast<std::size_t>(m_.coordinates());
  if (mass_form == MassForm::Entries || (mass_form == MassForm::Automatic && shallow)) {
    std::vector<Output> o;
    for (const MassEntry& e : mass_matrix())
      o.push_back({"M[" + std::to_string(e.row) + "," + std::to_string(e.col) + "]", e.value.id()});
    out_.mass_matrix = merged(o, {}, o);
  } else {
    out_.mass_loops = mass_loops();
  }

  // The constraint kinematics: h and J from the relative kinematics of the cut points (a joint
  // turns a point by e x r: constraint_jacobian()), J qd from them. The residual's constraint
  // accelerations J qdd + Jdot qd are the cut points' relative accelerations from the full
  // pass's forward kinematics (cut_accelerations()); Jdot qd is the same at qdd = 0.
  const std::vector<std::vector<Expr>> J = constraint_jacobian();
  std::vector<Expr> jqd;
  for (int i = 0; i < mc; ++i) {
    std::vector<Expr> terms;
    for (int j = 0; j < n; ++j)
      if (!J[i][j].is_zero()) terms.push_back(J[i][j] * ctx_->element(out_.qd, j));
    jqd.push_back(all_->assign("HD" + std::to_string(i + 1), ctx_->sum(terms)));
  }
  out_.assignments_built = all_->size();
  {
    const std::vector<Output> accelerations = outputs("a", cut_accelerations());
    std::vector<Output> o = outputs("r", residual), v = outputs("r", applied);
    for (const Output& a : accelerations) {
      o.push_back(a);
      v.push_back(a);
    }
    out_.residual = merged(o, {}, o);
    out_.applied = merged(v, {}, v);
  }
  {
    std::vector<Output> o = outputs("h", h);
    for (int i = 0; i < mc; ++i)
      for (int j = 0; j < n; ++j) o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", J[i][j].id()});
    out_.constraints = merged(o, {}, o);
  }
  {
    std::vector<Output> o = outputs("h", h);
    for (const Output& a : outputs("hdot", jqd)) o.push_back(a);
    out_.velocity_constraints = merged(o, {}, o);
  }
  if (const std::vector<Expr> bias = constraint_bias(); mc > 0 && !bias.empty()) {
    std::vector<Output> o = outputs("h", h);
    for (int i = 0; i < mc; ++i)
      for (int j = 0; j < n; ++j) o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", J[i][j].id()});
    for (const Output& a : outputs("Jdot_qd", bias)) o.push_back(a);
    out_.constraint_kinematics = merged(o, {}, o);
  }
  out_.position_constraints = merged(outputs("h", h), {}, outputs("h", h));
  out_.sensors = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, outputs("s", sensors))));

  std::vector<Direction> along_q;
  for (int j = 0; j < n; ++j) along_q.push_back(symbolic::along(ctx_->element(out_.q, j)));
  for (const JacobianRequest& request : m_.jacobians) {
    const V3 x = point_position(request.point);
    std::vector<Expr> xs{x[0], x[1], x[2]};
    const EquationList x_list = symbolic::eliminate(with_outputs(*all_, outputs("x", xs)));
    const EquationList dx = symbolic::differentiate(x_list, along_q);
    std::vector<Output> o;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < n; ++j)
        o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", dx.outputs()[3 + 3 * j + i].value});
    EquationList list(*ctx_);
    for (const auto& a : dx.assignments()) list.append(a);
    for (auto& output : o) list.add_output(std::move(output));
    out_.jacobians.push_back({request.name, std::make_unique<EquationList>(symbolic::eliminate(list))});
  }
}

// One list from the recursive scheme (the part `base_outputs` needs) followed by every
// assignment of the given lists not already in it (their primal parts are compactions of the
// scheme, their derivative parts new), eliminated. An assignment reads only earlier ones of
// its own list, which are placed before it.
std::unique_ptr<EquationList> Generator::merged(std::vector<Output> base_outputs,
                                                std::vector<const EquationList*> lists, std::vector<Output> outputs) {
  const EquationList base = symbolic::eliminate(with_outputs(*all_, std::move(base_outputs)));
  EquationList list(*ctx_);
  std::vector<bool> seen(ctx_->size(), false);
  for (const auto& a : base.assignments()) {
    list.append(a);
    seen[a.target] = true;
  }
  for (const EquationList* l : lists) {
    for (const auto& a : l->assignments()) {
      if (a.target >= seen.size()) seen.resize(ctx_->size(), false);
      if (seen[a.target]) continue;
      seen[a.target] = true;
      list.append(a);
    }
  }
  for (auto& o : outputs) list.add_output(std::move(o));
  return std::make_unique<EquationList>(symbolic::eliminate(list));
}

}  // namespace detail

ModelLists build_model_lists(const Model& model, MassForm mass_form) {
  ModelLists lists;
  detail::Generator(model, lists).run(mass_form);
  return lists;
}

std::vector<symbolic::ArrayId> tangent_arrays(const ModelLists& lists) {
  return {lists.q, lists.qd, lists.qdd, lists.inp, lists.p};
}

}  // namespace dydp::mbs
