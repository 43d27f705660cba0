#include "engine/graph_builder.hpp"

#include <algorithm>
#include <functional>
#include <queue>

#include "engine/errors.hpp"

namespace dydp::engine {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

void GraphBuilder::add_block(Node node) {
  index_[node.name] = static_cast<int>(nodes_.size());
  nodes_.push_back(std::move(node));
}

GraphBuilder::PortRef GraphBuilder::resolve(const std::string& text, bool input, int line) const {
  const auto dot = text.find('.');
  const std::string block = text.substr(0, dot);
  auto it = index_.find(block);
  if (it == index_.end()) throw InputError(file_, line, text, "unknown block '" + block + "'");
  PortRef ref{it->second, -1};
  if (dot == std::string::npos) return ref;
  const std::string port = text.substr(dot + 1);
  const Block& b = *nodes_[ref.node].block;
  const auto& ports = input ? b.inputs() : b.outputs();
  for (size_t k = 0; k < ports.size(); ++k)
    if (ports[k].name == port) ref.port = static_cast<int>(k);
  if (ref.port < 0) {
    std::string known;
    for (const auto& p : ports) known += " " + p.name;
    throw InputError(file_, line, text,
                     std::string("block '") + block + "' has no " + (input ? "input" : "output") +
                         " port '" + port + "' (" + (input ? "inputs" : "outputs") + ":" +
                         (known.empty() ? " none" : known) + ")");
  }
  return ref;
}

void GraphBuilder::connect(const std::string& text, int line) {
  const auto arrow = text.find("->");
  if (arrow == std::string::npos)
    throw InputError(file_, line, "connections", "expected 'block.port -> block.port', got '" + text + "'");
  const std::string from = trim(text.substr(0, arrow)), to = trim(text.substr(arrow + 2));
  if (from.find('.') == std::string::npos || to.find('.') == std::string::npos)
    throw InputError(file_, line, "connections", "both ends need block.port, got '" + text + "'");
  Edge e{resolve(from, false, line), resolve(to, true, line), line};
  const int w_src = nodes_[e.src.node].block->outputs()[e.src.port].width;
  const int w_dst = nodes_[e.dst.node].block->inputs()[e.dst.port].width;
  if (w_src != w_dst)
    throw InputError(file_, line, to,
                     "width mismatch: " + from + " has width " + std::to_string(w_src) + ", " + to +
                         " expects " + std::to_string(w_dst));
  for (const Edge& other : edges_)
    if (other.dst.node == e.dst.node && other.dst.port == e.dst.port)
      throw InputError(file_, line, to,
                       "input driven twice (also connected at line " + std::to_string(other.line) + ")");
  edges_.push_back(e);
}

void GraphBuilder::request_output(const std::string& text, int line) {
  requested_.emplace_back(resolve(trim(text), false, line), line);
}

bool GraphBuilder::has_feedthrough_output(int node) const {
  const auto& outs = nodes_[node].block->outputs();
  return std::any_of(outs.begin(), outs.end(), [](const PortDecl& p) { return p.feedthrough; });
}

std::vector<int> GraphBuilder::order_or_report_loop(const std::vector<bool>& keep) const {
  // Kahn's algorithm over the blocks' feedthrough outputs: block t waits for block s when an
  // output of s that reads inputs drives an input of t that some output of t reads. Outputs
  // that read states only are computed first, in a pass of their own. Ties keep scene order.
  const int n = static_cast<int>(nodes_.size());
  std::vector<bool> late(n, false);
  for (int i = 0; i < n; ++i) late[i] = keep[i] && has_feedthrough_output(i);
  std::vector<int> indegree(n, 0);
  std::vector<std::vector<int>> next(n);
  for (const Edge& e : edges_) {
    if (!late[e.src.node] || !late[e.dst.node]) continue;
    if (!nodes_[e.src.node].block->outputs()[e.src.port].feedthrough) continue;
    if (!nodes_[e.dst.node].block->inputs()[e.dst.port].feedthrough) continue;
    next[e.src.node].push_back(e.dst.node);
    ++indegree[e.dst.node];
  }
  std::priority_queue<int, std::vector<int>, std::greater<int>> ready;
  for (int i = 0; i < n; ++i)
    if (late[i] && indegree[i] == 0) ready.push(i);
  std::vector<int> order;
  while (!ready.empty()) {
    const int i = ready.top();
    ready.pop();
    order.push_back(i);
    for (int j : next[i])
      if (--indegree[j] == 0) ready.push(j);
  }
  const int count = static_cast<int>(std::count(late.begin(), late.end(), true));
  if (static_cast<int>(order.size()) == count) return order;

  // Some blocks remain, each with a remaining predecessor: walk predecessors until one repeats.
  std::vector<std::vector<int>> prev(n);
  for (int i = 0; i < n; ++i)
    for (int j : next[i]) prev[j].push_back(i);
  int at = -1;
  for (int i = 0; i < n && at < 0; ++i)
    if (late[i] && indegree[i] > 0) at = i;
  std::vector<int> path;
  std::vector<int> pos(n, -1);
  while (pos[at] < 0) {
    pos[at] = static_cast<int>(path.size());
    path.push_back(at);
    for (int j : prev[at])
      if (indegree[j] > 0) { at = j; break; }
  }
  std::vector<int> cycle(path.begin() + pos[at], path.end());
  std::reverse(cycle.begin(), cycle.end());  // now in signal-flow order
  std::string names;
  int line = 0;
  for (size_t k = 0; k < cycle.size(); ++k) {
    names += nodes_[cycle[k]].name + " -> ";
    const int to = cycle[(k + 1) % cycle.size()];
    for (const Edge& e : edges_)
      if (e.src.node == cycle[k] && e.dst.node == to && (line == 0 || e.line < line)) line = e.line;
  }
  names += nodes_[cycle.front()].name;
  throw InputError(file_, line, "connections",
                   "algebraic loop (a cycle through direct feedthrough, no state to break it): " + names);
}

void GraphBuilder::build(Diagram& d) {
  const int n = static_cast<int>(nodes_.size());
  // Every input of every block must be driven, whether or not the block is kept.
  for (int i = 0; i < n; ++i) {
    const auto& inputs = nodes_[i].block->inputs();
    for (size_t k = 0; k < inputs.size(); ++k) {
      const bool driven = std::any_of(edges_.begin(), edges_.end(), [&](const Edge& e) {
        return e.dst.node == i && e.dst.port == static_cast<int>(k);
      });
      if (!driven)
        throw InputError(file_, nodes_[i].line, nodes_[i].name + "." + inputs[k].name,
                         "input is not connected");
    }
  }

  // Keep what the requested outputs need, following every connection backwards.
  std::vector<bool> keep(n, false);
  std::vector<int> stack;
  for (const auto& [ref, line] : requested_) stack.push_back(ref.node);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    if (keep[i]) continue;
    keep[i] = true;
    for (const Edge& e : edges_)
      if (e.dst.node == i) stack.push_back(e.src.node);
  }
  // Loops are errors even in pruned parts of the scene: check over all blocks first.
  order_or_report_loop(std::vector<bool>(n, true));
  const std::vector<int> second = order_or_report_loop(keep);

  for (int i = 0; i < n; ++i)
    if (!keep[i]) d.pruned.push_back(nodes_[i].name);

  // Lay out signals, states and quadratures in scene order.
  std::vector<int> new_index(n, -1);
  for (int i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    Node& node = nodes_[i];
    node.state_offset = d.num_states;
    d.num_states += node.block->num_states();
    node.quad_offset = d.num_quadratures;
    d.num_quadratures += node.block->num_quadratures();
    for (const PortDecl& port : node.block->outputs()) {
      node.output_offset.push_back(d.num_signals);
      d.num_signals += port.width;
    }
    node.input_source.assign(node.block->inputs().size(), -1);
    new_index[i] = static_cast<int>(d.nodes.size());
    const auto& outs = node.block->outputs();
    if (std::any_of(outs.begin(), outs.end(), [](const PortDecl& p) { return !p.feedthrough; }))
      d.first_pass.push_back(new_index[i]);
    d.nodes.push_back(std::move(node));
  }
  for (int i : second) d.second_pass.push_back(new_index[i]);
  for (const Edge& e : edges_) {
    if (new_index[e.dst.node] < 0) continue;
    Node& dst = d.nodes[new_index[e.dst.node]];
    dst.input_source[e.dst.port] = d.nodes[new_index[e.src.node]].output_offset[e.src.port];
  }

  for (const auto& [ref, line] : requested_) {
    const Node& node = d.nodes[new_index[ref.node]];
    if (ref.port < 0 && node.objective) {
      d.objectives.push_back(new_index[ref.node]);
      continue;
    }
    const auto& ports = node.block->outputs();
    for (size_t k = 0; k < ports.size(); ++k) {
      if (ref.port >= 0 && ref.port != static_cast<int>(k)) continue;
      const std::string base = node.name + "." + ports[k].name;
      for (int c = 0; c < ports[k].width; ++c)
        d.logged.push_back({ports[k].width == 1 ? base : base + "[" + std::to_string(c) + "]",
                            node.output_offset[k] + c});
    }
  }
  nodes_.clear();
}

}  // namespace dydp::engine

