// The diagram canvas: blocks and wires of the controller's document, kept in step with it.
// Dropping a palette entry calls drop_block, dragging from a port to a port calls wire; a wire
// the controller refuses is not drawn and the reason is reported at once (message()).
#pragma once

#include <QGraphicsView>
#include <map>
#include <set>

#include "gui/diagram_items.hpp"
#include "gui/scene_controller.hpp"

namespace dydp::gui {

/// Mime type of a palette drag: the block type's name as UTF-8.
inline constexpr const char* kBlockTypeMime = "application/x-dydp-block-type";

class Canvas : public QGraphicsView {
  Q_OBJECT

 public:
  explicit Canvas(SceneController* controller, QWidget* parent = nullptr);
  /// The scene member outlives this body: its selection changes while it deletes its items
  /// must no longer reach the canvas (or, through selection_changed, the window being closed).
  ~Canvas() override;

  /// What a drop of a palette entry at scene position pos does; returns the new block's name.
  QString drop_block(const QString& type, QPointF pos);
  /// What releasing a wire drag from port a over port b does (either direction of drag);
  /// returns "" when wired, else the reason it was refused (also sent as message()).
  QString wire(const PortRef& a, bool a_is_input, const PortRef& b, bool b_is_input);
  /// Deletes the selected blocks and wires.
  void delete_selection();

  BlockItem* block_item(const std::string& name) const;
  int wire_count() const { return static_cast<int>(wires_.size()); }
  QStringList selected_blocks() const;
  void select_block(const QString& name);

  /// Marks blocks with an error (red frame, message on hover); clear_errors() removes the marks.
  void show_error(const QStringList& blocks, const QString& message);
  void clear_errors();
  /// Notes under objective blocks (their value after a run).
  void set_notes(const std::map<std::string, QString>& notes);
  /// Fits the whole diagram in the view (never magnifying beyond natural size).
  void fit_all();
  /// Selects and centres the block named `text` (or the first whose name contains it) at the
  /// level shown; false when there is none.
  bool find_block(const QString& text);

  /// Shows the inside of subsystem instance `block` of the level shown (a double-click on it);
  /// false when it is not an instance whose definition is known.
  bool open_subsystem(const QString& block);
  /// Back to the enclosing level (`levels` up; the breadcrumb's entries).
  void close_subsystem(int levels = 1);
  /// The instances opened, outermost first; empty at the scene's level.
  const QStringList& level() const { return level_; }
  /// A block with more than kPortsShownAll ports (ports_in_use.hpp) shows only those wired or
  /// logged, unless toggled to show all (View > Show all ports).
  void toggle_all_ports(const QString& block);
  /// Whether the level shown is the scene's own one.
  bool at_scene_level() const { return level_.isEmpty(); }
  /// The definition shown inside the instances opened (null at the scene's level); `instance`
  /// receives the innermost instance with its values bound.
  const DocSubsystem* definition_shown(DocBlock* instance = nullptr) const;
  /// Its name ("" at the scene's level).
  QString definition_name() const;
  /// Whether blocks shown can be moved and edited: the scene's level, or an inline definition.
  bool level_editable() const;
  /// Groups the selected blocks into a new subsystem (SceneController::group_into_subsystem);
  /// "" when done (the instance is then selected), else why not.
  QString group_selection();

 signals:
  void message(const QString& text);
  void selection_changed(const QString& block);
  void level_changed(const QStringList& level);

 public slots:
  void sync();

 protected:
  void dragEnterEvent(QDragEnterEvent* e) override;
  void dragMoveEvent(QDragMoveEvent* e) override;
  void dropEvent(QDropEvent* e) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void contextMenuEvent(QContextMenuEvent* e) override;

 private:
  /// What is drawn at the current level: blocks, connections and each block's ports.
  struct View {
    std::vector<DocBlock> blocks;
    std::vector<DocConnection> connections;
    std::map<std::string, BlockPorts> ports;
    std::map<std::string, std::string> summaries;
    std::vector<std::string> outputs;  ///< logged (the scene's level only)
  };
  /// The view of level_, or false when a level no longer exists (then back to the scene).
  bool make_view(View& view) const;
  void draw(const View& view);
  BlockPorts shown_ports(const View& view, const std::string& block) const;
  void grow_scene_rect();
  PortItem* port_at(QPoint view_pos) const;
  void update_wires_of(const std::string& block);
  void commit_moves();
  /// Removes every wire item from the scene (the document is untouched).
  void clear_wires();
  /// Removes every block and wire item: before another level is drawn.
  void clear_items();

  SceneController* controller_;
  QGraphicsScene scene_;
  std::map<std::string, BlockItem*> blocks_;
  std::vector<WireItem*> wires_;
  // A wire being dragged from a port.
  PortItem* drag_from_ = nullptr;
  PortItem* drag_over_ = nullptr;
  QGraphicsPathItem* drag_wire_ = nullptr;
  QStringList level_;
  QString shown_file_;
  bool panning_ = false;
  QPoint pan_from_;
  std::set<std::string> all_ports_;  ///< blocks showing every port
};

}  // namespace dydp::gui
