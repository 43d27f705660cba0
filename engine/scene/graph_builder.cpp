#include "engine/scene/graph_builder.hpp"

#include <algorithm>
#include <functional>
#include <queue>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
void GraphBuilder::add_block(Node node) {
  index_[node.name] = static_cast<int>(nodes_.size());
  nodes_.push_back(std::move(node));
}

GraphBuilder::PortRef GraphBuilder::resolve(const std::string& block, const std::string& port,
                                            bool input, int line, const std::string& file) const {
  const std::string text = port.empty() ? block : block + "." + port;
  auto it = index_.find(block);
  if (it == index_.end()) throw InputError(file_or_scene(file), line, text, "unknown block '" + block + "'");
  PortRef ref{it->second, -1};
  if (port.empty()) return ref;
  const Block& b = *nodes_[ref.node].block;
  const auto& ports = input ? b.inputs() : b.outputs();
  for (size_t k = 0; k < ports.size(); ++k)
    if (ports[k].name == port) ref.port = static_cast<int>(k);
  if (ref.port < 0) {
    std::string known;
    for (const auto& p : ports) known += " " + p.name;
    throw InputError(file_or_scene(file), line, text,
                     std::string("block '") + block + "' has no " + (input ? "input" : "output") +
                         " port '" + port + "' (" + (input ? "inputs" : "outputs") + ":" +
                         (known.empty() ? " none" : known) + ")");
  }
  return ref;
}

void GraphBuilder::check_port(const std::string& block, const std::string& port, bool input,
                              int line, const std::string& file) const {
  resolve(block, port, input, line, file);
}

void GraphBuilder::connect(const std::string& src_block, const std::string& src_port,
                           const std::string& dst_block, const std::string& dst_port, int line,
                           const std::string& file) {
  const std::string from = src_block + "." + src_port, to = dst_block + "." + dst_port;
  // resolve() takes an empty port for the whole block (an output request): a wire needs two ports.
  if (src_port.empty() || dst_port.empty())
    throw InputError(file_or_scene(file), line, "connections", "both ends need block.port, got '" + from + " -> " + to + "'");
  Edge e{resolve(src_block, src_port, false, line, file), resolve(dst_block, dst_port, true, line, file),
         line, file_or_scene(file)};
  const int w_src = nodes_[e.src.node].block->outputs()[e.src.port].width;
  const int w_dst = nodes_[e.dst.node].block->inputs()[e.dst.port].width;
  if (w_src != w_dst)
    throw InputError(e.file, line, to,
                     "width mismatch: " + from + " has width " + std::to_string(w_src) + ", " + to +
                         " expects " + std::to_string(w_dst));
  for (const Edge& other : edges_)
    if (other.dst.node == e.dst.node && other.dst.port == e.dst.port)
      throw InputError(e.file, line, to,
                       "input driven twice (also connected at " +
                           (other.file == e.file ? "line " : other.file + ":") + std::to_string(other.line) + ")");
  edges_.push_back(std::move(e));
}

void GraphBuilder::request_output(const std::string& block, const std::string& port, int line,
                                  const std::string& file, const std::string& shown_as) {
  requested_.push_back({resolve(block, port, false, line, file), line, shown_as});
}

std::vector<OutputStep> GraphBuilder::schedule_or_report_loop(const std::vector<bool>& keep) const {
  // One step per group of a block's outputs that read the same inputs; step t waits for step s
  // when an output of s drives an input that the outputs of t read. Kahn's algorithm orders the
  // steps; ties go to the state-only steps first (they wait for nothing), then scene order.
  const int n = static_cast<int>(nodes_.size());
  std::vector<OutputStep> steps;
  std::vector<std::vector<int>> step_of_output(n), steps_of_node(n);
  std::vector<std::vector<int>> reads_any(n);  ///< inputs some output of the node reads
  for (int state_only = 1; state_only >= 0; --state_only)
    for (int i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      const Block& b = *nodes_[i].block;
      const int no = static_cast<int>(b.outputs().size());
      if (state_only) step_of_output[i].assign(no, -1);
      std::vector<std::vector<int>> groups;
      for (int k = 0; k < no; ++k) {
        std::vector<int> reads = b.output_reads(k);
        if (state_only) reads_any[i].insert(reads_any[i].end(), reads.begin(), reads.end());
        if (reads.empty() == (state_only == 1) && std::find(groups.begin(), groups.end(), reads) == groups.end())
          groups.push_back(std::move(reads));
      }
      // fewer inputs first: a group read by a subset tends to be ready sooner
      std::stable_sort(groups.begin(), groups.end(),
                       [](const auto& l, const auto& r) { return l.size() < r.size(); });
      for (auto& reads : groups) {
        OutputStep step;
        step.node = i;
        for (int k = 0; k < no; ++k)
          if (b.output_reads(k) == reads) {
            step.outputs.push_back(k);
            step_of_output[i][k] = static_cast<int>(steps.size());
          }
        step.reads = std::move(reads);
        steps_of_node[i].push_back(static_cast<int>(steps.size()));
        steps.push_back(std::move(step));
      }
    }

  const int ns = static_cast<int>(steps.size());
  std::vector<int> indegree(ns, 0);
  std::vector<std::vector<std::pair<int, int>>> next(ns);  // (step, index of the connection)
  for (size_t ei = 0; ei < edges_.size(); ++ei) {
    const Edge& e = edges_[ei];
    if (!keep[e.src.node] || !keep[e.dst.node]) continue;
    const int from = step_of_output[e.src.node][e.src.port];
    for (int to : steps_of_node[e.dst.node]) {
      const auto& reads = steps[to].reads;
      if (!std::binary_search(reads.begin(), reads.end(), e.dst.port)) continue;
      next[from].emplace_back(to, static_cast<int>(ei));
      ++indegree[to];
    }
  }
  std::priority_queue<int, std::vector<int>, std::greater<int>> ready;
  for (int s = 0; s < ns; ++s)
    if (indegree[s] == 0) ready.push(s);
  std::vector<int> order;
  while (!ready.empty()) {
    const int s = ready.top();
    ready.pop();
    order.push_back(s);
    for (const auto& [t, edge] : next[s])
      if (--indegree[t] == 0) ready.push(t);
  }
  if (static_cast<int>(order.size()) == ns) {
    // The inputs ready at each step: those its block's earlier steps and itself read.
    std::vector<OutputStep> ordered;
    std::vector<std::vector<unsigned char>> mask(n);
    for (int s : order) {
      OutputStep& step = steps[s];
      auto& m = mask[step.node];
      m.resize(nodes_[step.node].block->inputs().size(), 0);
      for (int k : step.reads) m[k] = 1;
      step.ready = m;
      step.inputs_ready = std::all_of(reads_any[step.node].begin(), reads_any[step.node].end(),
                                      [&](int k) { return m[k] != 0; });
      ordered.push_back(std::move(step));
    }
    return ordered;
  }

  // Some steps remain, each with a remaining predecessor: walk predecessors until one repeats.
  std::vector<std::vector<std::pair<int, int>>> prev(ns);
  for (int s = 0; s < ns; ++s)
    for (const auto& [t, edge] : next[s]) prev[t].emplace_back(s, edge);
  int at = -1;
  for (int s = 0; s < ns && at < 0; ++s)
    if (indegree[s] > 0) at = s;
  std::vector<int> path;
  std::vector<int> pos(ns, -1);
  while (pos[at] < 0) {
    pos[at] = static_cast<int>(path.size());
    path.push_back(at);
    for (const auto& [s, edge] : prev[at])
      if (indegree[s] > 0) { at = s; break; }
  }
  std::vector<int> cycle(path.begin() + pos[at], path.end());
  std::reverse(cycle.begin(), cycle.end());  // now in signal-flow order
  // Named at the first connection of the loop as written (the scene's own file first).
  std::string names;
  const Edge* at_edge = nullptr;
  const auto earlier = [&](const Edge& a, const Edge& b) {
    if ((a.file == file_) != (b.file == file_)) return a.file == file_;
    return a.file != b.file ? a.file < b.file : a.line < b.line;
  };
  for (size_t k = 0; k < cycle.size(); ++k) {
    names += nodes_[steps[cycle[k]].node].name + " -> ";
    const int to = cycle[(k + 1) % cycle.size()];
    for (const auto& [t, edge] : next[cycle[k]])
      if (t == to && (!at_edge || earlier(edges_[edge], *at_edge))) at_edge = &edges_[edge];
  }
  names += nodes_[steps[cycle.front()].node].name;
  throw InputError(at_edge ? at_edge->file : file_, at_edge ? at_edge->line : 0, "connections",
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
        throw InputError(file_or_scene(nodes_[i].file), nodes_[i].line, nodes_[i].name + "." + inputs[k].name,
                         "input is not connected");
    }
  }

  // Keep what the requested outputs need, following every connection backwards.
  std::vector<bool> keep(n, false);
  std::vector<int> stack;
  for (const Request& r : requested_) stack.push_back(r.ref.node);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    if (keep[i]) continue;
    keep[i] = true;
    for (const Edge& e : edges_)
      if (e.dst.node == i) stack.push_back(e.src.node);
  }
  // Loops are errors even in pruned parts of the scene: check over all blocks first.
  schedule_or_report_loop(std::vector<bool>(n, true));
  std::vector<OutputStep> steps = schedule_or_report_loop(keep);

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
    d.nodes.push_back(std::move(node));
  }
  for (OutputStep& step : steps) {
    step.node = new_index[step.node];
    d.output_steps.push_back(std::move(step));
  }
  for (const Edge& e : edges_) {
    if (new_index[e.dst.node] < 0) continue;
    Node& dst = d.nodes[new_index[e.dst.node]];
    dst.input_source[e.dst.port] = d.nodes[new_index[e.src.node]].output_offset[e.src.port];
  }

  for (const auto& [ref, line, shown_as] : requested_) {
    const Node& node = d.nodes[new_index[ref.node]];
    if (ref.port < 0 && node.objective) {
      d.objectives.push_back(new_index[ref.node]);
      continue;
    }
    const auto& ports = node.block->outputs();
    for (size_t k = 0; k < ports.size(); ++k) {
      if (ref.port >= 0 && ref.port != static_cast<int>(k)) continue;
      const std::string base = ref.port >= 0 && !shown_as.empty() ? shown_as : node.name + "." + ports[k].name;
      for (int c = 0; c < ports[k].width; ++c)
        d.logged.push_back({ports[k].width == 1 ? base : base + "[" + std::to_string(c) + "]",
                            node.output_offset[k] + c});
    }
  }
  nodes_.clear();
}

}  // namespace dydp::engine

