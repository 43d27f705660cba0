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

/// Replaces the chart's series by the given curves against t, with fitted axes.
void set_curves(QChartView* view, const QString& title, const std::vector<double>& t,
                const std::vector<std::pair<QString, std::vector<double>>>& curves) {
  QChart* chart = view->chart();
  chart->removeAllSeries();
  for (QAbstractAxis* a : chart->axes()) {
    chart->removeAxis(a);
    delete a;
  }
  chart->setTitle(title);
  if (t.empty() || curves.empty()) return;
  double lo = INFINITY, hi = -INFINITY;
  auto* x = new QValueAxis;
  auto* y = new QValueAxis;
  x->setTitleText("t [s]");
  x->setRange(t.front(), t.back());
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  for (const auto& [name, v] : curves) {
    auto* s = new QLineSeries;
    s->setName(name);
    QList<QPointF> points;
    points.reserve(static_cast<qsizetype>(t.size()));
    for (size_t k = 0; k < t.size(); ++k) {
      points.append({t[k], v[k]});
      lo = std::min(lo, v[k]);
      hi = std::max(hi, v[k]);
    }
    s->replace(points);
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y);
  }
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
  objectives_ = new QTableWidget(0, 2);
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
  layout->addWidget(split);
  connect(signal_, &QComboBox::currentIndexChanged, this, &ResultsPanel::plot_signal);
  clear();
}

void ResultsPanel::clear() {
  result_.reset();
  objectives_->setRowCount(0);
  objectives_->setColumnCount(2);
  objectives_->setHorizontalHeaderLabels({tr("objective"), tr("ψ")});
  signal_->clear();
  set_curves(value_chart_, tr("signal"), {}, {});
  set_curves(sens_chart_, tr("sensitivities"), {}, {});
}

void ResultsPanel::show_result(std::shared_ptr<const engine::RunResult> result) {
  clear();
  result_ = std::move(result);
  const auto& r = *result_;
  QStringList headers = {tr("objective"), tr("ψ")};
  for (const auto& p : r.sensitivity_names) headers << QString("dψ/d%1").arg(q(p));
  objectives_->setColumnCount(headers.size());
  objectives_->setHorizontalHeaderLabels(headers);
  for (const auto& o : r.objectives) {
    const int row = objectives_->rowCount();
    objectives_->insertRow(row);
    objectives_->setItem(row, 0, new QTableWidgetItem(q(o.name)));
    objectives_->setItem(row, 1, new QTableWidgetItem(QString::number(o.value, 'g', 8)));
    for (size_t d = 0; d < o.sensitivity.size(); ++d)
      objectives_->setItem(row, 2 + static_cast<int>(d), new QTableWidgetItem(QString::number(o.sensitivity[d], 'g', 8)));
  }
  {
    const QSignalBlocker block(signal_);
    for (const auto& name : r.signal_names) signal_->addItem(q(name));
  }
  if (!r.signal_names.empty()) plot_signal(0);
}

void ResultsPanel::plot_signal(int i) {
  if (!result_ || i < 0 || i >= result_->num_signals()) return;
  const auto& r = *result_;
  const size_t n = r.t.size();
  std::vector<double> v(n);
  for (size_t k = 0; k < n; ++k) v[k] = r.value(static_cast<int>(k), i);
  const QString name = q(r.signal_names[i]);
  set_curves(value_chart_, name, r.t, {{name, v}});
  std::vector<std::pair<QString, std::vector<double>>> sens;
  if (!r.tangents.empty()) {
    for (size_t d = 0; d < r.sensitivity_names.size(); ++d) {
      std::vector<double> dv(n);
      for (size_t k = 0; k < n; ++k) dv[k] = r.tangent(static_cast<int>(k), static_cast<int>(d), i);
      sens.emplace_back(QString("d/d%1").arg(q(r.sensitivity_names[d])), std::move(dv));
    }
  }
  set_curves(sens_chart_, tr("sensitivities of %1").arg(name), r.t, sens);
  if (signal_->currentIndex() != i) {
    const QSignalBlocker block(signal_);
    signal_->setCurrentIndex(i);
  }
}

}  // namespace dydp::gui
