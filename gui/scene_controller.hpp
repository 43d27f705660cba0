// The edit API of the GUI: every change the views make to a scene (drop a block, drag a wire,
// type a parameter) is one call here, checked first and refused with a reason, else applied as
// an undoable command. Tests build scenes with the same calls the canvas makes.
#pragma once

#include <QObject>
#include <QPointF>
#include <QString>
#include <QStringList>
#include <QUndoStack>
#include <map>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "gui/block_catalog.hpp"
#include "gui/scene_document.hpp"

namespace dydp::gui {

class SceneController : public QObject {
  Q_OBJECT

 public:
  explicit SceneController(QObject* parent = nullptr);

  const SceneDocument& document() const { return doc_; }
  QUndoStack* undo_stack() { return &undo_; }
  /// The file the scene was opened from or saved to; empty for a new scene.
  const QString& file_path() const { return path_; }
  bool modified() const { return !undo_.isClean(); }

  void new_scene();
  /// Opens a scene file; blocks without a layout position are placed by the layered layout
  /// (automatic_layout.hpp), below those that have one.
  /// Throws engine::InputError when the file is not a scene.
  void open(const QString& path);
  /// Writes the scene (with its layout) to path; throws std::exception on failure.
  void save(const QString& path);

  // Edits. Those returning QString return an empty string when done, else why they were refused
  // (nothing changed then). add_block returns the new block's name, empty for an unknown type.
  QString add_block(const QString& type, QPointF pos);
  void remove_blocks(const QStringList& names);
  void move_block(const QString& name, QPointF pos);
  /// Places every block of the scene anew by the layered layout (one undo step).
  void lay_out();
  /// Replaces the blocks by one instance of a new inline subsystem definition (subsystem_grouping.hpp);
  /// `instance` receives its name.
  QString group_into_subsystem(const QStringList& blocks, QString* instance = nullptr);

  // Edits inside a subsystem definition written inline in the scene (one written in a file of
  // its own is read only here: other scenes include it too).
  /// Whether the definition named `subsystem` can be edited here.
  bool definition_editable(const QString& subsystem) const;
  void move_block_in(const QString& subsystem, const QString& block, QPointF pos);
  /// A parameter or setting of a block inside: a number, `$name` of the definition's own
  /// parameters, or a setting; checked as set_block_value checks the scene's blocks.
  QString set_block_value_in(const QString& subsystem, const QString& block, const QString& key, const QString& text);
  QString connect_ports(const QString& from, const QString& to);
  /// Why `from -> to` cannot be wired ("" when it can); changes nothing.
  QString check_connection(const QString& from, const QString& to) const;
  void remove_connections(const std::vector<DocConnection>& connections);
  /// A parameter (number or $scene_parameter) or a setting ("[a, b]" for lists); empty text
  /// removes the key so the type's default applies. A setting that changes the ports drops the
  /// wires and outputs that no longer fit, in the same undo step.
  QString set_block_value(const QString& block, const QString& key, const QString& text);
  QString rename_block(const QString& from, const QString& to);
  /// Adds or removes an entry of `outputs:` ("block.port" or an objective's name).
  void set_output(const QString& ref, bool logged);
  QString set_time(const QString& key, const QString& text);
  QString set_solver(const QString& key, const QString& text);
  /// The `initial:` section as YAML text (`equilibrium`, `{state: equilibrium, hold: {rig.zdot: 0}}`;
  /// empty removes it); refused when it is not YAML (the engine checks the rest when run).
  QString set_initial(const QString& text);
  void set_scene_info(const QString& name, const QString& description);
  QString add_scene_parameter(const QString& name, const QString& value);
  /// Replaces scene parameter `name` by p; a new name is carried to $refs and sensitivities.
  QString update_scene_parameter(const QString& name, const DocParameter& p);
  QString remove_scene_parameter(const QString& name);
  void set_sensitivity(const QString& name, bool on);
  /// Makes a block parameter a sensitivity direction in one step: the scene parameter driving it
  /// (`$name`), or a new one named BLOCK_PARAMETER holding its current value and unit, becomes a
  /// direction. `parameter` receives the scene parameter's name.
  QString make_direction(const QString& block, const QString& key, QString* parameter = nullptr);

  /// The ports of a block of the document (cached per type and settings).
  BlockPorts ports(const std::string& block) const;
  const engine::BlockType* type_of(const std::string& block) const;

  /// The scene as the engine loads it to run (the saved file when unmodified, else the
  /// document written to a temporary file beside it). Throws engine::InputError.
  engine::Diagram load_for_run() const;
  /// The blocks a validation error is about: the block its field names, or those of a loop.
  QStringList blocks_of_error(const engine::InputError& e) const;

 signals:
  void document_changed();
  void file_changed();

 private:
  friend class DocumentEdit;
  /// Pushes the change from the current document to `after` as one undo step (none if equal).
  void commit(const QString& label, SceneDocument after);
  void replace(const SceneDocument& doc);
  /// Drops connections and outputs that the block's current ports no longer support.
  void drop_dangling(SceneDocument& doc, const std::string& block) const;

  SceneDocument doc_;
  QUndoStack undo_;
  QString path_;
  mutable std::map<std::string, BlockPorts> ports_cache_;
};

}  // namespace dydp::gui
