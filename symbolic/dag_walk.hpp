// Depth-first walks over the expression DAG of a Context, for the passes that mark, count, collect
// or rebuild the nodes that some roots (right-hand sides, outputs) read: the seen-and-stack loop
// they would each write out, with no recursion, so that deep expressions cannot overflow the
// call stack.
//  - DagWalk: each node reachable from the roots once, over all the roots walked with it, in
//    pre-order; a callback stops the descent at a node (an atom, an auxiliary, an abbreviation).
//  - walk_post_order: each node not done yet after its children, for a pass that builds a node's
//    image from its children's (a topological order), the pass's own memo telling what is done.
// Both take a node's children last first: the order a stack gives them, on which the callers
// whose result depends on the order (the nodes collected, the nodes built) rely.
#pragma once

#include "symbolic/expr.hpp"

#include <cstdint>
#include <vector>

namespace dydp::symbolic {

// Pre-order walk from any number of roots, each node visited once over all of them until
// restart(). The walks must not reach a node built after the DagWalk was (its seen-set has one
// entry per node the context had then).
class DagWalk {
 public:
  explicit DagWalk(const Context& ctx) : ctx_(ctx), stamp_(ctx.size(), 0) {}

  // Visits the nodes reachable from `root` that no walk since the last restart visited: visit(n)
  // is called once per node, and returns whether to go on into n's children.
  template <typename Visit>
  void walk(NodeId root, Visit&& visit) {
    stack_.push_back(root);
    while (!stack_.empty()) {
      const NodeId n = stack_.back();
      stack_.pop_back();
      if (stamp_[n] == current_) continue;
      stamp_[n] = current_;
      if (!visit(n)) continue;
      for (NodeId c : ctx_.children(n)) {
        if (stamp_[c] != current_) stack_.push_back(c);
      }
    }
  }

  // Whether a walk since the last restart has visited n.
  bool seen(NodeId n) const { return stamp_[n] == current_; }
  // Forgets the nodes visited, in constant time: the next walks visit them again.
  void restart() { ++current_; }

 private:
  const Context& ctx_;
  std::vector<std::uint32_t> stamp_;  // by node: the current_ of the last walk that visited it
  std::uint32_t current_ = 1;
  std::vector<NodeId> stack_;
};

// Post-order walk from `root`: emit(n) is called for each node reached with done(n) false, once
// done(c) holds for all its children, and must make done(n) true. The descent stops at the nodes
// done before (an earlier root's, an auxiliary given its definition); a leaf is emitted as soon as
// it is reached. emit may build nodes (no span of children is held across it); `stack` is
// scratch space, empty between calls, that the caller keeps to reuse.
template <typename Done, typename Emit>
void walk_post_order(const Context& ctx, NodeId root, std::vector<NodeId>& stack, Done&& done, Emit&& emit) {
  stack.push_back(root);
  while (!stack.empty()) {
    const NodeId n = stack.back();
    if (done(n)) {
      stack.pop_back();
      continue;
    }
    bool ready = true;
    for (NodeId c : ctx.children(n)) {
      if (!done(c)) {
        stack.push_back(c);
        ready = false;
      }
    }
    if (!ready) continue;
    stack.pop_back();
    emit(n);
  }
}

}  // namespace dydp::symbolic
