#include "gui/diagram_items.hpp"

#include <QFontMetricsF>
#include <QGraphicsScene>
#include <QPainter>
#include <QPainterPathStroker>
#include <QPen>
#include <QStyleOptionGraphicsItem>
#include <algorithm>

namespace dydp::gui {
namespace {

constexpr double kHeader = 40.0;   // [px] name and type
constexpr double kRow = 20.0;      // [px] one port row
constexpr double kPortRadius = 5.0;

QString q(const std::string& s) { return QString::fromStdString(s); }

QString port_label(const engine::PortDecl& p) {
  return p.width > 1 ? QString("%1 [%2]").arg(q(p.name)).arg(p.width) : q(p.name);
}

std::string signature(const DocBlock& b, const BlockPorts& ports) {
  std::string s = b.type + "|" + ports.error;
  for (const auto& p : ports.inputs) s += "|i" + p.name + ":" + std::to_string(p.width);
  for (const auto& p : ports.outputs) s += "|o" + p.name + ":" + std::to_string(p.width);
  return s;
}

}  // namespace

QSizeF block_size(const DocBlock& block, const BlockPorts& ports) {
  const QFont font;
  QFont bold = font;
  bold.setBold(true);
  const QFontMetricsF fm(font), fb(bold);
  const size_t rows = std::max<size_t>({ports.inputs.size(), ports.outputs.size(), 1});
  double left = 0, right = 0;
  for (const auto& p : ports.inputs) left = std::max(left, fm.horizontalAdvance(port_label(p)));
  for (const auto& p : ports.outputs) right = std::max(right, fm.horizontalAdvance(port_label(p)));
  const double width = std::max({150.0, left + right + 40.0, fb.horizontalAdvance(q(block.name)) + 24.0,
                                 fm.horizontalAdvance(q(block.type)) + 24.0});
  const double height = kHeader + kRow * static_cast<double>(rows) + (ports.is_objective ? kRow : 6.0);
  return {width, height};
}

double port_offset(size_t k) { return kHeader + kRow * (static_cast<double>(k) + 0.5); }

PortItem::PortItem(QGraphicsItem* parent, std::string block, const engine::PortDecl& decl, bool input)
    : QGraphicsEllipseItem(-kPortRadius, -kPortRadius, 2 * kPortRadius, 2 * kPortRadius, parent),
      block_(std::move(block)), name_(decl.name), input_(input), width_(decl.width) {
  setPen(QPen(QColor(40, 40, 40), 1.2));
  setAcceptHoverEvents(true);
  setCursor(Qt::CrossCursor);
  QString tip = QString("%1.%2 (%3, width %4)").arg(q(block_), q(name_), input ? "input" : "output").arg(width_);
  if (!decl.unit.empty()) tip += QString(" [%1]").arg(q(decl.unit));
  setToolTip(tip);
  refresh_brush();
}

void PortItem::set_logged(bool logged) {
  logged_ = logged;
  refresh_brush();
}

void PortItem::set_drop_state(int state) {
  drop_state_ = state;
  refresh_brush();
}

void PortItem::refresh_brush() {
  QColor c = input_ ? QColor(250, 250, 250) : QColor(120, 170, 230);
  if (logged_) c = QColor(90, 180, 110);
  if (drop_state_ > 0) c = QColor(60, 200, 60);
  if (drop_state_ < 0) c = QColor(220, 60, 60);
  setBrush(c);
}

BlockItem::BlockItem(const DocBlock& block, const std::string& summary, const BlockPorts& ports)
    : name_(block.name), type_(block.type), signature_(signature(block, ports)), summary_(q(summary)),
      ports_error_(q(ports.error)), objective_(ports.is_objective) {
  setFlags(ItemIsMovable | ItemIsSelectable | ItemSendsGeometryChanges);
  setAcceptHoverEvents(true);
  const size_t rows = std::max<size_t>({ports.inputs.size(), ports.outputs.size(), 1});
  for (size_t r = 0; r < rows; ++r)
    rows_.emplace_back(r < ports.inputs.size() ? port_label(ports.inputs[r]) : QString(),
                       r < ports.outputs.size() ? port_label(ports.outputs[r]) : QString());
  const QSizeF size = block_size(block, ports);
  const double width = size.width();
  setRect(0, 0, width, size.height());
  for (size_t k = 0; k < ports.inputs.size(); ++k) {
    auto* p = new PortItem(this, name_, ports.inputs[k], true);
    p->setPos(0, port_offset(k));
    ports_.push_back(p);
  }
  for (size_t k = 0; k < ports.outputs.size(); ++k) {
    auto* p = new PortItem(this, name_, ports.outputs[k], false);
    p->setPos(width, port_offset(k));
    ports_.push_back(p);
  }
  setPos(block.x, block.y);
  setToolTip(q(type_) + ": " + summary_ + (ports_error_.isEmpty() ? "" : "\n" + ports_error_));
}

bool BlockItem::same_shape(const DocBlock& block, const BlockPorts& ports) const {
  return block.name == name_ && signature(block, ports) == signature_;
}

PortItem* BlockItem::port(const std::string& name, bool input) const {
  for (PortItem* p : ports_)
    if (p->ref().port == name && p->is_input() == input) return p;
  return nullptr;
}

void BlockItem::set_logged(const std::vector<std::string>& outputs) {
  const bool all = std::find(outputs.begin(), outputs.end(), name_) != outputs.end();
  for (PortItem* p : ports_)
    if (!p->is_input())
      p->set_logged(all || std::find(outputs.begin(), outputs.end(), p->ref().text()) != outputs.end());
  objective_logged_ = objective_ && all;
  update();
}

void BlockItem::set_error(const QString& message) {
  error_ = message;
  setToolTip(message.isEmpty() ? q(type_) + ": " + summary_ : message);
  update();
}

void BlockItem::set_note(const QString& note) {
  note_ = note;
  update();
}

void BlockItem::paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) {
  const QRectF r = rect();
  const bool selected = isSelected();
  QColor frame = selected ? QColor(30, 100, 220) : QColor(70, 70, 70);
  if (!error_.isEmpty() || !ports_error_.isEmpty()) frame = QColor(210, 40, 40);
  p->setRenderHint(QPainter::Antialiasing);
  p->setPen(QPen(frame, selected || !error_.isEmpty() ? 2.5 : 1.2));
  p->setBrush(objective_ ? QColor(255, 248, 225) : QColor(246, 248, 252));
  p->drawRoundedRect(r, 6, 6);
  p->setPen(Qt::NoPen);
  p->setBrush(objective_ ? QColor(250, 225, 160) : QColor(210, 222, 240));
  QPainterPath header;
  header.addRoundedRect(QRectF(r.left() + 1, r.top() + 1, r.width() - 2, kHeader - 4), 5, 5);
  p->drawPath(header);

  QFont font = p->font();
  QFont bold = font;
  bold.setBold(true);
  p->setPen(Qt::black);
  p->setFont(bold);
  p->drawText(QRectF(r.left() + 8, r.top() + 2, r.width() - 16, 18), Qt::AlignLeft | Qt::AlignVCenter, q(name_));
  QFont small = font;
  small.setPointSizeF(font.pointSizeF() * 0.85);
  p->setFont(small);
  p->setPen(QColor(70, 70, 90));
  p->drawText(QRectF(r.left() + 8, r.top() + 18, r.width() - 16, 16), Qt::AlignLeft | Qt::AlignVCenter, q(type_));
  p->setFont(font);
  p->setPen(QColor(30, 30, 30));
  for (size_t k = 0; k < rows_.size(); ++k) {
    const QRectF row(r.left() + 10, r.top() + kHeader + kRow * static_cast<double>(k), r.width() - 20, kRow);
    p->drawText(row, Qt::AlignLeft | Qt::AlignVCenter, rows_[k].first);
    p->drawText(row, Qt::AlignRight | Qt::AlignVCenter, rows_[k].second);
  }
  const QString note = !note_.isEmpty() ? note_ : objective_logged_ ? QObject::tr("ψ requested") : QString();
  if (!note.isEmpty()) {
    p->setPen(QColor(120, 70, 0));
    p->drawText(QRectF(r.left() + 10, r.bottom() - kRow - 2, r.width() - 20, kRow), Qt::AlignLeft | Qt::AlignVCenter, note);
  }
  if (!ports_error_.isEmpty()) {
    p->setPen(QColor(210, 40, 40));
    p->drawText(QRectF(r.left() + 10, r.top() + kHeader, r.width() - 20, kRow), Qt::AlignLeft | Qt::AlignVCenter,
                QObject::tr("needs settings"));
  }
}

QVariant BlockItem::itemChange(GraphicsItemChange change, const QVariant& value) {
  if (change == ItemPositionHasChanged && on_moved) on_moved();
  if (change == ItemSelectedHasChanged) update();
  return QGraphicsRectItem::itemChange(change, value);
}

QPainterPath wire_path(QPointF from, QPointF to) {
  const double dx = std::max(40.0, std::abs(to.x() - from.x()) * 0.5);
  QPainterPath path(from);
  path.cubicTo(from + QPointF(dx, 0), to - QPointF(dx, 0), to);
  return path;
}

WireItem::WireItem(const DocConnection& c, PortItem* from, PortItem* to)
    : connection_(c), from_(from), to_(to) {
  setFlags(ItemIsSelectable);
  setZValue(-1);
  setPen(QPen(QColor(60, 60, 60), 1.8));
  setToolTip(q(c.text()));
  update_path();
}

void WireItem::update_path() { setPath(wire_path(from_->anchor(), to_->anchor())); }

QPainterPath WireItem::shape() const {
  QPainterPathStroker stroker;
  stroker.setWidth(8);
  return stroker.createStroke(path());
}

QVariant WireItem::itemChange(GraphicsItemChange change, const QVariant& value) {
  if (change == ItemSelectedHasChanged)
    setPen(QPen(value.toBool() ? QColor(30, 100, 220) : QColor(60, 60, 60), value.toBool() ? 3.0 : 1.8));
  return QGraphicsPathItem::itemChange(change, value);
}

}  // namespace dydp::gui
