// The property editor of the selected block: its name, type and summary; its parameters
// (value or $scene_parameter, unit, default, bounds) and settings; which outputs are logged.
// A refused value is reverted and the reason shown under the table.
#pragma once

#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QTableWidget>
#include <QWidget>

#include "gui/scene_controller.hpp"

namespace dydp::gui {

class PropertyEditor : public QWidget {
  Q_OBJECT

 public:
  explicit PropertyEditor(SceneController* controller, QWidget* parent = nullptr);
  /// Shows block `name` of the scene, or of the inline definition `subsystem` (opened on the
  /// canvas): there its values are edited, its name and outputs are not.
  void set_block(const QString& name, const QString& subsystem = {});
  const QString& block() const { return block_; }
  const QString& subsystem() const { return subsystem_; }
  /// Applies text to the parameter or setting in `row` as if typed; returns the refusal or "".
  QString edit_value(const QString& key, const QString& text);
  QTableWidget* table() { return table_; }
  /// Makes parameter `key` of the block a sensitivity direction (SceneController::make_direction).
  QString make_direction(const QString& key);
  QPushButton* make_direction_button() { return make_direction_; }

 public slots:
  void refresh();

 signals:
  void message(const QString& text);

 private:
  SceneController* controller_;
  QString block_;
  QString subsystem_;  ///< "" for a block of the scene
  QLineEdit* name_;
  QLabel* type_;
  QLabel* summary_;
  QTableWidget* table_;
  QListWidget* outputs_;
  QLabel* status_;
  QPushButton* make_direction_;
  bool refreshing_ = false;
};

}  // namespace dydp::gui
