// The mass matrix by composite inertias: the subtrees' inertias backward, then each joint's
// unit-acceleration wrench carried to its ancestors, as one assignment per entry (mass_matrix())
// or as loops over the lanes (mass_loops()).
#include "symbolic/mbs/newton_euler_generator.hpp"

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "symbolic/dag_walk.hpp"
#include "symbolic/eliminate.hpp"

namespace dydp::mbs::detail {

Generator::Sym Generator::sym_from(const std::function<Expr(int, int)>& entry) {
  return {entry(0, 0), entry(1, 1), entry(2, 2), entry(0, 1), entry(0, 2), entry(1, 2)};
}

// Composite k moved into its parent's frame: rotation R (rotate(k, .)), origin r there:
// h' = R h + m r, J' = R J R^T - (h' r^T + r h'^T) + (2 r.h' + m |r|^2) E - m r r^T, with
// R h the moment about O_k and h' about the parent's origin (of R h + m r, the R h part).
Generator::Composite Generator::to_parent(int k, const Composite& c) {
  const V3 r = offset_[k];
  const V3 h = rotate(k, c.moment);  // about O_k, parent components
  std::array<V3, 3> columns;          // R J R^T by columns: R (J (R^T e_c))
  for (int col = 0; col < 3; ++col) columns[col] = rotate(k, c.inertia.apply(rotate_back(k, unit(col))));
  const Expr rh = dot(r, h), rr = dot(r, r);
  const Expr diagonal = ctx_->constant(2.0) * rh + c.mass * rr;
  const Sym J = sym_from([&](int a, int b) {
    Expr e = columns[b][a] - (h[a] * r[b] + r[a] * h[b]) - c.mass * (r[a] * r[b]);
    return a == b ? e + diagonal : e;
  });
  return {c.mass, h + c.mass * r, J};
}

Generator::Composite Generator::body_composite(int k) {
  const Joint& j = m_.joints[k];
  if (j.body < 0) return {ctx_->zero(), zero3(), {ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero()}};
  const Body& b = m_.bodies[j.body];
  const Expr mass = val(b.mass);
  const V3 c = vec(b.com);
  const Sym I{val(b.inertia[0]), val(b.inertia[1]), val(b.inertia[2]), val(b.inertia[3]), val(b.inertia[4]), val(b.inertia[5])};
  const Expr cc = dot(c, c);
  // about the frame origin: I_G + m (|c|^2 E - c c^T)
  const Sym J = sym_from([&](int a, int e) {
    Expr v = I.at(a, e) - mass * (c[a] * c[e]);
    return a == e ? v + mass * cc : v;
  });
  return {mass, mass * c, J};
}

// The number of entries of the composite-inertia M (kMassEntriesPerCoordinate).
std::size_t Generator::mass_entry_count() const {
  std::size_t count = 0;
  for (int i = 0; i < m_.coordinates(); ++i)
    for (int k = i; k >= 0; k = m_.joints[k].parent) ++count;
  return count;
}

// The composite inertia of every joint's subtree about its origin, in its components.
std::vector<Generator::Composite> Generator::composites() {
  const int n = m_.coordinates();
  std::vector<Composite> composite(n);
  for (const int k : m_.order) composite[k] = body_composite(k);
  for (auto it = m_.order.rbegin(); it != m_.order.rend(); ++it) {
    const int k = *it;
    Composite& c = composite[k];
    const std::string tag = "CM" + std::to_string(k + 1);
    c.mass = all_->assign(tag + "_m", c.mass);
    c.moment = assign(tag + "_h", 0, c.moment);
    c.inertia = sym_from([&](int a, int b) {
      return all_->assign(tag + "_J" + std::to_string(a + 1) + std::to_string(b + 1), c.inertia.at(a, b));
    });
    const int parent = m_.joints[k].parent;
    if (parent < 0) continue;
    const Composite moved = to_parent(k, c);
    Composite& p = composite[parent];
    p.mass = p.mass + moved.mass;
    p.moment = p.moment + moved.moment;
    p.inertia = sym_from([&](int a, int b) { return p.inertia.at(a, b) + moved.inertia.at(a, b); });
  }
  return composite;
}

// The force and torque (about its origin, its components) joint i's unit acceleration needs
// on its subtree: revolute axis e: F = e x h, N = J e; prismatic: F = m e, N = h x e.
std::pair<V3, V3> Generator::unit_wrench(int i, const Composite& c) {
  const V3 e = joint_axis(i);
  if (is_revolute(m_.joints[i].type)) return {cross(e, c.moment), c.inertia.apply(e)};
  return {c.mass * e, cross(c.moment, e)};
}

// M(i, k) from joint i's wrench in joint k's frame: k's axis against N (revolute) or F.
Expr Generator::mass_entry(int k, const V3& F, const V3& N) {
  const V3 axis = joint_axis(k);
  return is_revolute(m_.joints[k].type) ? dot(axis, N) : dot(axis, F);
}

// The mass matrix by composite inertias: the subtrees' inertias backward, then for each joint
// i the force and torque its unit acceleration needs on its subtree (revolute axis e:
// F = e x h, N = J e; prismatic: F = m e, N = h x e), carried to every ancestor k, where
// M(i, k) is k's axis against them. Entries of two joints neither of which carries the other
// are zero and not computed (two suspension corners). One entry (i, k) per joint i and k = i
// or an ancestor of i: M(i, k) = M(k, i).
std::vector<Generator::MassEntry> Generator::mass_matrix() {
  const int n = m_.coordinates();
  const std::vector<Composite> composite = composites();
  std::vector<MassEntry> entries;
  for (int i = 0; i < n; ++i) {
    const std::pair<V3, V3> wrench = unit_wrench(i, composite[i]);
    V3 F = wrench.first, N = wrench.second;
    auto entry = [&](int k) {
      entries.push_back({i, k, all_->assign("MM" + std::to_string(i + 1) + "_" + std::to_string(k + 1), mass_entry(k, F, N))});
    };
    entry(i);
    for (int k = i; m_.joints[k].parent >= 0; k = m_.joints[k].parent) {
      F = rotate(k, F);
      N = rotate(k, N) + cross(offset_[k], F);
      const std::string tag = std::to_string(i + 1) + "_" + std::to_string(k + 1);
      F = assign("MF" + tag + "_", 0, F);
      N = assign("MN" + tag + "_", 0, N);
      entry(m_.joints[k].parent);
    }
  }
  return entries;
}

// The same recursion with its sweeps as loops (MassLoops): the lanes in depth-first order,
// then for each joint k below a root, deepest first, the lanes of k's subtree (all in k's
// frame by then) carried to its parent's frame, F' = R F, N' = R N + r x F', and
// M(i, parent) read off them. The sweeps' expressions are in placeholders, so that their code
// is one loop body per joint whatever the number of lanes it carries.
std::unique_ptr<MassLoops> Generator::mass_loops() {
  const int n = m_.coordinates();
  auto loops = std::make_unique<MassLoops>();
  std::vector<std::vector<int>> children(n);
  std::vector<int> roots;
  for (int k = 0; k < n; ++k) (m_.joints[k].parent < 0 ? roots : children[m_.joints[k].parent]).push_back(k);
  std::vector<int> position(n), size(n, 1);
  std::vector<int> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const int k = stack.back();
    stack.pop_back();
    position[k] = static_cast<int>(loops->lane_joint.size());
    loops->lane_joint.push_back(k);
    for (auto c = children[k].rbegin(); c != children[k].rend(); ++c) stack.push_back(*c);
  }
  for (auto t = loops->lane_joint.rbegin(); t != loops->lane_joint.rend(); ++t)
    if (m_.joints[*t].parent >= 0) size[m_.joints[*t].parent] += size[*t];

  const std::vector<Composite> composite = composites();
  std::vector<Output> o(7 * static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t) {
    const int i = loops->lane_joint[t];
    const std::pair<V3, V3> wrench = unit_wrench(i, composite[i]);
    const V3& F = wrench.first;
    const V3& N = wrench.second;
    const std::string tag = std::to_string(i + 1);
    for (int a = 0; a < 3; ++a) {
      o[a * n + t] = {"F" + std::to_string(a + 1) + "[" + tag + "]", F[a].id()};
      o[(a + 3) * n + t] = {"N" + std::to_string(a + 1) + "[" + tag + "]", N[a].id()};
    }
    o[6 * n + t] = {"M[" + std::to_string(i) + "," + std::to_string(i) + "]", mass_entry(i, F, N).id()};
  }
  V3 F, N, Fm, Nm;
  for (int a = 0; a < 3; ++a) {
    F[a] = ctx_->aux("mf" + std::to_string(a + 1));
    N[a] = ctx_->aux("mn" + std::to_string(a + 1));
    Fm[a] = ctx_->aux("mg" + std::to_string(a + 1));
    Nm[a] = ctx_->aux("mh" + std::to_string(a + 1));
    loops->lane[a] = F[a].id();
    loops->lane[a + 3] = N[a].id();
    loops->moved_lane[a] = Fm[a].id();
    loops->moved_lane[a + 3] = Nm[a].id();
  }
  for (auto t = loops->lane_joint.rbegin(); t != loops->lane_joint.rend(); ++t) {
    const int k = *t, parent = m_.joints[k].parent;
    if (parent < 0) continue;
    MassLoops::Sweep sweep{k, parent, position[k], position[k] + size[k]};
    const V3 f = rotate(k, F), moment = rotate(k, N) + cross(offset_[k], Fm);
    for (int a = 0; a < 3; ++a) {
      sweep.moved[a] = f[a].id();
      sweep.moved[a + 3] = moment[a].id();
    }
    sweep.entry = mass_entry(parent, Fm, Nm).id();
    loops->sweeps.push_back(sweep);
  }

  // What the sweeps read besides the placeholders and the function's arrays: auxiliaries
  // (an arbitrary axis's rotation, an offset along a prismatic joint) and sin/cos.
  // Listed in the order met, the sweeps' roots walked last first (a sweep's entry before its moved).
  std::vector<char> placeholder(ctx_->size(), 0);
  for (int a = 0; a < 6; ++a) placeholder[loops->lane[a]] = placeholder[loops->moved_lane[a]] = 1;
  symbolic::DagWalk walk(*ctx_);
  auto read = [&](NodeId x) {
    if (placeholder[x]) return false;
    if (!ctx_->is_abbreviation(x) && !ctx_->is_symbol(x, SymbolKind::Aux)) return true;
    loops->reads.push_back(x);
    o.push_back({"read " + std::to_string(loops->reads.size() - 1), x});
    return false;
  };
  for (auto sweep = loops->sweeps.rbegin(); sweep != loops->sweeps.rend(); ++sweep) {
    walk.walk(sweep->entry, read);
    for (auto m = sweep->moved.rbegin(); m != sweep->moved.rend(); ++m) walk.walk(*m, read);
  }
  loops->start = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, std::move(o))));
  return loops;
}

}  // namespace dydp::mbs::detail
