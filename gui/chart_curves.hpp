// Curves of the results panel drawn into a chart: time on the x axis, the curves grouped by
// their unit, the first unit on the left axis and a second one on the right axis; a legend names
// every curve. More units than two are refused by the caller (signals) or share one axis with
// the unit in each curve's name (sensitivities).
#pragma once

#include <QString>
#include <functional>
#include <vector>

QT_BEGIN_NAMESPACE
class QChart;
QT_END_NAMESPACE

namespace dydp::gui {

/// One curve: values against its own time grid [s] (or another x, see ChartAxes); dashed for the
/// previous run's.
struct Curve {
  QString name;
  QString unit;  ///< the unit of the values ("" when unknown)
  const std::vector<double>* t = nullptr;
  std::vector<double> v;
  bool dashed = false;
};

/// How the axes read: the x axis's title, and whether it and the first unit's y axis are
/// logarithmic (a frequency response's frequency and magnitude; values <= 0 are left out there).
struct ChartAxes {
  QString x_title = "t [s]";
  bool log_x = false;
  bool log_first_y = false;
};

/// The distinct units of the curves, in order of first appearance.
std::vector<QString> units_of(const std::vector<Curve>& curves);

/// Replaces the chart's series and axes by `curves`. With one or two units each has its own y
/// axis (left, then right) titled axis_title(unit); with more, one axis for all. `t` of a curve
/// is its x values: time, or frequency with ChartAxes{"f [Hz]", true}.
void draw_curves(QChart* chart, const QString& title, const std::vector<Curve>& curves,
                 const std::function<QString(const QString& unit)>& axis_title, const ChartAxes& axes = {});

}  // namespace dydp::gui
