// Wires loaded blocks into a graph, checks it (ports, widths, unconnected or doubly driven
// inputs, algebraic loops), prunes what no requested output needs and orders the rest.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "engine/diagram.hpp"

namespace dydp::engine {

class GraphBuilder {
 public:
  explicit GraphBuilder(std::string file) : file_(std::move(file)) {}

  bool has_block(const std::string& name) const { return index_.count(name) != 0; }
  void add_block(Node node);
  const std::vector<Node>& blocks() const { return nodes_; }

  /// "src.port -> dst.port", written at `line`.
  void connect(const std::string& text, int line);
  /// "block.port" (log that signal) or "block" (an objective, or all outputs of the block).
  void request_output(const std::string& text, int line);

  /// Validates, prunes and orders into d (nodes, offsets, logged signals, objectives).
  void build(Diagram& d);

 private:
  struct PortRef {
    int node = -1;
    int port = -1;
  };
  struct Edge {
    PortRef src, dst;
    int line = 0;
  };
  PortRef resolve(const std::string& text, bool input, int line) const;
  /// The output steps of the kept blocks in evaluation order (node: index into nodes_); throws
  /// naming the blocks of an algebraic loop.
  std::vector<OutputStep> schedule_or_report_loop(const std::vector<bool>& keep) const;

  std::string file_;
  std::vector<Node> nodes_;
  std::map<std::string, int> index_;
  std::vector<Edge> edges_;
  std::vector<std::pair<PortRef, int>> requested_;   ///< port (or port -1: whole block), line
};

}  // namespace dydp::engine
