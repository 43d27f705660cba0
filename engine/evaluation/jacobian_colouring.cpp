// The structurally coloured Jacobian (see jacobian_colouring.hpp).
#include "engine/evaluation/jacobian_colouring.hpp"

#include <algorithm>
#include <map>

namespace dydp::engine {

JacobianColouring::JacobianColouring(const Diagram& d) : nx_(d.num_states), nq_(d.num_quadratures) {
  const int nodes = static_cast<int>(d.nodes.size());
  // The output port behind each signal offset, and the inputs each output port feeds.
  std::map<int, std::pair<int, int>> port_at;  // first offset of an output -> (node, port)
  for (int i = 0; i < nodes; ++i)
    for (int k = 0; k < static_cast<int>(d.nodes[i].output_offset.size()); ++k) port_at[d.nodes[i].output_offset[k]] = {i, k};
  std::vector<std::vector<std::vector<std::pair<int, int>>>> feeds(nodes);  // [node][port] -> (node, input)
  for (int i = 0; i < nodes; ++i) feeds[i].resize(d.nodes[i].output_offset.size());
  for (int c = 0; c < nodes; ++c)
    for (int k = 0; k < static_cast<int>(d.nodes[c].input_source.size()); ++k) {
      auto it = port_at.upper_bound(d.nodes[c].input_source[k]);
      if (it == port_at.begin()) continue;
      --it;
      feeds[it->second.first][it->second.second].push_back({c, k});
    }

  // The rows each node's states reach (all of a node's states reach the same ones).
  std::vector<std::vector<int>> node_rows(nodes);
  for (int start = 0; start < nodes; ++start) {
    if (d.nodes[start].block->num_states() == 0) continue;
    std::vector<char> node_reached(nodes, 0);
    std::vector<std::vector<char>> port_reached(nodes);
    for (int i = 0; i < nodes; ++i) port_reached[i].assign(d.nodes[i].output_offset.size(), 0);
    std::vector<std::pair<int, int>> pending;
    node_reached[start] = 1;
    for (int k = 0; k < static_cast<int>(port_reached[start].size()); ++k) pending.push_back({start, k});
    while (!pending.empty()) {
      const auto [i, k] = pending.back();
      pending.pop_back();
      if (port_reached[i][k]) continue;
      port_reached[i][k] = 1;
      for (const auto& [c, input] : feeds[i][k]) {
        node_reached[c] = 1;
        const Block& b = *d.nodes[c].block;
        for (int out = 0; out < static_cast<int>(b.outputs().size()); ++out) {
          const std::vector<int> reads = b.output_reads(out);
          if (std::binary_search(reads.begin(), reads.end(), input)) pending.push_back({c, out});
        }
      }
    }
    std::vector<int>& rows = node_rows[start];
    for (int i = 0; i < nodes; ++i) {
      if (!node_reached[i]) continue;
      const Node& n = d.nodes[i];
      for (int s = 0; s < n.block->num_states(); ++s) rows.push_back(n.state_offset + s);
    }
    for (int i = 0; i < nodes; ++i) {
      if (!node_reached[i]) continue;
      const Node& n = d.nodes[i];
      for (int s = 0; s < n.block->num_quadratures(); ++s) rows.push_back(nx_ + n.quad_offset + s);
    }
    std::sort(rows.begin(), rows.end());
  }

  // Greedy colouring in state order: a column takes the first colour none of whose rows it has.
  rows_.resize(nx_);
  colour_.assign(nx_, 0);
  std::vector<std::vector<char>> used;  // [colour][row]
  for (int i = 0; i < nodes; ++i) {
    const Node& n = d.nodes[i];
    for (int s = 0; s < n.block->num_states(); ++s) {
      const int column = n.state_offset + s;
      rows_[column] = node_rows[i];
      int c = 0;
      for (; c < static_cast<int>(used.size()); ++c) {
        bool free = true;
        for (int r : rows_[column]) free = free && !used[c][r];
        if (free) break;
      }
      if (c == static_cast<int>(used.size())) used.emplace_back(nx_ + nq_, 0);
      for (int r : rows_[column]) used[c][r] = 1;
      colour_[column] = c;
    }
  }
  colours_ = static_cast<int>(used.size());
  if (colours_ == nx_)
    for (int j = 0; j < nx_; ++j) colour_[j] = j;  // the identity: one column per pass direction
  seeds_.assign(static_cast<std::size_t>(nx_) * colours_, 0.0);
  for (int j = 0; j < nx_; ++j) seeds_[static_cast<std::size_t>(colour_[j]) * nx_ + j] = 1.0;
}

bool JacobianColouring::reaches(int column, int row) const {
  return std::binary_search(rows_[column].begin(), rows_[column].end(), row);
}

void JacobianColouring::evaluate(Evaluator& ev, double t, const double* x, DirView J, DirView JQ) {
  if (nx_ == 0) return;
  if (colours_ == nx_) {
    ev.tangents(t, x, nx_, {seeds_.data(), nx_}, false, J, JQ);
    return;
  }
  compressed_x_.resize(static_cast<std::size_t>(nx_) * colours_);
  const bool quads = JQ.data && nq_ > 0;
  compressed_q_.resize(quads ? static_cast<std::size_t>(nq_) * colours_ : 0);
  ev.tangents(t, x, colours_, {seeds_.data(), nx_}, false, {compressed_x_.data(), nx_},
              {quads ? compressed_q_.data() : nullptr, nq_});
  for (int j = 0; j < nx_; ++j) {
    for (int r = 0; r < nx_; ++r) J(r, j) = 0.0;
    if (quads)
      for (int r = 0; r < nq_; ++r) JQ(r, j) = 0.0;
    const std::size_t c = static_cast<std::size_t>(colour_[j]);
    for (int r : rows_[j]) {
      if (r < nx_) J(r, j) = compressed_x_[c * nx_ + r];
      else if (quads) JQ(r - nx_, j) = compressed_q_[c * nq_ + (r - nx_)];
    }
  }
}

}  // namespace dydp::engine
