#include "gui/palette.hpp"

#include <QHeaderView>
#include <QMimeData>
#include <QPainter>
#include <QStyledItemDelegate>

#include "gui/block_catalog.hpp"
#include "gui/canvas.hpp"

namespace dydp::gui {
namespace {

constexpr int kTypeRole = Qt::UserRole + 1;
constexpr int kSummaryRole = Qt::UserRole + 2;

/// Draws a type entry as its name over its summary (grey, elided to the column).
class EntryDelegate : public QStyledItemDelegate {
 public:
  using QStyledItemDelegate::QStyledItemDelegate;
  void paint(QPainter* p, const QStyleOptionViewItem& option, const QModelIndex& index) const override {
    const QString summary = index.data(kSummaryRole).toString();
    if (summary.isEmpty()) return QStyledItemDelegate::paint(p, option, index);
    QStyleOptionViewItem o = option;
    initStyleOption(&o, index);
    const QString name = o.text;
    o.text.clear();
    o.widget->style()->drawControl(QStyle::CE_ItemViewItem, &o, p, o.widget);
    const QRect r = o.rect.adjusted(4, 2, -4, -2);
    const int half = r.height() / 2;
    p->save();
    QFont bold = o.font;
    bold.setBold(true);
    p->setFont(bold);
    p->setPen(o.palette.color(o.state & QStyle::State_Selected ? QPalette::HighlightedText : QPalette::Text));
    p->drawText(QRect(r.left(), r.top(), r.width(), half), Qt::AlignLeft | Qt::AlignVCenter, name);
    QFont small = o.font;
    small.setPointSizeF(o.font.pointSizeF() * 0.85);
    p->setFont(small);
    p->setPen(o.state & QStyle::State_Selected ? o.palette.color(QPalette::HighlightedText) : QColor(100, 100, 100));
    const QString elided = QFontMetrics(small).elidedText(summary, Qt::ElideRight, r.width());
    p->drawText(QRect(r.left(), r.top() + half, r.width(), half), Qt::AlignLeft | Qt::AlignVCenter, elided);
    p->restore();
  }
  QSize sizeHint(const QStyleOptionViewItem& option, const QModelIndex& index) const override {
    QSize s = QStyledItemDelegate::sizeHint(option, index);
    if (!index.data(kSummaryRole).toString().isEmpty()) s.setHeight(QFontMetrics(option.font).height() * 2 + 8);
    return s;
  }
};

QString section_label(const std::string& title) {
  QString t = QString::fromStdString(title);
  if (!t.isEmpty()) t[0] = t[0].toUpper();
  return t;
}

}  // namespace

Palette::Palette(QWidget* parent) : QTreeWidget(parent) {
  setHeaderHidden(true);
  setColumnCount(1);
  setDragEnabled(true);
  setDragDropMode(DragOnly);
  setRootIsDecorated(true);
  setIndentation(12);
  setItemDelegate(new EntryDelegate(this));
  for (const PaletteSection& section : palette_sections()) {
    auto* top = new QTreeWidgetItem(this, {section_label(section.title)});
    QFont f = top->font(0);
    f.setBold(true);
    top->setFont(0, f);
    top->setFlags(Qt::ItemIsEnabled);
    for (const engine::BlockType* t : section.types) {
      auto* item = new QTreeWidgetItem(top, {QString::fromStdString(t->name)});
      item->setData(0, kTypeRole, QString::fromStdString(t->name));
      item->setData(0, kSummaryRole, QString::fromStdString(t->summary));
      item->setToolTip(0, QString::fromStdString(t->summary));
      item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsDragEnabled);
    }
    top->setExpanded(true);
  }
  connect(this, &QTreeWidget::itemDoubleClicked, this, [this](QTreeWidgetItem* item) {
    const QString type = item->data(0, kTypeRole).toString();
    if (!type.isEmpty()) emit activated_type(type);
  });
}

QStringList Palette::sections() const {
  QStringList out;
  for (int i = 0; i < topLevelItemCount(); ++i) out << topLevelItem(i)->text(0);
  return out;
}

QTreeWidgetItem* Palette::entry(const QString& type) const {
  for (int i = 0; i < topLevelItemCount(); ++i)
    for (int j = 0; j < topLevelItem(i)->childCount(); ++j)
      if (topLevelItem(i)->child(j)->data(0, kTypeRole).toString() == type) return topLevelItem(i)->child(j);
  return nullptr;
}

QStringList Palette::mimeTypes() const { return {kBlockTypeMime}; }

QMimeData* Palette::mimeData(const QList<QTreeWidgetItem*>& items) const {
  if (items.isEmpty()) return nullptr;
  const QString type = items.front()->data(0, kTypeRole).toString();
  if (type.isEmpty()) return nullptr;
  auto* data = new QMimeData;
  data->setData(kBlockTypeMime, type.toUtf8());
  return data;
}

}  // namespace dydp::gui
