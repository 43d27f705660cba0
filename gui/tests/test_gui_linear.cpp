// The "Modes & FRF" tab: the sedan on its 4-poster (scenarios/fourposter_comfort.yaml, the pads
// held still) opened in the window, its modes computed on the worker thread and tabled, and the
// pad-to-body frequency response plotted; each compared with the engine's own modes and
// frequency_response computed here, apart from the GUI. A scene's initial state shown and edited
// in the Scene tab, the run starting where it says. A scene with no equilibrium in reach (a
// constant force on a mass without spring) shows the error and the window goes on working.
#include <QChart>
#include <QChartView>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>
#include <cmath>

#include "engine/linear/equilibrium.hpp"
#include "engine/linear/frequency_response.hpp"
#include "engine/linear/modes.hpp"
#include "gui/main_window.hpp"

using namespace dydp::gui;
namespace engine = dydp::engine;

namespace {

const QString kSedan = QString(DYDP_SCENARIOS_DIR) + "/fourposter_comfort.yaml";
constexpr double kDegrees = 57.29577951308232;

/// The sedan's equilibrium with the pads still, computed by the engine alone.
struct EngineSedan {
  engine::Diagram d = engine::load_scene(kSedan.toStdString());
  engine::Equilibrium eq;
  EngineSedan() {
    engine::EquilibriumOptions o;
    o.held = engine::held_signals(d, {"rig.zdot=0"}, "test");
    eq = engine::find_equilibrium(d, o);
  }
};

QLineSeries* series(QChart* chart, int k) {
  const auto all = chart->series();
  return k < all.size() ? qobject_cast<QLineSeries*>(all[k]) : nullptr;
}

bool near(double a, double b, double relative) { return std::fabs(a - b) <= relative * std::max(std::fabs(b), 1e-300); }

}  // namespace

class GuiLinear : public QObject {
  Q_OBJECT

 private slots:
  void modes_table_holds_the_engines_modes() {
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(kSedan, true));
    LinearPanel* panel = w.linear();
    panel->hold_field()->setText("rig.zdot=0");
    QSignalSpy ended(panel, &LinearPanel::analysis_ended);
    QVERIFY(w.start_modes());
    QVERIFY(panel->busy());
    QVERIFY(!w.start_run());  // the worker is busy with the analysis
    QVERIFY(ended.wait(120000));
    QCOMPARE(ended.takeFirst().at(0).toString(), QString());

    // The engine's modes about the same equilibrium, apart from the GUI.
    EngineSedan ref;
    const engine::LinearModel m = engine::linearize(ref.d, ref.eq.t, ref.eq.x, {}, {}, ref.eq.held);
    std::vector<engine::Mode> expected;
    for (const engine::Mode& mode : engine::modes(m))
      if (std::abs(mode.eigenvalue) >= 1e-3) expected.push_back(mode);
    QTableWidget* table = panel->modes_table();
    QCOMPARE(table->rowCount(), static_cast<int>(expected.size()));
    QVERIFY(table->rowCount() >= 10);
    // The first rows: the Wk filter's lowest pole (0.4 Hz), then the body's heave, pitch and roll
    // (docs/studies.md: 1.227, 1.329, 1.772 Hz).
    int body = 0, hop = 0;
    for (int row = 0; row < table->rowCount(); ++row) {
      const double f = table->item(row, 0)->data(Qt::UserRole).toDouble();
      const double zeta = table->item(row, 1)->data(Qt::UserRole).toDouble();
      QVERIFY2(near(f, expected[row].frequency_hz, 1e-9), qPrintable(QString("row %1: %2 Hz").arg(row).arg(f)));
      QVERIFY2(std::fabs(zeta - expected[row].damping_ratio) < 1e-9, qPrintable(QString("row %1").arg(row)));
      QCOMPARE(table->item(row, 0)->text(), QString::number(expected[row].frequency_hz, 'f', 3));
      QCOMPARE(table->item(row, 1)->text(), QString::number(expected[row].damping_ratio, 'f', 3));
      const QString name = table->item(row, 2)->text();
      if (name.startsWith("body ")) {
        const char* order[] = {"body heave", "body pitch", "body roll"};
        if (body < 3) {
          QCOMPARE(name, QString(order[body]));
          QVERIFY(f > 1.0 && f < 2.0);
        }
        ++body;
      }
      QVERIFY(table->item(row, 3)->text().startsWith(QString::fromStdString(expected[row].dominant.front().first)));
      if (name.startsWith("wheel hop")) {
        QVERIFY2(f > 10.0 && f < 25.0, qPrintable(name));
        ++hop;
      }
    }
    QCOMPARE(body, 3);
    QCOMPARE(hop, 4);  // one per corner: the rear trailing links, the front lower arms
    QVERIFY(panel->message().contains("eigenvalues below 1e-3"));
    QVERIFY(w.status_text().contains("modes of"));
  }

  void frf_plot_holds_the_engines_response() {
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(kSedan, true));
    LinearPanel* panel = w.linear();
    // The default choice: the pads' height with its rate, to the first logged signal.
    QCOMPARE(panel->input_box()->currentText(), QString("rig.z"));
    QCOMPARE(panel->rate_box()->currentText(), QString("rig.zdot"));
    QCOMPARE(panel->output_box()->currentText(), QString("car.body_acc_z"));
    panel->hold_field()->setText("rig.zdot=0");
    panel->points_box()->setValue(40);
    QSignalSpy ended(panel, &LinearPanel::analysis_ended);
    QVERIFY(w.start_frf());
    QVERIFY(ended.wait(120000));
    QCOMPARE(ended.takeFirst().at(0).toString(), QString());

    EngineSedan ref;
    const engine::LinearModel m =
        engine::linearize(ref.d, ref.eq.t, ref.eq.x, {"rig.z", "rig.zdot"}, {"car.body_acc_z"}, ref.eq.held);
    const std::vector<double> f = engine::log_frequencies(0.5, 30.0, 40);
    const engine::FrequencyResponse h = engine::frequency_response(m, {0, 1}, f);
    QChart* chart = panel->frf_chart()->chart();
    QLineSeries* magnitude = series(chart, 0);
    QLineSeries* phase = series(chart, 1);
    QVERIFY(magnitude && phase);
    QCOMPARE(magnitude->count(), 40);
    QCOMPARE(phase->count(), 40);
    for (int k = 0; k < 40; ++k) {
      QVERIFY2(near(magnitude->at(k).x(), f[k], 1e-12), qPrintable(QString::number(k)));
      QVERIFY2(near(magnitude->at(k).y(), std::abs(h.H[k][0]), 1e-9), qPrintable(QString("%1 Hz").arg(f[k])));
      QVERIFY2(std::fabs(phase->at(k).y() - std::arg(h.H[k][0]) * kDegrees) < 1e-7, qPrintable(QString("%1 Hz").arg(f[k])));
    }
    // Frequency and magnitude on log axes, the phase on the right in degrees.
    int logs = 0;
    for (QAbstractAxis* a : chart->axes())
      if (qobject_cast<QLogValueAxis*>(a)) ++logs;
    QCOMPARE(logs, 2);
    // Below the ride modes |a_z / z| rises as w^2: 11.8 1/s^2 at 0.5 Hz (docs/studies.md).
    QVERIFY(std::abs(h.H[0][0]) > 5.0 && std::abs(h.H[0][0]) < 20.0);

    // An output that does not exist: the error shown, the last plot kept.
    panel->output_box()->setCurrentText("car.no_such_signal");
    QVERIFY(w.start_frf());
    QVERIFY(ended.wait(120000));
    const QString error = ended.takeFirst().at(0).toString();
    QVERIFY2(error.contains("car.no_such_signal"), qPrintable(error));
    QCOMPARE(panel->error(), error);
    QCOMPARE(series(chart, 0)->count(), 40);
  }

  void initial_state_is_edited_in_the_scene_tab() {
    QTemporaryDir dir;
    const QString path = dir.filePath("still.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(R"(scene: still
time: {stop: 1.0, output_step: 0.1}
initial: {state: equilibrium, hold: {f.y: 2.0}}
blocks:
  m: {type: mass_spring_damper, k: 4.0, c: 1.0}
  f: {type: source.constant, value: 1.0}
connections: [f.y -> m.f]
outputs: [m.x]
)");
    f.close();
    MainWindow w;
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(path, true));
    auto* field = w.scene_panel()->findChild<QLineEdit*>("scene_initial");
    QVERIFY(field);
    QTRY_COMPARE(field->text(), QString("{state: equilibrium, hold: {f.y: 2.0}}"));  // refreshed queued
    // The run starts at the equilibrium with f.y held at 2 N: x = 0.5 m from t = 0 (then the
    // force is 1 N and the mass moves toward 0.25 m).
    QSignalSpy run(&w, &MainWindow::run_ended);
    QVERIFY(w.start_run());
    QVERIFY(run.wait(60000));
    RunOutcome outcome = run.takeFirst().at(0).value<RunOutcome>();
    QVERIFY(outcome.status == RunOutcome::Status::finished);
    QCOMPARE(outcome.result->value(0, 0), 0.5);
    // Edited in the Scene tab: `declared` starts at the block's x0 = 0.
    field->setText("declared");
    QMetaObject::invokeMethod(field, "editingFinished");
    QCOMPARE(QString::fromStdString(w.controller()->document().initial), QString("declared"));
    QVERIFY(w.start_run());
    QVERIFY(run.wait(60000));
    outcome = run.takeFirst().at(0).value<RunOutcome>();
    QVERIFY(outcome.status == RunOutcome::Status::finished);
    QCOMPARE(outcome.result->value(0, 0), 0.0);
    // Not YAML: refused, the document unchanged.
    field->setText("{state: [");
    QMetaObject::invokeMethod(field, "editingFinished");
    QCOMPARE(QString::fromStdString(w.controller()->document().initial), QString("declared"));
    // Undo brings the equilibrium back.
    w.controller()->undo_stack()->undo();
    QCOMPARE(QString::fromStdString(w.controller()->document().initial), QString("{state: equilibrium, hold: {f.y: 2.0}}"));
  }

  void scene_without_equilibrium_shows_the_error() {
    QTemporaryDir dir;
    const QString path = dir.filePath("falling.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(R"(scene: falling
time: {stop: 1.0, output_step: 0.1}
blocks:
  m: {type: mass_spring_damper, k: 0.0, c: 0.0}
  f: {type: source.constant, value: 1.0}
connections: [f.y -> m.f]
outputs: [m.x]
)");
    f.close();
    MainWindow w;
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(path, true));
    QSignalSpy ended(w.linear(), &LinearPanel::analysis_ended);
    QVERIFY(w.start_modes());
    QVERIFY(ended.wait(60000));
    const QString error = ended.takeFirst().at(0).toString();
    QVERIFY2(error.contains("no equilibrium in reach"), qPrintable(error));
    QCOMPARE(w.linear()->message(), error);
    QCOMPARE(w.linear()->modes_table()->rowCount(), 0);
    QVERIFY(w.status_text().contains("no equilibrium in reach"));
    // The window goes on: the scene still runs.
    QSignalSpy run(&w, &MainWindow::run_ended);
    QVERIFY(w.start_run());
    QVERIFY(run.wait(60000));
    QVERIFY(run.takeFirst().at(0).value<RunOutcome>().status == RunOutcome::Status::finished);
  }
};

QTEST_MAIN(GuiLinear)
#include "test_gui_linear.moc"
