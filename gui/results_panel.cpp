#include "gui/results_panel.hpp"

#include <QChart>
#include <QChartView>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineSeries>
#include <QSplitter>
#include <QVBoxLayout>
#include <QValueAxis>
#include <algorithm>
#include <cmath>

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

QChartView* make_chart_view() {
  auto* view = new QChartView(new QChart);
  view->setRenderHint(QPainter::Antialiasing);
  view->chart()->legend()->setAlignment(Qt::AlignRight);
  view->chart()->setMargins(QMargins(4, 4, 4, 4));
  view->setMinimumHeight(140);
  return view;
}

/// One curve of a chart: values against its own time grid; dashed for the previous run.
struct Curve {
  QString name;
  const std::vector<double>* t;
  std::vector<double> v;
  bool dashed = false;
};

/// Replaces the chart's series by the given curves, with fitted axes.
void set_curves(QChartView* view, const QString& title, const QString& y_title, const std::vector<Curve>& curves) {
  QChart* chart = view->chart();
  chart->removeAllSeries();
  for (QAbstractAxis* a : chart->axes()) {
    chart->removeAxis(a);
    delete a;
  }
  chart->setTitle(title);
  if (curves.empty() || curves.front().t->empty()) return;
  double lo = INFINITY, hi = -INFINITY, t0 = INFINITY, t1 = -INFINITY;
  auto* x = new QValueAxis;
  auto* y = new QValueAxis;
  x->setTitleText("t [s]");
  y->setTitleText(y_title);
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  for (const Curve& c : curves) {
    auto* s = new QLineSeries;
    s->setName(c.name);
    QList<QPointF> points;
    points.reserve(static_cast<qsizetype>(c.t->size()));
    for (size_t k = 0; k < c.t->size() && k < c.v.size(); ++k) {
      points.append({(*c.t)[k], c.v[k]});
      lo = std::min(lo, c.v[k]);
      hi = std::max(hi, c.v[k]);
    }
    t0 = std::min(t0, c.t->front());
    t1 = std::max(t1, c.t->back());
    s->replace(points);
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y);
    if (c.dashed) {
      QPen pen = s->pen();
      pen.setStyle(Qt::DashLine);
      pen.setColor(QColor(150, 150, 150));
      s->setPen(pen);
    }
  }
  x->setRange(t0, t1);
  if (!(hi > lo)) {
    lo -= 1;
    hi += 1;
  }
  const double pad = 0.05 * (hi - lo);
  y->setRange(lo - pad, hi + pad);
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
  left_layout->addWidget(new QLabel(tr("Signal")));
  signal_ = new QComboBox;
  left_layout->addWidget(signal_);
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
  connect(signal_, &QComboBox::currentIndexChanged, this, &ResultsPanel::plot_signal);
  clear();
}

void ResultsPanel::clear() {
  result_.reset();
  diagram_.reset();
  objectives_->setRowCount(0);
  objectives_->setColumnCount(4);
  objectives_->setHorizontalHeaderLabels({tr("objective"), tr("quantity"), tr("value"), tr("unit")});
  signal_->clear();
  set_curves(value_chart_, tr("signal"), {}, {});
  set_curves(sens_chart_, tr("sensitivities"), {}, {});
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
    const QSignalBlocker block(signal_);
    for (const auto& name : r.signal_names) signal_->addItem(q(name));
  }
  if (!r.signal_names.empty()) plot_signal(0);
}

int ResultsPanel::find_row(const QString& objective, const QString& quantity) const {
  for (int row = 0; row < objectives_->rowCount(); ++row)
    if (objectives_->item(row, 0)->text() == objective && objectives_->item(row, 1)->text() == quantity) return row;
  return -1;
}

void ResultsPanel::plot_signal(int i) {
  if (!result_ || i < 0 || i >= result_->num_signals()) return;
  const auto& r = *result_;
  const size_t n = r.t.size();
  std::vector<double> v(n);
  for (size_t k = 0; k < n; ++k) v[k] = r.value(static_cast<int>(k), i);
  const QString name = q(r.signal_names[i]);
  const QString unit = signal_unit(i);
  std::vector<Curve> values = {{name, &r.t, std::move(v)}};
  // The same signal of the previous run, when it has one.
  const int j = previous_ ? previous_->signal_index(r.signal_names[i]) : -1;
  if (j >= 0) {
    std::vector<double> pv(previous_->t.size());
    for (size_t k = 0; k < pv.size(); ++k) pv[k] = previous_->value(static_cast<int>(k), j);
    values.push_back({name + tr(" (previous run)"), &previous_->t, std::move(pv), true});
  }
  set_curves(value_chart_, name, unit.isEmpty() ? name : QString("%1 [%2]").arg(name, unit), values);
  std::vector<Curve> sens;
  if (!r.tangents.empty()) {
    for (size_t d = 0; d < r.sensitivity_names.size(); ++d) {
      std::vector<double> dv(n);
      for (size_t k = 0; k < n; ++k) dv[k] = r.tangent(static_cast<int>(k), static_cast<int>(d), i);
      const QString per = q(engine::unit_per(unit.toStdString(), parameter_unit(d).toStdString()));
      sens.push_back({QString("d/d%1").arg(q(r.sensitivity_names[d])) + (per.isEmpty() ? "" : " [" + per + "]"),
                      &r.t, std::move(dv)});
    }
  }
  // The axis names the unit when all directions share it; else each curve's name carries its own.
  QString per_all;
  for (size_t d = 0; d < r.sensitivity_names.size(); ++d) {
    const QString per = q(engine::unit_per(unit.toStdString(), parameter_unit(d).toStdString()));
    per_all = d == 0 || per == per_all ? per : QString("mixed");
  }
  set_curves(sens_chart_, tr("sensitivities of %1").arg(name),
             QString("d(%1)/dp").arg(name) + (per_all.isEmpty() || per_all == "mixed" ? "" : " [" + per_all + "]"), sens);
  if (signal_->currentIndex() != i) {
    const QSignalBlocker block(signal_);
    signal_->setCurrentIndex(i);
  }
}

}  // namespace dydp::gui
