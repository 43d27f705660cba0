// The scene panel: name and description, time span and output step, solver settings, and the
// scene parameters with their units, ranges and whether each is a sensitivity direction.
#pragma once

#include <QComboBox>
#include <QLabel>
#include <QLineEdit>
#include <QTableWidget>
#include <QWidget>
#include <map>

#include "gui/scene_controller.hpp"

namespace dydp::gui {

class ScenePanel : public QWidget {
  Q_OBJECT

 public:
  explicit ScenePanel(SceneController* controller, QWidget* parent = nullptr);
  QTableWidget* parameters() { return params_; }

 public slots:
  void refresh();

 signals:
  void message(const QString& text);

 private:
  void report(const QString& why);
  void edit_parameter(int row);

  SceneController* controller_;
  QLineEdit* name_;
  QLineEdit* description_;
  std::map<QString, QLineEdit*> time_, solver_;
  QLineEdit* initial_;
  QComboBox* method_;
  QTableWidget* params_;
  QLabel* status_;
  bool refreshing_ = false;
};

}  // namespace dydp::gui
