// Results of the last run: the objectives table (psi and d(psi)/dp per direction) and plots of
// a chosen logged signal over time with its sensitivities.
#pragma once

#include <QComboBox>
#include <QTableWidget>
#include <QWidget>
#include <memory>

#include "engine/run.hpp"

QT_BEGIN_NAMESPACE
class QChartView;
QT_END_NAMESPACE

namespace dydp::gui {

class ResultsPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ResultsPanel(QWidget* parent = nullptr);
  void show_result(std::shared_ptr<const engine::RunResult> result);
  void clear();
  QTableWidget* objectives() { return objectives_; }
  /// Plots signal i (index into the result's logged signals).
  void plot_signal(int i);

 private:
  std::shared_ptr<const engine::RunResult> result_;
  QTableWidget* objectives_;
  QComboBox* signal_;
  QChartView* value_chart_;
  QChartView* sens_chart_;
};

}  // namespace dydp::gui
