#include "gui/chart_curves.hpp"

#include <QChart>
#include <QLegend>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QValueAxis>
#include <algorithm>
#include <cmath>

namespace dydp::gui {
namespace {

constexpr size_t kAxesPerChart = 2;

/// y range of the curves with padding; a flat curve gets a unit band around its value.
std::pair<double, double> padded_range(double lo, double hi) {
  if (!(hi > lo)) {
    lo -= 1;
    hi += 1;
  }
  const double pad = 0.05 * (hi - lo);
  return {lo - pad, hi + pad};
}

/// The same on a log axis (lo, hi > 0): 5 % of the decades either side.
std::pair<double, double> padded_log_range(double lo, double hi) {
  if (!(lo > 0) || !std::isfinite(lo) || !std::isfinite(hi)) return {0.1, 10.0};
  if (!(hi > lo)) return {lo / 10, lo * 10};
  const double pad = std::pow(hi / lo, 0.05);
  return {lo / pad, hi * pad};
}

QAbstractAxis* make_axis(bool log, const QString& title) {
  if (log) {
    auto* a = new QLogValueAxis;
    a->setBase(10.0);
    a->setLabelFormat("%g");
    a->setMinorTickCount(8);
    a->setTitleText(title);
    return a;
  }
  auto* a = new QValueAxis;
  a->setTitleText(title);
  return a;
}

}  // namespace

std::vector<QString> units_of(const std::vector<Curve>& curves) {
  std::vector<QString> units;
  for (const Curve& c : curves)
    if (std::find(units.begin(), units.end(), c.unit) == units.end()) units.push_back(c.unit);
  return units;
}

void draw_curves(QChart* chart, const QString& title, const std::vector<Curve>& curves,
                 const std::function<QString(const QString& unit)>& axis_title, const ChartAxes& axes) {
  chart->removeAllSeries();
  for (QAbstractAxis* a : chart->axes()) {
    chart->removeAxis(a);
    delete a;
  }
  chart->setTitle(title);
  if (curves.empty() || !curves.front().t || curves.front().t->empty()) return;
  const std::vector<QString> units = units_of(curves);
  const bool per_unit = units.size() <= kAxesPerChart;
  QAbstractAxis* x = make_axis(axes.log_x, axes.x_title);
  chart->addAxis(x, Qt::AlignBottom);
  // One y axis per unit (left, right), or one for all.
  std::vector<QAbstractAxis*> y_axes;
  std::vector<bool> log_y;
  std::vector<double> lo, hi;
  for (size_t k = 0; k < (per_unit ? units.size() : 1); ++k) {
    log_y.push_back(k == 0 && axes.log_first_y);
    QAbstractAxis* y =
        make_axis(log_y.back(), per_unit ? axis_title(units[k]) : QObject::tr("value (units in the legend)"));
    chart->addAxis(y, k == 0 ? Qt::AlignLeft : Qt::AlignRight);
    y_axes.push_back(y);
    lo.push_back(INFINITY);
    hi.push_back(-INFINITY);
  }
  double t0 = INFINITY, t1 = -INFINITY;
  for (const Curve& c : curves) {
    const size_t axis =
        per_unit ? static_cast<size_t>(std::find(units.begin(), units.end(), c.unit) - units.begin()) : 0;
    auto* s = new QLineSeries;
    s->setName(c.name);
    QList<QPointF> points;
    points.reserve(static_cast<qsizetype>(c.t->size()));
    for (size_t k = 0; k < c.t->size() && k < c.v.size(); ++k) {
      if ((log_y[axis] && !(c.v[k] > 0)) || (axes.log_x && !((*c.t)[k] > 0))) continue;  // not on a log axis
      points.append({(*c.t)[k], c.v[k]});
      lo[axis] = std::min(lo[axis], c.v[k]);
      hi[axis] = std::max(hi[axis], c.v[k]);
    }
    if (!c.t->empty()) {
      t0 = std::min(t0, c.t->front());
      t1 = std::max(t1, c.t->back());
    }
    s->replace(points);
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y_axes[axis]);
    if (c.dashed) {
      QPen pen = s->pen();
      pen.setStyle(Qt::DashLine);
      pen.setColor(QColor(150, 150, 150));
      s->setPen(pen);
    }
  }
  x->setRange(t0, t1);
  for (size_t k = 0; k < y_axes.size(); ++k) {
    const auto [a, b] = log_y[k] ? padded_log_range(lo[k], hi[k]) : padded_range(lo[k], hi[k]);
    y_axes[k]->setRange(a, b);
  }
  chart->legend()->setVisible(true);
}

}  // namespace dydp::gui
