// Results of the last run: the objectives table (psi and d(psi)/dp for every direction, one row
// each, with full precision and units) and plots of a chosen logged signal over time with its
// sensitivities, axes named with their units, the previous run's curve dashed beside it.
#pragma once

#include <QComboBox>
#include <QTableWidget>
#include <QWidget>
#include <memory>

#include "engine/diagram.hpp"
#include "engine/run.hpp"

QT_BEGIN_NAMESPACE
class QChartView;
QT_END_NAMESPACE

namespace dydp::gui {

class ResultsPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ResultsPanel(QWidget* parent = nullptr);
  /// `diagram`: the run's diagram, for units (null: none shown).
  void show_result(std::shared_ptr<const engine::RunResult> result,
                   std::shared_ptr<const engine::Diagram> diagram = nullptr);
  void clear();
  /// Clears and forgets the previous run too (another scene opened).
  void forget_runs();
  QTableWidget* objectives() { return objectives_; }
  /// Plots signal i (index into the result's logged signals).
  void plot_signal(int i);
  /// The table row of an objective's quantity ("ψ", "dψ/dP"), or -1.
  int find_row(const QString& objective, const QString& quantity) const;
  QChartView* value_chart() { return value_chart_; }
  QChartView* sensitivity_chart() { return sens_chart_; }
  /// A number with every digit needed to read it back exactly.
  static QString full_number(double v);

 private:
  QString parameter_unit(size_t direction) const;
  QString signal_unit(int signal) const;

  std::shared_ptr<const engine::RunResult> result_;
  std::shared_ptr<const engine::RunResult> previous_;  ///< the run shown before, for comparison
  std::shared_ptr<const engine::Diagram> diagram_;
  QTableWidget* objectives_;
  QComboBox* signal_;
  QChartView* value_chart_;
  QChartView* sens_chart_;
};

}  // namespace dydp::gui
