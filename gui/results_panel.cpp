#include "gui/results_panel.hpp"

#include "gui/chart_curves.hpp"

#include <QChart>
#include <QChartView>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineSeries>
#include <QSplitter>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

QChartView* make_chart_view() {
  auto* view = new QChartView(new QChart);
  view->setRenderHint(QPainter::Antialiasing);
  view->chart()->legend()->setAlignment(Qt::AlignBottom);
  view->chart()->setMargins(QMargins(4, 4, 4, 4));
  view->setMinimumHeight(140);
  return view;
}

}  // namespace

ResultsPanel::ResultsPanel(QWidget* parent) : QWidget(parent) {
  auto* layout = new QHBoxLayout(this);
  auto* left = new QWidget;
  auto* left_layout = new QVBoxLayout(left);
  left_layout->setContentsMargins(0, 0, 0, 0);
  left_layout->addWidget(new QLabel(tr("Objectives")));
  objectives_ = new QTableWidget(0, 4);
  objectives_->verticalHeader()->hide();
  objectives_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  objectives_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  left_layout->addWidget(objectives_);
  left_layout->addWidget(new QLabel(tr("Signals (tick several to overlay them)")));
  signal_list_ = new QListWidget;
  signal_list_->setObjectName("signal_list");
  left_layout->addWidget(signal_list_);
  plot_message_ = new QLabel;
  plot_message_->setWordWrap(true);
  plot_message_->setStyleSheet("color: #c02020;");
  left_layout->addWidget(plot_message_);
  auto* charts = new QSplitter(Qt::Horizontal);
  value_chart_ = make_chart_view();
  sens_chart_ = make_chart_view();
  charts->addWidget(value_chart_);
  charts->addWidget(sens_chart_);
  auto* split = new QSplitter(Qt::Horizontal);
  split->addWidget(left);
  split->addWidget(charts);
  split->setStretchFactor(1, 3);
  // Wide enough for an objective, a dψ/dp label and a value to the last digit with its unit.
  left->setMinimumWidth(520);
  layout->addWidget(split);
  connect(signal_list_, &QListWidget::itemChanged, this, [this](QListWidgetItem* item) {
    const int i = signal_list_->row(item);
    std::vector<int> want = plotted_;
    std::erase(want, i);
    if (item->checkState() == Qt::Checked) want.push_back(i);
    if (want == plotted_) return;
    // A refused signal is unticked again by plot_signals (through tick_plotted).
    if (!plot_signals(want).isEmpty()) tick_plotted();
  });
  clear();
}

void ResultsPanel::clear() {
  result_.reset();
  diagram_.reset();
  objectives_->setRowCount(0);
  objectives_->setColumnCount(4);
  objectives_->setHorizontalHeaderLabels({tr("objective"), tr("quantity"), tr("value"), tr("unit")});
  plotted_.clear();
  {
    const QSignalBlocker block(signal_list_);
    signal_list_->clear();
  }
  plot_message_->clear();
  draw_curves(value_chart_->chart(), tr("signal"), {}, {});
  draw_curves(sens_chart_->chart(), tr("sensitivities"), {}, {});
}

void ResultsPanel::forget_runs() {
  clear();
  previous_.reset();
}

QString ResultsPanel::parameter_unit(size_t d) const {
  if (!diagram_ || d >= diagram_->sensitivities.size()) return {};
  return q(diagram_->parameters[diagram_->sensitivities[d]].unit);
}

QString ResultsPanel::signal_unit(int i) const {
  if (!diagram_ || i < 0 || i >= static_cast<int>(diagram_->logged.size())) return {};
  return q(diagram_->signal_unit(diagram_->logged[i].offset));
}

QString ResultsPanel::full_number(double v) { return QString::number(v, 'g', QLocale::FloatingPointShortest); }

void ResultsPanel::show_result(std::shared_ptr<const engine::RunResult> result,
                               std::shared_ptr<const engine::Diagram> diagram) {
  // The run shown so far stays, dashed, for comparison with the new one.
  if (result_) previous_ = result_;
  clear();
  result_ = std::move(result);
  diagram_ = std::move(diagram);
  const auto& r = *result_;
  // One row per figure: psi, then d(psi)/dp for every direction, each with its full value and
  // unit, so that no direction is cut off however many there are.
  const auto add = [this](const QString& objective, const QString& quantity, double value, const QString& unit) {
    const int row = objectives_->rowCount();
    objectives_->insertRow(row);
    objectives_->setItem(row, 0, new QTableWidgetItem(objective));
    objectives_->setItem(row, 1, new QTableWidgetItem(quantity));
    auto* v = new QTableWidgetItem(full_number(value));
    v->setTextAlignment(Qt::AlignRight | Qt::AlignVCenter);
    objectives_->setItem(row, 2, v);
    objectives_->setItem(row, 3, new QTableWidgetItem(unit));
  };
  for (const auto& o : r.objectives) {
    add(q(o.name), QString("ψ"), o.value, q(o.unit));
    for (size_t d = 0; d < o.sensitivity.size() && d < r.sensitivity_names.size(); ++d)
      add(q(o.name), QString("dψ/d%1").arg(q(r.sensitivity_names[d])), o.sensitivity[d],
          q(engine::unit_per(o.unit, parameter_unit(d).toStdString())));
  }
  {
    const QSignalBlocker block(signal_list_);
    for (size_t i = 0; i < r.signal_names.size(); ++i) {
      const QString unit = signal_unit(static_cast<int>(i));
      auto* item = new QListWidgetItem(q(r.signal_names[i]) + (unit.isEmpty() ? "" : " [" + unit + "]"), signal_list_);
      item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable | Qt::ItemIsSelectable);
      item->setCheckState(Qt::Unchecked);
    }
  }
  if (!r.signal_names.empty()) plot_signal(0);
}

int ResultsPanel::find_row(const QString& objective, const QString& quantity) const {
  for (int row = 0; row < objectives_->rowCount(); ++row)
    if (objectives_->item(row, 0)->text() == objective && objectives_->item(row, 1)->text() == quantity) return row;
  return -1;
}

void ResultsPanel::plot_signal(int i) { plot_signals({i}); }

QString ResultsPanel::plot_signals(const std::vector<int>& chosen) {
  if (!result_) return tr("no run to plot");
  std::vector<QString> units;
  for (int i : chosen) {
    if (i < 0 || i >= result_->num_signals()) return tr("no signal %1").arg(i);
    if (std::find(units.begin(), units.end(), signal_unit(i)) == units.end()) units.push_back(signal_unit(i));
  }
  // One chart has a left and a right axis: a third unit would have no axis to be read against.
  if (units.size() > 2) {
    const int refused = chosen.back();
    const QString why = tr("%1 [%2] not drawn: the chart already shows %3 and %4 (one unit per axis); "
                           "untick a signal of one of those first")
                            .arg(q(result_->signal_names[refused]), signal_unit(refused), units[0], units[1]);
    plot_message_->setText(why);
    return why;
  }
  plot_message_->clear();
  plotted_ = chosen;
  tick_plotted();
  draw_plotted();
  return {};
}

void ResultsPanel::tick_plotted() {
  const QSignalBlocker block(signal_list_);
  for (int row = 0; row < signal_list_->count(); ++row) {
    const bool on = std::find(plotted_.begin(), plotted_.end(), row) != plotted_.end();
    signal_list_->item(row)->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  }
}

void ResultsPanel::draw_plotted() {
  const auto& r = *result_;
  const size_t n = r.t.size();
  std::vector<Curve> values, sens;
  QStringList names;
  for (int i : plotted_) {
    const QString name = q(r.signal_names[i]);
    const QString unit = signal_unit(i);
    names << name;
    std::vector<double> v(n);
    for (size_t k = 0; k < n; ++k) v[k] = r.value(static_cast<int>(k), i);
    values.push_back({name, unit, &r.t, std::move(v)});
    // The same signal of the previous run, when it has one.
    const int j = previous_ ? previous_->signal_index(r.signal_names[i]) : -1;
    if (j >= 0) {
      std::vector<double> pv(previous_->t.size());
      for (size_t k = 0; k < pv.size(); ++k) pv[k] = previous_->value(static_cast<int>(k), j);
      values.push_back({name + tr(" (previous run)"), unit, &previous_->t, std::move(pv), true});
    }
    for (size_t d = 0; d < r.sensitivity_names.size() && !r.tangents.empty(); ++d) {
      std::vector<double> dv(n);
      for (size_t k = 0; k < n; ++k) dv[k] = r.tangent(static_cast<int>(k), static_cast<int>(d), i);
      const QString per = q(engine::unit_per(unit.toStdString(), parameter_unit(d).toStdString()));
      const QString label = plotted_.size() == 1 ? QString("d/d%1").arg(q(r.sensitivity_names[d]))
                                                 : QString("d(%1)/d%2").arg(name, q(r.sensitivity_names[d]));
      sens.push_back({label + (per.isEmpty() ? "" : " [" + per + "]"), per, &r.t, std::move(dv)});
    }
  }
  // An axis is named after its signals when they are few, with their unit.
  const auto value_axis = [&](const QString& unit) {
    QStringList of;
    for (int i : plotted_)
      if (signal_unit(i) == unit) of << q(r.signal_names[i]);
    const QString what = of.size() <= 2 ? of.join(", ") : tr("value");
    return unit.isEmpty() ? what : QString("%1 [%2]").arg(what, unit);
  };
  const QString title = names.join(", ");
  draw_curves(value_chart_->chart(), title, values, value_axis);
  const QString of = names.size() == 1 ? names.front() : tr("signals");
  draw_curves(sens_chart_->chart(), tr("sensitivities of %1").arg(title), sens, [&](const QString& per) {
    return QString("d(%1)/dp").arg(of) + (per.isEmpty() ? "" : " [" + per + "]");
  });
}

}  // namespace dydp::gui
