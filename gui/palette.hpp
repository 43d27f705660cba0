// The block palette: every registered block type, grouped in sections, with its one-line
// summary; an entry dragged onto the canvas carries its type name (kBlockTypeMime).
#pragma once

#include <QTreeWidget>

namespace dydp::gui {

class Palette : public QTreeWidget {
  Q_OBJECT

 public:
  explicit Palette(QWidget* parent = nullptr);
  /// The section titles shown, in order.
  QStringList sections() const;
  /// The entry of a block type, or null.
  QTreeWidgetItem* entry(const QString& type) const;
  /// What a drag of `entry` carries to the canvas (the block type under kBlockTypeMime).
  QMimeData* drag_data(QTreeWidgetItem* entry) const { return mimeData({entry}); }

 signals:
  /// A double-clicked entry: add the type at a free place.
  void activated_type(const QString& type);

 protected:
  QMimeData* mimeData(const QList<QTreeWidgetItem*>& items) const override;
  QStringList mimeTypes() const override;
};

}  // namespace dydp::gui
