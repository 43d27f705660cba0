#include "gui/layered_layout.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace dydp::gui {
namespace {

constexpr double kLayerGap = 140;  // [px] between the widest block of a layer and the next layer
constexpr double kBlockGap = 40;   // [px] between blocks stacked in a layer
constexpr int kSweeps = 12;        // barycentre sweeps (down and up count as two)
constexpr int kPulls = 6;          // rounds pulling blocks towards their neighbours' ports

/// A connection between two blocks of the layout, with the ports' heights in their blocks.
struct Edge {
  int from, to;
  double from_y, to_y;  ///< port offset as a fraction of the block's height
  bool forward = true;  ///< false: a back edge of a cycle, not used for layering
};

/// Marks back edges by depth-first search from the blocks nothing drives, in document order,
/// then from any block left (a cycle with no source).
void break_cycles(int n, std::vector<Edge>& edges) {
  std::vector<std::vector<int>> out(n);
  std::vector<int> indegree(n, 0);
  for (size_t e = 0; e < edges.size(); ++e) {
    out[edges[e].from].push_back(static_cast<int>(e));
    ++indegree[edges[e].to];
  }
  enum { kNew, kOnStack, kDone };
  std::vector<int> state(n, kNew);
  const std::function<void(int)> visit = [&](int v) {
    state[v] = kOnStack;
    for (int e : out[v]) {
      const int w = edges[e].to;
      if (state[w] == kOnStack) edges[e].forward = false;
      else if (state[w] == kNew) visit(w);
    }
    state[v] = kDone;
  };
  for (int v = 0; v < n; ++v)
    if (indegree[v] == 0 && state[v] == kNew) visit(v);
  for (int v = 0; v < n; ++v)
    if (state[v] == kNew) visit(v);
}

/// Longest path from a source over the forward edges; objectives in a last layer of their own.
std::vector<int> assign_layers(const std::vector<LayoutBlock>& blocks, const std::vector<Edge>& edges) {
  const int n = static_cast<int>(blocks.size());
  std::vector<int> layer(n, 0);
  // The forward edges form a DAG: n rounds of relaxation reach the longest paths.
  for (int round = 0; round < n; ++round) {
    bool changed = false;
    for (const Edge& e : edges)
      if (e.forward && layer[e.to] < layer[e.from] + 1) {
        layer[e.to] = layer[e.from] + 1;
        changed = true;
      }
    if (!changed) break;
  }
  int last = -1;
  bool any_objective = false;
  for (int v = 0; v < n; ++v) {
    if (blocks[v].objective) any_objective = true;
    else last = std::max(last, layer[v]);
  }
  if (any_objective)
    for (int v = 0; v < n; ++v)
      if (blocks[v].objective) layer[v] = last + 1;
  return layer;
}

/// Crossings of the forward edges drawn as straight lines between (layer, position) points:
/// two edges cross where their height difference changes sign over the layers they share.
int count_crossings(const std::vector<Edge>& edges, const std::vector<int>& layer, const std::vector<double>& pos) {
  struct Line {
    double x0, y0, x1, y1;
    double at(double x) const { return y0 + (y1 - y0) * (x - x0) / (x1 - x0); }
  };
  std::vector<Line> lines;
  for (const Edge& e : edges)
    if (e.forward && layer[e.to] > layer[e.from])
      lines.push_back({double(layer[e.from]), pos[e.from] + e.from_y, double(layer[e.to]), pos[e.to] + e.to_y});
  int crossings = 0;
  for (size_t i = 0; i < lines.size(); ++i)
    for (size_t j = i + 1; j < lines.size(); ++j) {
      const double a = std::max(lines[i].x0, lines[j].x0), b = std::min(lines[i].x1, lines[j].x1);
      if (!(b > a)) continue;
      const double da = lines[i].at(a) - lines[j].at(a), db = lines[i].at(b) - lines[j].at(b);
      if (da * db < 0) ++crossings;
    }
  return crossings;
}

/// Rank of each block within its layer (its position in `order[layer]`).
std::vector<double> ranks(const std::vector<std::vector<int>>& order, int n) {
  std::vector<double> pos(n, 0);
  for (const auto& blocks : order)
    for (size_t k = 0; k < blocks.size(); ++k) pos[blocks[k]] = static_cast<double>(k);
  return pos;
}

/// Orders the blocks of every layer by barycentre sweeps; returns the order with fewest crossings.
std::vector<std::vector<int>> order_layers(int n, const std::vector<Edge>& edges, const std::vector<int>& layer) {
  const int layers = n == 0 ? 0 : *std::max_element(layer.begin(), layer.end()) + 1;
  std::vector<std::vector<int>> order(layers);
  for (int v = 0; v < n; ++v) order[layer[v]].push_back(v);
  auto best = order;
  int best_crossings = count_crossings(edges, layer, ranks(order, n));
  for (int sweep = 0; sweep < kSweeps && best_crossings > 0; ++sweep) {
    const bool down = sweep % 2 == 0;
    for (int step = 0; step < layers; ++step) {
      const int l = down ? step : layers - 1 - step;
      const std::vector<double> pos = ranks(order, n);
      // A block's barycentre: the mean height of the ports it is wired to on the side swept
      // from (every edge, back edges too, so a corner lines up with the car port it drives).
      std::vector<std::pair<double, int>> keyed;
      for (int v : order[l]) {
        double sum = 0;
        int count = 0;
        for (const Edge& e : edges) {
          const int other = e.to == v ? e.from : e.from == v ? e.to : -1;
          if (other < 0 || other == v) continue;
          if (down ? layer[other] >= l : layer[other] <= l) continue;
          sum += pos[other] + (e.to == v ? e.from_y : e.to_y);
          ++count;
        }
        keyed.emplace_back(count ? sum / count : pos[v] + 0.5, v);
      }
      std::stable_sort(keyed.begin(), keyed.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      for (size_t k = 0; k < keyed.size(); ++k) order[l][k] = keyed[k].second;
    }
    const int crossings = count_crossings(edges, layer, ranks(order, n));
    if (crossings < best_crossings) {
      best_crossings = crossings;
      best = order;
    }
  }
  return best;
}

/// Places the blocks of one layer at heights as near `want` as their order and the gaps allow.
void stack(const std::vector<int>& blocks, const std::vector<LayoutBlock>& info, const std::vector<double>& want,
           std::vector<double>& y) {
  double next = -std::numeric_limits<double>::infinity();
  for (int v : blocks) {
    y[v] = std::max(want[v], next);
    next = y[v] + info[v].height + kBlockGap;
  }
  double limit = std::numeric_limits<double>::infinity();
  for (auto it = blocks.rbegin(); it != blocks.rend(); ++it) {
    y[*it] = std::min(y[*it], limit - info[*it].height);
    limit = y[*it] - kBlockGap;
  }
}

}  // namespace

std::map<std::string, LayoutPosition> layered_layout(const std::vector<LayoutBlock>& blocks,
                                                     const std::vector<DocConnection>& connections, double origin) {
  const int n = static_cast<int>(blocks.size());
  std::map<std::string, int> index;
  for (int v = 0; v < n; ++v) index[blocks[v].name] = v;
  std::vector<Edge> edges;
  for (const DocConnection& c : connections) {
    const auto f = index.find(c.from.block), t = index.find(c.to.block);
    if (f == index.end() || t == index.end() || f->second == t->second) continue;
    const LayoutBlock &bf = blocks[f->second], &bt = blocks[t->second];
    const auto fy = bf.output_y.find(c.from.port), ty = bt.input_y.find(c.to.port);
    edges.push_back({f->second, t->second, (fy == bf.output_y.end() ? bf.height / 2 : fy->second) / bf.height,
                     (ty == bt.input_y.end() ? bt.height / 2 : ty->second) / bt.height});
  }
  break_cycles(n, edges);
  const std::vector<int> layer = assign_layers(blocks, edges);
  const std::vector<std::vector<int>> order = order_layers(n, edges, layer);

  // Columns: each as wide as its widest block.
  std::vector<double> column_x(order.size(), origin);
  for (size_t l = 1; l < order.size(); ++l) {
    double widest = 0;
    for (int v : order[l - 1]) widest = std::max(widest, blocks[v].width);
    column_x[l] = column_x[l - 1] + widest + kLayerGap;
  }
  // Heights: first stacked and centred on the tallest column, then pulled towards the ports
  // each block is wired to, the order in the layer and the gaps kept.
  std::vector<double> y(n, 0), want(n, 0);
  double tallest = 0;
  for (const auto& column : order) {
    double h = 0;
    for (int v : column) h += blocks[v].height + kBlockGap;
    tallest = std::max(tallest, h);
  }
  for (const auto& column : order) {
    double h = 0;
    for (int v : column) h += blocks[v].height + kBlockGap;
    double at = (tallest - h) / 2;
    for (int v : column) {
      y[v] = at;
      at += blocks[v].height + kBlockGap;
    }
  }
  for (int round = 0; round < kPulls; ++round) {
    for (size_t l = 0; l < order.size(); ++l) {
      for (int v : order[l]) {
        // The block's port wired to each neighbour level with that neighbour's port.
        double sum = 0;
        int count = 0;
        for (const Edge& e : edges) {
          if (e.to == v && e.from != v) sum += y[e.from] + e.from_y * blocks[e.from].height - e.to_y * blocks[v].height;
          else if (e.from == v && e.to != v) sum += y[e.to] + e.to_y * blocks[e.to].height - e.from_y * blocks[v].height;
          else continue;
          ++count;
        }
        want[v] = count ? sum / count : y[v];
      }
      stack(order[l], blocks, want, y);
    }
  }
  double top = std::numeric_limits<double>::infinity();
  for (int v = 0; v < n; ++v) top = std::min(top, y[v]);
  std::map<std::string, LayoutPosition> out;
  for (int v = 0; v < n; ++v)
    out[blocks[v].name] = {std::round(column_x[layer[v]]), std::round(y[v] - top + origin), layer[v]};
  return out;
}

}  // namespace dydp::gui
