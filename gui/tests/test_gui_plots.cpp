// Several signals overlaid in one chart: msd_sensitivity run in the window, body.x [m] and
// body.v [m/s] ticked in the results' signal list with the mouse and the keyboard, drawn in the
// same chart with a legend entry each and one axis per unit (left m, right m/s); a third unit
// (body.a, m/s^2) refused with the reason and left unticked; the curves hold the run's values.
#include <QChart>
#include <QChartView>
#include <QLegend>
#include <QLineSeries>
#include <QSignalSpy>
#include <QValueAxis>
#include <QtTest>

#include "gui/main_window.hpp"

using namespace dydp::gui;

namespace {

int row_of(QListWidget* list, const QString& prefix) {
  for (int row = 0; row < list->count(); ++row)
    if (list->item(row)->text().startsWith(prefix + " ") || list->item(row)->text() == prefix) return row;
  return -1;
}

/// Toggles the tick of a list row as a user does: a click selects it, Space toggles it.
void toggle(QListWidget* list, int row) {
  QTest::mouseClick(list->viewport(), Qt::LeftButton, {}, list->visualItemRect(list->item(row)).center());
  QTest::keyClick(list, Qt::Key_Space);
}

QLineSeries* series_named(QChart* chart, const QString& name) {
  for (QAbstractSeries* s : chart->series())
    if (s->name() == name) return qobject_cast<QLineSeries*>(s);
  return nullptr;
}

QString axis_title(QChart* chart, Qt::Alignment side) {
  for (QAbstractAxis* a : chart->axes(Qt::Vertical))
    if (a->alignment() == side) return a->titleText();
  return {};
}

}  // namespace

class GuiPlots : public QObject {
  Q_OBJECT

 private slots:
  void two_signals_in_one_chart_a_third_unit_refused() {
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/msd_sensitivity.yaml", true));
    QSignalSpy ended(&w, &MainWindow::run_ended);
    QVERIFY(w.start_run());
    QVERIFY(ended.wait(60000));
    const RunOutcome outcome = ended.takeFirst().at(0).value<RunOutcome>();
    QVERIFY(outcome.status == RunOutcome::Status::finished);

    ResultsPanel* results = w.results();
    QListWidget* list = results->signal_list();
    const int x = row_of(list, "body.x"), v = row_of(list, "body.v"), a = row_of(list, "body.a");
    QVERIFY(x >= 0 && v >= 0 && a >= 0);
    // After a run the first signal is shown alone, ticked.
    QCOMPARE(results->plotted(), std::vector<int>{0});
    QCOMPARE(list->item(0)->checkState(), Qt::Checked);
    if (x != 0) toggle(list, x);
    if (list->item(0)->checkState() == Qt::Checked && x != 0) toggle(list, 0);
    toggle(list, v);
    QCOMPARE(results->plotted(), (std::vector<int>{x, v}));
    QCOMPARE(list->item(v)->checkState(), Qt::Checked);

    QChart* chart = results->value_chart()->chart();
    QCOMPARE(chart->series().size(), 2);
    QLineSeries* sx = series_named(chart, "body.x");
    QLineSeries* sv = series_named(chart, "body.v");
    QVERIFY(sx && sv);
    QVERIFY(chart->legend()->isVisible());
    QCOMPARE(chart->legend()->markers().size(), 2);
    // One axis per unit: x on the left in m, v on the right in m/s.
    QCOMPARE(axis_title(chart, Qt::AlignLeft), QString("body.x [m]"));
    QCOMPARE(axis_title(chart, Qt::AlignRight), QString("body.v [m/s]"));
    QCOMPARE(sx->attachedAxes().size(), 2);
    QCOMPARE(chart->axes(Qt::Vertical, sx).front()->alignment(), Qt::AlignLeft);
    QCOMPARE(chart->axes(Qt::Vertical, sv).front()->alignment(), Qt::AlignRight);
    // The curves are the run's values.
    const auto& r = *outcome.result;
    QCOMPARE(sx->count(), static_cast<int>(r.t.size()));
    const int k = static_cast<int>(r.t.size()) / 2;
    QCOMPARE(sx->at(k).y(), r.value(k, x));
    QCOMPARE(sv->at(k).y(), r.value(k, v));
    // Their sensitivities overlaid too: three directions for each of the two signals.
    QCOMPARE(results->sensitivity_chart()->chart()->series().size(), 6);

    // A third unit has no axis: refused with the reason, nothing redrawn, the tick taken back.
    toggle(list, a);
    QCOMPARE(results->plotted(), (std::vector<int>{x, v}));
    QCOMPARE(list->item(a)->checkState(), Qt::Unchecked);
    QVERIFY2(results->plot_message().contains("body.a") && results->plot_message().contains("m/s^2"),
             qPrintable(results->plot_message()));
    QCOMPARE(chart->series().size(), 2);

    // Unticking v leaves x alone on one axis.
    toggle(list, v);
    QCOMPARE(results->plotted(), std::vector<int>{x});
    QCOMPARE(chart->series().size(), 1);
    QCOMPARE(chart->axes(Qt::Vertical).size(), 1);
    QVERIFY(results->plot_message().isEmpty());
  }
};

QTEST_MAIN(GuiPlots)
#include "test_gui_plots.moc"
