#include "gui/canvas.hpp"

#include <QDragEnterEvent>
#include <QContextMenuEvent>
#include <QKeyEvent>
#include <QMenu>
#include <QMimeData>
#include <QScrollBar>
#include <QWheelEvent>
#include <algorithm>
#include <set>

#include "gui/ports_in_use.hpp"
#include "gui/subsystem_ports.hpp"

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

}  // namespace

Canvas::Canvas(SceneController* controller, QWidget* parent)
    : QGraphicsView(parent), controller_(controller) {
  setScene(&scene_);
  setAcceptDrops(true);
  setRenderHint(QPainter::Antialiasing);
  setDragMode(RubberBandDrag);
  // Ctrl+wheel zooms about the point under the cursor.
  setTransformationAnchor(AnchorUnderMouse);
  setBackgroundBrush(QColor(252, 252, 250));
  connect(controller_, &SceneController::document_changed, this, &Canvas::sync);
  connect(controller_, &SceneController::file_changed, this, [this] {
    // Another scene (or a new one): start at its top.
    if (shown_file_ != controller_->file_path() && !level_.isEmpty()) close_subsystem(static_cast<int>(level_.size()));
    shown_file_ = controller_->file_path();
  });
  connect(&scene_, &QGraphicsScene::selectionChanged, this, [this] {
    // Inside a subsystem written in a file of its own nothing is edited: nothing to show.
    if (!level_editable()) return;
    const QStringList sel = selected_blocks();
    const DocSubsystem* def = definition_shown();
    const bool block = sel.size() == 1 && (!def || def->find_block(sel.front().toStdString()));
    emit selection_changed(block ? sel.front() : QString());
  });
  sync();
}

Canvas::~Canvas() { disconnect(&scene_, nullptr, this, nullptr); }

BlockItem* Canvas::block_item(const std::string& name) const {
  const auto it = blocks_.find(name);
  return it == blocks_.end() ? nullptr : it->second;
}

void Canvas::sync() {
  View view;
  if (!make_view(view)) {
    // The instance shown is gone (undo, rename): back to the scene.
    level_.clear();
    emit level_changed(level_);
    make_view(view);
  }
  draw(view);
}

namespace {

std::string summary_of(const SceneDocument& doc, const DocBlock& b) {
  if (const DocSubsystem* def = doc.subsystem_of(b))
    return "subsystem " + def->name + (def->description.empty() ? "" : ": " + def->description) +
           " (double-click to open)";
  const engine::BlockType* type = engine::Registry::global().find(b.type);
  return type ? type->summary : "unknown block type";
}

engine::PortDecl port_named(const std::vector<engine::PortDecl>& ports, const std::string& name) {
  for (const auto& p : ports)
    if (p.name == name) return p;
  engine::PortDecl p;
  p.name = name;
  return p;
}

}  // namespace

const DocSubsystem* Canvas::definition_shown(DocBlock* instance_out) const {
  if (level_.isEmpty()) return nullptr;
  // Walk down the instances opened: each with its values bound as the engine binds them.
  const SceneDocument& doc = controller_->document();
  const DocBlock* top = doc.find_block(level_.front().toStdString());
  if (!top) return nullptr;
  DocBlock instance = *top;
  const DocSubsystem* def = doc.subsystem_of(instance);
  for (qsizetype i = 1; def && def->error.empty() && i < level_.size(); ++i) {
    const DocBlock* inner = def->find_block(level_[i].toStdString());
    if (!inner) return nullptr;
    instance = bound_block(*def, instance, *inner);
    def = doc.subsystem_of(instance);
  }
  if (!def || !def->error.empty()) return nullptr;
  if (instance_out) *instance_out = instance;
  return def;
}

QString Canvas::definition_name() const {
  const DocSubsystem* def = definition_shown();
  return def ? q(def->name) : QString();
}

bool Canvas::level_editable() const {
  return at_scene_level() || controller_->definition_editable(definition_name());
}

bool Canvas::make_view(View& v) const {
  const SceneDocument& doc = controller_->document();
  if (level_.isEmpty()) {
    v.blocks = doc.blocks;
    v.connections = doc.connections;
    v.outputs = doc.outputs;
    for (const DocBlock& b : doc.blocks) {
      v.ports[b.name] = controller_->ports(b.name);
      v.summaries[b.name] = summary_of(doc, b);
    }
    return true;
  }
  DocBlock instance;
  const DocSubsystem* def = definition_shown(&instance);
  if (!def) return false;
  double left = 0, right = 0, topmost = 0;
  bool first = true;
  for (const DocBlock& b : def->blocks) {
    v.blocks.push_back(b);  // shown as written inside: `$stiffness`, not the instance's value
    const DocBlock bound = bound_block(*def, instance, b);
    v.ports[b.name] = block_ports(doc, bound);
    v.summaries[b.name] = summary_of(doc, bound);
    left = first ? b.x : std::min(left, b.x);
    right = first ? b.x : std::max(right, b.x);
    topmost = first ? b.y : std::min(topmost, b.y);
    first = false;
  }
  v.connections = def->connections;
  // The instance's own ports as blocks at the edges: inputs left of the inside, outputs right.
  const BlockPorts outer = instance_ports(doc, instance);
  int row = 0;
  for (const auto& [port, targets] : def->inputs) {
    DocBlock pb;
    pb.name = "in " + port;
    pb.x = left - 300;
    pb.y = topmost + 90 * row++;
    pb.placed = true;
    BlockPorts pp;
    pp.outputs.push_back(port_named(outer.inputs, port));
    v.ports[pb.name] = pp;
    v.summaries[pb.name] = "input port " + port + " of subsystem " + def->name;
    for (const std::string& t : targets) {
      DocConnection c;
      c.from = {pb.name, port};
      if (PortRef::parse(t, c.to)) v.connections.push_back(c);
    }
    v.blocks.push_back(pb);
  }
  row = 0;
  for (const auto& [port, source] : def->outputs) {
    DocBlock pb;
    pb.name = "out " + port;
    pb.x = right + 300;
    pb.y = topmost + 90 * row++;
    pb.placed = true;
    BlockPorts pp;
    pp.inputs.push_back(port_named(outer.outputs, port));
    v.ports[pb.name] = pp;
    v.summaries[pb.name] = "output port " + port + " of subsystem " + def->name;
    DocConnection c;
    c.to = {pb.name, port};
    if (PortRef::parse(source, c.from)) v.connections.push_back(c);
    v.blocks.push_back(pb);
  }
  return true;
}

void Canvas::toggle_all_ports(const QString& block) {
  const std::string name = block.toStdString();
  if (!all_ports_.erase(name)) all_ports_.insert(name);
  sync();
}

BlockPorts Canvas::shown_ports(const View& view, const std::string& block) const {
  // A block with very many ports (a whole car) shows those in use; the rest on request.
  const BlockPorts& ports = view.ports.at(block);
  return all_ports_.count(block) ? ports : ports_in_use(ports, block, view.connections, view.outputs);
}

void Canvas::draw(const View& view) {
  // At a subsystem's level the blocks inside move, the port blocks at the edges do not.
  const DocSubsystem* def = definition_shown();
  const bool editable = level_editable();
  // Blocks: keep items whose shape is unchanged (selection and error marks survive), remake others.
  std::set<std::string> present;
  for (const DocBlock& b : view.blocks) {
    present.insert(b.name);
    const BlockPorts ports = shown_ports(view, b.name);
    const BlockPorts& all = view.ports.at(b.name);
    const size_t hidden = all.inputs.size() + all.outputs.size() - ports.inputs.size() - ports.outputs.size();
    BlockItem* item = block_item(b.name);
    bool reselect = false;
    if (item && !item->same_shape(b, ports)) {
      // Settings changed the ports: remake the item (wires are remade below anyway).
      reselect = item->isSelected();
      clear_wires();
      scene_.removeItem(item);
      delete item;
      item = nullptr;
      blocks_.erase(b.name);
    }
    if (!item) {
      std::string summary = view.summaries.at(b.name);
      if (hidden > 0)
        summary += "\n" + std::to_string(hidden) + " ports not in use are hidden: View > Show all ports";
      item = new BlockItem(b, summary, ports);
      const std::string name = b.name;
      item->on_moved = [this, name] { update_wires_of(name); };
      scene_.addItem(item);
      blocks_[b.name] = item;
      item->setSelected(reselect);
    }
    item->setFlag(QGraphicsItem::ItemIsMovable, editable && (!def || def->find_block(b.name)));
    if (item->pos() != QPointF(b.x, b.y)) item->setPos(b.x, b.y);
    item->set_logged(view.outputs);
  }
  for (auto it = blocks_.begin(); it != blocks_.end();) {
    if (present.count(it->first)) {
      ++it;
      continue;
    }
    scene_.removeItem(it->second);
    delete it->second;
    it = blocks_.erase(it);
  }
  // Wires: always redrawn from the connections.
  clear_wires();
  for (const DocConnection& c : view.connections) {
    BlockItem* from = block_item(c.from.block);
    BlockItem* to = block_item(c.to.block);
    PortItem* pf = from ? from->port(c.from.port, false) : nullptr;
    PortItem* pt = to ? to->port(c.to.port, true) : nullptr;
    if (!pf || !pt) continue;  // the engine reports it when the scene is run
    auto* w = new WireItem(c, pf, pt);
    scene_.addItem(w);
    wires_.push_back(w);
  }
  grow_scene_rect();
}

void Canvas::grow_scene_rect() {
  // The scene is the diagram plus a margin to drop and drag into: it grows and shrinks with it.
  const QRectF items = scene_.itemsBoundingRect();
  const QRectF shown = mapToScene(viewport()->rect()).boundingRect();
  const double mx = std::max(400.0, shown.width() / 2), my = std::max(300.0, shown.height() / 2);
  scene_.setSceneRect(items.isEmpty() ? QRectF(-mx, -my, 2 * mx, 2 * my) : items.adjusted(-mx, -my, mx, my));
}

void Canvas::clear_wires() {
  for (WireItem* w : wires_) {
    scene_.removeItem(w);
    delete w;
  }
  wires_.clear();
}

void Canvas::clear_items() {
  clear_wires();
  for (auto& [name, item] : blocks_) {
    scene_.removeItem(item);
    delete item;
  }
  blocks_.clear();
}

bool Canvas::open_subsystem(const QString& block) {
  const QStringList before = level_;
  level_ << block;
  View view;
  if (!make_view(view)) {
    level_ = before;
    return false;
  }
  clear_items();
  draw(view);
  emit level_changed(level_);
  emit message(level_editable()
                   ? tr("inside %1: blocks move and their values are edited in the Block tab; Alt+Up or the breadcrumb goes back")
                         .arg(level_.join(" ▸ "))
                   : tr("inside %1 (read only: defined in %2); Alt+Up or the breadcrumb goes back")
                         .arg(level_.join(" ▸ "), q(definition_shown()->file)));
  fit_all();
  return true;
}

void Canvas::close_subsystem(int levels) {
  if (level_.isEmpty()) return;
  const QString left = level_.back();
  for (int i = 0; i < levels && !level_.isEmpty(); ++i) level_.removeLast();
  clear_items();
  sync();
  emit level_changed(level_);
  emit message({});
  fit_all();
  if (levels == 1) select_block(left);
}

void Canvas::mouseDoubleClickEvent(QMouseEvent* e) {
  for (QGraphicsItem* item : items(e->pos())) {
    for (QGraphicsItem* at = item; at; at = at->parentItem())
      if (auto* b = qgraphicsitem_cast<BlockItem*>(at)) {
        if (!open_subsystem(q(b->name()))) QGraphicsView::mouseDoubleClickEvent(e);
        return;
      }
  }
  QGraphicsView::mouseDoubleClickEvent(e);
}

void Canvas::update_wires_of(const std::string& block) {
  for (WireItem* w : wires_)
    if (w->connection().from.block == block || w->connection().to.block == block) w->update_path();
}

QString Canvas::drop_block(const QString& type, QPointF pos) {
  if (!at_scene_level()) {
    emit message(tr("refused: the inside of a subsystem is read only here; go back to the scene to add blocks"));
    return {};
  }
  const QString name = controller_->add_block(type, pos);
  if (name.isEmpty()) emit message(tr("unknown block type '%1'").arg(type));
  else select_block(name);
  return name;
}

QString Canvas::wire(const PortRef& a, bool a_is_input, const PortRef& b, bool b_is_input) {
  // Dragging from an input to an output wires output -> input; same-direction pairs are refused
  // by the controller with the reason.
  const bool swap = a_is_input && !b_is_input;
  const QString from = q(swap ? b.text() : a.text()), to = q(swap ? a.text() : b.text());
  const QString why = controller_->connect_ports(from, to);
  emit message(why.isEmpty() ? tr("wired %1 -> %2").arg(from, to) : tr("refused: %1").arg(why));
  return why;
}

void Canvas::delete_selection() {
  if (!at_scene_level()) return;
  QStringList blocks;
  std::vector<DocConnection> wires;
  for (QGraphicsItem* item : scene_.selectedItems()) {
    if (auto* b = qgraphicsitem_cast<BlockItem*>(item)) blocks << q(b->name());
    if (auto* w = qgraphicsitem_cast<WireItem*>(item)) wires.push_back(w->connection());
  }
  controller_->undo_stack()->beginMacro(tr("Delete"));
  if (!wires.empty()) controller_->remove_connections(wires);
  if (!blocks.isEmpty()) controller_->remove_blocks(blocks);
  controller_->undo_stack()->endMacro();
}

QStringList Canvas::selected_blocks() const {
  QStringList out;
  for (QGraphicsItem* item : scene_.selectedItems())
    if (auto* b = qgraphicsitem_cast<BlockItem*>(item)) out << q(b->name());
  return out;
}

void Canvas::select_block(const QString& name) {
  scene_.clearSelection();
  if (BlockItem* b = block_item(name.toStdString())) b->setSelected(true);
}

void Canvas::show_error(const QStringList& blocks, const QString& message) {
  clear_errors();
  for (const QString& name : blocks)
    if (BlockItem* b = block_item(name.toStdString())) {
      b->set_error(message);
      ensureVisible(b);
    }
}

void Canvas::clear_errors() {
  for (auto& [name, item] : blocks_) item->set_error({});
}

void Canvas::set_notes(const std::map<std::string, QString>& notes) {
  for (auto& [name, item] : blocks_) {
    const auto it = notes.find(name);
    item->set_note(it == notes.end() ? QString() : it->second);
  }
}

void Canvas::fit_all() {
  QRectF r = scene_.itemsBoundingRect();
  if (r.isEmpty()) return;
  r.adjust(-30, -30, 30, 30);
  fitInView(r, Qt::KeepAspectRatio);
  // Never magnify: text stays at its natural size when the diagram is small.
  if (transform().m11() > 1.0) resetTransform();
  centerOn(r.center());
}

PortItem* Canvas::port_at(QPoint view_pos) const {
  for (QGraphicsItem* item : items(view_pos))
    if (auto* p = qgraphicsitem_cast<PortItem*>(item)) return p;
  return nullptr;
}

void Canvas::dragEnterEvent(QDragEnterEvent* e) {
  if (e->mimeData()->hasFormat(kBlockTypeMime)) e->acceptProposedAction();
  else QGraphicsView::dragEnterEvent(e);
}

void Canvas::dragMoveEvent(QDragMoveEvent* e) {
  if (e->mimeData()->hasFormat(kBlockTypeMime)) e->acceptProposedAction();
  else QGraphicsView::dragMoveEvent(e);
}

void Canvas::dropEvent(QDropEvent* e) {
  if (!e->mimeData()->hasFormat(kBlockTypeMime)) return QGraphicsView::dropEvent(e);
  const QString type = QString::fromUtf8(e->mimeData()->data(kBlockTypeMime));
  drop_block(type, mapToScene(e->position().toPoint()));
  e->acceptProposedAction();
}

bool Canvas::find_block(const QString& text) {
  // The first block whose name contains the text (case-insensitive), the exact name first.
  BlockItem* found = block_item(text.toStdString());
  for (auto it = blocks_.begin(); !found && it != blocks_.end(); ++it)
    if (QString::fromStdString(it->first).contains(text, Qt::CaseInsensitive)) found = it->second;
  if (!found || text.isEmpty()) {
    emit message(tr("no block named like '%1' here").arg(text));
    return false;
  }
  scene_.clearSelection();
  found->setSelected(true);
  centerOn(found);
  emit message(tr("found %1").arg(q(found->name())));
  return true;
}

void Canvas::mousePressEvent(QMouseEvent* e) {
  if (e->button() == Qt::MiddleButton) {
    // Pan: the diagram follows the mouse while the middle button is held.
    pan_from_ = e->pos();
    panning_ = true;
    return;
  }
  if (e->button() == Qt::LeftButton && at_scene_level()) {
    if (PortItem* p = port_at(e->pos())) {
      drag_from_ = p;
      drag_wire_ = scene_.addPath(wire_path(p->anchor(), p->anchor()), QPen(QColor(30, 100, 220), 1.8, Qt::DashLine));
      return;
    }
  }
  QGraphicsView::mousePressEvent(e);
}

void Canvas::mouseMoveEvent(QMouseEvent* e) {
  if (panning_) {
    const QPoint d = e->pos() - pan_from_;
    pan_from_ = e->pos();
    horizontalScrollBar()->setValue(horizontalScrollBar()->value() - d.x());
    verticalScrollBar()->setValue(verticalScrollBar()->value() - d.y());
    return;
  }
  if (!drag_from_) return QGraphicsView::mouseMoveEvent(e);
  const QPointF at = mapToScene(e->pos());
  const QPointF a = drag_from_->anchor();
  drag_wire_->setPath(drag_from_->is_input() ? wire_path(at, a) : wire_path(a, at));
  PortItem* over = port_at(e->pos());
  if (over == drag_from_) over = nullptr;
  if (over != drag_over_) {
    if (drag_over_) drag_over_->set_drop_state(0);
    drag_over_ = over;
    if (over) {
      // Tell at once whether the wire would be accepted, and why not.
      const bool swap = drag_from_->is_input() && !over->is_input();
      const QString why = controller_->check_connection(q((swap ? over : drag_from_)->ref().text()),
                                                        q((swap ? drag_from_ : over)->ref().text()));
      over->set_drop_state(why.isEmpty() ? 1 : -1);
      emit message(why.isEmpty() ? tr("release to wire") : tr("refused: %1").arg(why));
    }
  }
}

void Canvas::mouseReleaseEvent(QMouseEvent* e) {
  if (panning_ && e->button() == Qt::MiddleButton) {
    panning_ = false;
    return;
  }
  if (!drag_from_) {
    QGraphicsView::mouseReleaseEvent(e);
    commit_moves();
    return;
  }
  PortItem* from = drag_from_;
  PortItem* over = port_at(e->pos());
  if (drag_over_) drag_over_->set_drop_state(0);
  scene_.removeItem(drag_wire_);
  delete drag_wire_;
  drag_wire_ = nullptr;
  drag_from_ = drag_over_ = nullptr;
  if (over && over != from) wire(from->ref(), from->is_input(), over->ref(), over->is_input());
}

void Canvas::commit_moves() {
  if (!level_editable()) return;
  // Blocks dragged with the mouse: one undo step for all that moved.
  const DocSubsystem* def = definition_shown();
  const QString inside = def ? q(def->name) : QString();
  std::vector<std::pair<QString, QPointF>> moved;
  for (const DocBlock& b : def ? def->blocks : controller_->document().blocks)
    if (BlockItem* item = block_item(b.name); item && item->pos() != QPointF(b.x, b.y))
      moved.emplace_back(q(b.name), item->pos());
  if (moved.empty()) return;
  controller_->undo_stack()->beginMacro(tr("Move"));
  for (const auto& [name, pos] : moved) {
    if (inside.isEmpty()) controller_->move_block(name, pos);
    else controller_->move_block_in(inside, name, pos);
  }
  controller_->undo_stack()->endMacro();
}

QString Canvas::group_selection() {
  if (!at_scene_level()) {
    emit message(tr("refused: group blocks at the scene's level"));
    return tr("not at the scene's level");
  }
  QString instance;
  const QString why = controller_->group_into_subsystem(selected_blocks(), &instance);
  if (!why.isEmpty()) {
    emit message(tr("refused: %1").arg(why));
    return why;
  }
  select_block(instance);
  emit message(tr("grouped into subsystem %1: double-click it to see inside").arg(instance));
  return {};
}

void Canvas::contextMenuEvent(QContextMenuEvent* e) {
  // Right-click on a block not selected selects it alone, as file managers do.
  for (QGraphicsItem* item : items(e->pos()))
    for (QGraphicsItem* at = item; at; at = at->parentItem())
      if (auto* b = qgraphicsitem_cast<BlockItem*>(at); b && !b->isSelected()) {
        scene_.clearSelection();
        b->setSelected(true);
      }
  const QStringList sel = selected_blocks();
  QMenu menu;
  QAction* group = menu.addAction(tr("&Group into subsystem (%1 blocks)").arg(sel.size()), this, [this] { group_selection(); });
  group->setEnabled(at_scene_level() && !sel.isEmpty());
  QAction* open = menu.addAction(tr("&Open subsystem"), this, [this, sel] { open_subsystem(sel.front()); });
  const DocBlock* one = sel.size() == 1 && at_scene_level() ? controller_->document().find_block(sel.front().toStdString()) : nullptr;
  open->setEnabled(one && controller_->document().subsystem_of(*one));
  menu.exec(e->globalPos());
}

void Canvas::keyPressEvent(QKeyEvent* e) {
  if (e->key() == Qt::Key_Delete || e->key() == Qt::Key_Backspace) {
    delete_selection();
    return;
  }
  QGraphicsView::keyPressEvent(e);
}

void Canvas::wheelEvent(QWheelEvent* e) {
  if (e->modifiers() & Qt::ControlModifier) {
    const double f = e->angleDelta().y() > 0 ? 1.15 : 1 / 1.15;
    scale(f, f);
    return;
  }
  QGraphicsView::wheelEvent(e);
}

}  // namespace dydp::gui
