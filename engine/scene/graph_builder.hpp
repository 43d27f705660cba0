// Wires loaded blocks into a graph, checks it (ports, widths, unconnected or doubly driven
// inputs, algebraic loops), prunes what no requested output needs and orders the rest.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

class GraphBuilder {
 public:
  explicit GraphBuilder(std::string file) : file_(std::move(file)) {}

  bool has_block(const std::string& name) const { return index_.count(name) != 0; }
  /// Node::file empty: the scene's file.
  void add_block(Node node);
  const std::vector<Node>& blocks() const { return nodes_; }
  /// The blocks read so far, for binding sensitivity directions to their parameters.
  std::vector<Node>& blocks() { return nodes_; }

  /// A block's port by (flat) block name, written at file:line; throws InputError naming the
  /// known ports when there is none (`file` empty: the scene's file).
  void check_port(const std::string& block, const std::string& port, bool input, int line,
                  const std::string& file) const;

  /// src_block.src_port -> dst_block.dst_port, written at file:line.
  void connect(const std::string& src_block, const std::string& src_port, const std::string& dst_block,
               const std::string& dst_port, int line, const std::string& file);
  /// Log block.port (port empty: an objective, or all outputs of the block), written at
  /// file:line; `shown_as` (when not empty) names the logged signal instead of block.port
  /// (a subsystem's output port: `corner_fl.damper_force`).
  void request_output(const std::string& block, const std::string& port, int line,
                      const std::string& file, const std::string& shown_as = "");

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
    std::string file;
  };
  struct Request {
    PortRef ref;  ///< port -1: the whole block
    int line = 0;
    std::string shown_as;
  };
  PortRef resolve(const std::string& block, const std::string& port, bool input, int line,
                  const std::string& file) const;
  const std::string& file_or_scene(const std::string& file) const { return file.empty() ? file_ : file; }
  /// The output steps of the kept blocks in evaluation order (node: index into nodes_); throws
  /// naming the blocks of an algebraic loop.
  std::vector<OutputStep> schedule_or_report_loop(const std::vector<bool>& keep) const;

  std::string file_;
  std::vector<Node> nodes_;
  std::map<std::string, int> index_;
  std::vector<Edge> edges_;
  std::vector<Request> requested_;
};

}  // namespace dydp::engine
