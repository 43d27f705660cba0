// The diagram canvas: blocks and wires of the controller's document, kept in step with it.
// Dropping a palette entry calls drop_block, dragging from a port to a port calls wire; a wire
// the controller refuses is not drawn and the reason is reported at once (message()).
#pragma once

#include <QGraphicsView>
#include <map>

#include "gui/diagram_items.hpp"
#include "gui/scene_controller.hpp"

namespace dydp::gui {

/// Mime type of a palette drag: the block type's name as UTF-8.
inline constexpr const char* kBlockTypeMime = "application/x-dydp-block-type";

class Canvas : public QGraphicsView {
  Q_OBJECT

 public:
  explicit Canvas(SceneController* controller, QWidget* parent = nullptr);

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
  void fit_all();

 signals:
  void message(const QString& text);
  void selection_changed(const QString& block);

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

 private:
  PortItem* port_at(QPoint view_pos) const;
  void update_wires_of(const std::string& block);
  void commit_moves();

  SceneController* controller_;
  QGraphicsScene scene_;
  std::map<std::string, BlockItem*> blocks_;
  std::vector<WireItem*> wires_;
  // A wire being dragged from a port.
  PortItem* drag_from_ = nullptr;
  PortItem* drag_over_ = nullptr;
  QGraphicsPathItem* drag_wire_ = nullptr;
};

}  // namespace dydp::gui
