// Block's default adjoints: the vector-Jacobian products w^T J of outputs, derivatives,
// quadratures and initial state from the block's own tangent. The local Jacobian J is built
// from unit seeds, one per wanted column (the block's states, the elements of its wanted and
// ready inputs, the caller's parameter columns), then its transpose is applied to the weights.
// Exact (the tangent is), and cheap for the small blocks of the library; a large block (the
// multibody adapter) pays one tangent direction per column.
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/local_adjoint.hpp"

namespace dydp::engine {

LocalJacobian local_jacobian(const Block& b, BlockFunction fn, const Eval& e, bool states,
                             const std::vector<bool>& inputs, int p_columns, ConstDirView p_seeds) {
  LocalJacobian J;
  const int nx = b.num_states();
  const auto& ports = b.inputs();
  const int nports = static_cast<int>(ports.size());
  const bool reads_inputs = fn != BlockFunction::initial_state;
  switch (fn) {
    case BlockFunction::outputs:
      for (const auto& port : b.outputs()) J.rows += port.width;
      break;
    case BlockFunction::derivatives:
    case BlockFunction::initial_state: J.rows = nx; break;
    case BlockFunction::quadratures: J.rows = b.num_quadratures(); break;
  }
  J.state_columns = reads_inputs && states ? nx : 0;
  J.input_first.assign(nports, -1);
  int nd = J.state_columns;
  if (reads_inputs)
    for (int k = 0; k < nports; ++k)
      if (k < static_cast<int>(inputs.size()) && inputs[k] && e.input_ready(k)) J.input_first[k] = nd, nd += ports[k].width;
  J.parameter_first = nd;
  const int np = p_seeds.ld;
  if (p_columns > 0 && np > 0 && !p_seeds.zero()) J.parameter_columns = p_columns;
  nd += J.parameter_columns;
  if (nd == 0 || J.rows == 0) return J;

  std::vector<double> sx(J.state_columns ? static_cast<size_t>(nx) * nd : 0, 0.0);
  for (int i = 0; i < J.state_columns; ++i) sx[static_cast<size_t>(i) * nx + i] = 1.0;
  std::vector<std::vector<double>> su(nports);
  std::vector<ConstDirView> su_view(nports);
  for (int k = 0; k < nports; ++k) {
    const int w = ports[k].width;
    su[k].assign(static_cast<size_t>(w) * nd, 0.0);
    if (J.input_first[k] >= 0)
      for (int i = 0; i < w; ++i) su[k][static_cast<size_t>(J.input_first[k] + i) * w + i] = 1.0;
    su_view[k] = {su[k].data(), w};
  }
  std::vector<double> sp(J.parameter_columns ? static_cast<size_t>(np) * nd : 0, 0.0);
  for (int c = 0; c < J.parameter_columns; ++c)
    for (int j = 0; j < np; ++j) sp[static_cast<size_t>(J.parameter_first + c) * np + j] = p_seeds(j, c);
  Seeds s;
  s.directions = nd;
  s.x = J.state_columns ? ConstDirView{sx.data(), nx} : ConstDirView{};
  s.u = su_view.data();
  s.p = J.parameter_columns ? ConstDirView{sp.data(), np} : ConstDirView{};

  J.values.assign(static_cast<size_t>(J.rows) * nd, 0.0);
  const int rows = J.rows;
  switch (fn) {
    case BlockFunction::outputs: {
      std::vector<DirView> dy(b.outputs().size());
      int offset = 0;
      for (size_t k = 0; k < dy.size(); ++k) dy[k] = {J.values.data() + offset, rows}, offset += b.outputs()[k].width;
      b.outputs_tangent(e, s, dy.data());
      break;
    }
    case BlockFunction::derivatives: b.derivatives_tangent(e, s, {J.values.data(), rows}); break;
    case BlockFunction::quadratures: b.quadratures_tangent(e, s, {J.values.data(), rows}); break;
    case BlockFunction::initial_state: b.initial_state_tangent(e, s, {J.values.data(), rows}); break;
  }
  return J;
}

void add_transpose_product(const Block& b, const LocalJacobian& J, const std::function<double(int, int)>& weight,
                           const Adjoint& a) {
  const int rows = J.rows, nd = J.columns();
  if (rows == 0 || nd == 0) return;
  const auto& ports = b.inputs();
  std::vector<double> wm(rows);
  // (w^T J)(c, m) = sum_r w(r, m) J(r, c), into the view its column belongs to
  for (int m = 0; m < a.directions; ++m) {
    bool any = false;
    for (int r = 0; r < rows; ++r) wm[r] = weight(r, m), any = any || wm[r] != 0.0;
    if (!any) continue;
    auto product = [&](int c) {
      const double* col = J.values.data() + static_cast<size_t>(c) * rows;
      double sum = 0.0;
      for (int r = 0; r < rows; ++r) sum += wm[r] * col[r];
      return sum;
    };
    if (a.x.data)
      for (int i = 0; i < J.state_columns; ++i) a.x(i, m) += product(i);
    if (a.u)
      for (size_t k = 0; k < ports.size(); ++k)
        if (J.input_first[k] >= 0 && a.u[k].data)
          for (int i = 0; i < ports[k].width; ++i) a.u[k](i, m) += product(J.input_first[k] + i);
    if (a.p.data)
      for (int c = 0; c < std::min(J.parameter_columns, a.p_columns); ++c) a.p(c, m) += product(J.parameter_first + c);
  }
}

std::function<double(int, int)> output_weights(const Block& b, const ConstDirView* w) {
  std::vector<int> port_of, element_of;
  for (size_t k = 0; k < b.outputs().size(); ++k)
    for (int i = 0; i < b.outputs()[k].width; ++i) port_of.push_back(static_cast<int>(k)), element_of.push_back(i);
  return [w, port_of = std::move(port_of), element_of = std::move(element_of)](int r, int m) {
    return w[port_of[r]](element_of[r], m);
  };
}

namespace {

std::vector<bool> wanted_inputs(const Block& b, const Adjoint& a) {
  std::vector<bool> wanted(b.inputs().size(), false);
  if (a.u)
    for (size_t k = 0; k < wanted.size(); ++k) wanted[k] = a.u[k].data != nullptr;
  return wanted;
}

void default_adjoint(const Block& b, BlockFunction fn, const Eval& e, const std::function<double(int, int)>& weight,
                     const Adjoint& a) {
  if (a.directions == 0) return;
  const LocalJacobian J = local_jacobian(b, fn, e, a.x.data != nullptr, wanted_inputs(b, a),
                                         a.p.data ? a.p_columns : 0, a.p_seeds);
  add_transpose_product(b, J, weight, a);
}

}  // namespace

void Block::outputs_adjoint(const Eval& e, const ConstDirView* w, const Adjoint& a) const {
  bool any = false;
  for (size_t k = 0; k < outputs_.size(); ++k) any = any || w[k].data;
  if (!any) return;
  default_adjoint(*this, BlockFunction::outputs, e, output_weights(*this, w), a);
}

void Block::derivatives_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const {
  if (w.zero()) return;
  default_adjoint(*this, BlockFunction::derivatives, e, [&](int r, int m) { return w(r, m); }, a);
}

void Block::quadratures_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const {
  if (w.zero()) return;
  default_adjoint(*this, BlockFunction::quadratures, e, [&](int r, int m) { return w(r, m); }, a);
}

void Block::initial_state_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const {
  if (w.zero()) return;
  default_adjoint(*this, BlockFunction::initial_state, e, [&](int r, int m) { return w(r, m); }, a);
}

}  // namespace dydp::engine
