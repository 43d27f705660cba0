// Expands a scene into flat blocks: each instance of a subsystem (`type: subsystem.NAME`) becomes
// its blocks with prefixed names (`corner_fl.damper`), its ports become the internal ports they
// stand for, and every message names the file and line where the problem is written.
#pragma once

#include <yaml-cpp/yaml.h>

#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "engine/scene/block_reader.hpp"
#include "engine/scene/graph_builder.hpp"
#include "engine/scene/subsystem_definition.hpp"

namespace dydp::engine {

class SceneFlattener {
 public:
  /// `forced`: settings replaced in every block that declares them (replay's input file).
  SceneFlattener(const Diagram& d, GraphBuilder& graph,
                 const std::vector<std::pair<std::string, std::string>>& forced,
                 std::vector<std::string>& warnings)
      : d_(d), graph_(graph), forced_(forced), warnings_(warnings) {}

  /// The scene's `blocks:` and `connections:` (connections may be undefined), written in `file`,
  /// with the subsystem types of `library`.
  void add_scene(const std::string& file, const SubsystemLibrary& library, const YAML::Node& blocks,
                 const YAML::Node& connections);
  /// One item of the scene's `outputs:`: `block.port`, `block`, an instance's output port
  /// (`corner_fl.damper_force`), a block inside an instance (`corner_fl.damper.force`), or a
  /// whole instance (all its output ports).
  void request_output(const std::string& text, const std::string& file, int line);

 private:
  /// The scene, or one instance of a subsystem inside it.
  struct Level {
    Scope scope;
    std::string name;   ///< the instance's flat name (`corner_fl`); "" for the scene
    std::string file;   ///< where the instance is written
    int line = 0;
    std::set<std::string> blocks;                             ///< plain blocks, local names
    std::map<std::string, std::unique_ptr<Level>> instances;  ///< local name -> its inside
    std::set<std::string> driven;                             ///< input ports connected from outside
  };
  using FlatPort = std::pair<std::string, std::string>;  ///< flat block, port

  /// `connections`: null when none are written.
  void expand(Level& level, const YAML::Node& blocks, const YAML::Node* connections);
  void instantiate(Level& outer, const YAML::Node& key, const YAML::Node& body,
                   const SubsystemDefinition& def, const YAML::Node& type_node);
  void connect(Level& level, const YAML::Node& item);
  FlatPort source(const Level& level, const std::string& text, const std::string& file, int line) const;
  void targets(const Level& level, const std::string& text, const std::string& file, int line,
               std::vector<FlatPort>& out, bool mark_driven) const;
  void request(const Level& level, const std::string& text, const std::string& shown,
               const std::string& file, int line);

  const Diagram& d_;
  GraphBuilder& graph_;
  const std::vector<std::pair<std::string, std::string>>& forced_;
  std::vector<std::string>& warnings_;
  Level scene_;
  std::vector<const SubsystemDefinition*> open_;  ///< definitions being expanded, outermost first
};

}  // namespace dydp::engine
