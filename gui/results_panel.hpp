// Results of the last run: the objectives table (psi and d(psi)/dp for every direction, one row
// each, with full precision and units) and plots of the logged signals ticked in the list, over
// time, overlaid in one chart with a legend (two units: a second axis; a third is refused), and
// of their sensitivities; axes named with their units, the previous run's curves dashed beside.
#pragma once

#include <QLabel>
#include <QListWidget>
#include <QTableWidget>
#include <QWidget>
#include <memory>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

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
  /// Plots signal i alone (index into the result's logged signals).
  void plot_signal(int i);
  /// Plots signals overlaid (indices into the result's logged signals) and ticks them in the
  /// list; "" when drawn, else why not (signals of more than two units: nothing changes).
  QString plot_signals(const std::vector<int>& chosen);
  /// The signals plotted, in the order they were ticked.
  const std::vector<int>& plotted() const { return plotted_; }
  /// The list of logged signals: ticking one adds it to the plot.
  QListWidget* signal_list() { return signal_list_; }
  /// Why the last signal ticked was not drawn ("" when it was).
  QString plot_message() const { return plot_message_->text(); }
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
  /// Draws plotted_ (values and sensitivities).
  void draw_plotted();
  /// The ticks of the list follow plotted_.
  void tick_plotted();

  QListWidget* signal_list_;
  QLabel* plot_message_;
  std::vector<int> plotted_;
  QChartView* value_chart_;
  QChartView* sens_chart_;
};

}  // namespace dydp::gui
