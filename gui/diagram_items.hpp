// The graphics items of the canvas: a block with its ports (inputs left, outputs right), the
// ports themselves, and the wires between them. Items only draw; edits go through the canvas.
#pragma once

#include <QGraphicsEllipseItem>
#include <QGraphicsPathItem>
#include <QGraphicsRectItem>
#include <functional>

#include "gui/block_catalog.hpp"
#include "gui/scene_document.hpp"

namespace dydp::gui {

/// The size a block is drawn with, given the ports it shows [px].
QSizeF block_size(const DocBlock& block, const BlockPorts& ports);
/// The height of the k-th input (or output) port below the block's top edge [px].
double port_offset(size_t k);

class PortItem : public QGraphicsEllipseItem {
 public:
  enum { Type = UserType + 1 };
  PortItem(QGraphicsItem* parent, std::string block, const engine::PortDecl& decl, bool input);
  int type() const override { return Type; }

  PortRef ref() const { return {block_, name_}; }
  bool is_input() const { return input_; }
  int width() const { return width_; }
  /// Where wires attach, in scene coordinates.
  QPointF anchor() const { return scenePos(); }
  void set_logged(bool logged);
  /// Hover feedback during a wire drag: 0 none, 1 accepts, -1 refuses.
  void set_drop_state(int state);

 private:
  void refresh_brush();
  std::string block_, name_;
  bool input_;
  int width_;
  bool logged_ = false;
  int drop_state_ = 0;
};

class BlockItem : public QGraphicsRectItem {
 public:
  enum { Type = UserType + 2 };
  BlockItem(const DocBlock& block, const std::string& summary, const BlockPorts& ports);
  int type() const override { return Type; }

  const std::string& name() const { return name_; }
  /// Whether the block's type, settings or ports differ from those it was drawn with.
  bool same_shape(const DocBlock& block, const BlockPorts& ports) const;
  PortItem* port(const std::string& name, bool input) const;
  const std::vector<PortItem*>& ports() const { return ports_; }
  void set_logged(const std::vector<std::string>& outputs);
  /// A validation or solver error shown on the block (red frame, message as tooltip); "" clears.
  void set_error(const QString& message);
  bool has_error() const { return !error_.isEmpty(); }
  /// A line under the ports (the objective's value after a run); "" clears.
  void set_note(const QString& note);
  /// Called whenever the block moved (wires follow).
  std::function<void()> on_moved;

  void paint(QPainter* p, const QStyleOptionGraphicsItem* option, QWidget* widget) override;

 protected:
  QVariant itemChange(GraphicsItemChange change, const QVariant& value) override;

 private:
  std::string name_, type_, signature_;
  QString summary_, note_, error_, ports_error_;
  std::vector<PortItem*> ports_;
  bool objective_ = false;
  bool objective_logged_ = false;
  std::vector<std::pair<QString, QString>> rows_;  ///< input label, output label per row
};

class WireItem : public QGraphicsPathItem {
 public:
  enum { Type = UserType + 3 };
  WireItem(const DocConnection& c, PortItem* from, PortItem* to);
  int type() const override { return Type; }
  const DocConnection& connection() const { return connection_; }
  void update_path();
  QPainterPath shape() const override;

 protected:
  QVariant itemChange(GraphicsItemChange change, const QVariant& value) override;

 private:
  DocConnection connection_;
  PortItem *from_, *to_;
};

/// A cubic from an output anchor to an input anchor, leaving and entering horizontally.
QPainterPath wire_path(QPointF from, QPointF to);

}  // namespace dydp::gui
