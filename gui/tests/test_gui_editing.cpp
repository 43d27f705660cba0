// Scenes built in the GUI by the calls a drag makes (palette drop, port-to-port wire, property
// edits), saved, reopened and run in the worker thread; refusals with reasons; undo and redo;
// validation errors marked on their block; cancelling a run.
#include <QChart>
#include <QChartView>
#include <QMimeData>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>

#include "engine/scene/scene_keys.hpp"
#include "gui/main_window.hpp"
#include "gui/scene_controller.hpp"

using namespace dydp::gui;

namespace {

PortRef port(const char* block, const char* name) { return {block, name}; }

/// Runs the window's scene and waits for the outcome.
RunOutcome run_and_wait(MainWindow& w) {
  QSignalSpy ended(&w, &MainWindow::run_ended);
  if (!w.start_run()) return {};
  if (!ended.wait(120000)) return {};
  return ended.takeFirst().at(0).value<RunOutcome>();
}

/// constant ($v) -> integrator -> objective.final over [0, 2]: psi = 2 v, dpsi/dv = 2.
void build_ramp_scene(MainWindow& w) {
  Canvas* canvas = w.canvas();
  SceneController* c = w.controller();
  QCOMPARE(canvas->drop_block("source.constant", {0, 0}), QString("constant"));
  QCOMPARE(canvas->drop_block("math.integrator", {260, 0}), QString("integrator"));
  QCOMPARE(canvas->drop_block("objective.final", {520, 0}), QString("final"));
  QCOMPARE(c->add_scene_parameter("v", "1.5"), QString());
  QCOMPARE(c->set_block_value("constant", "value", "$v"), QString());
  // One wire dragged output -> input, the other input -> output: both wire output -> input.
  QCOMPARE(canvas->wire(port("constant", "y"), false, port("integrator", "u"), true), QString());
  QCOMPARE(canvas->wire(port("final", "in"), true, port("integrator", "y"), false), QString());
  c->set_output("final", true);
  c->set_output("integrator.y", true);
  c->set_sensitivity("v", true);
  QCOMPARE(c->set_time("stop", "2.0"), QString());
}

}  // namespace

class GuiEditing : public QObject {
  Q_OBJECT

 private slots:
  // Every key of `solver:` can be set from the scene panel; the switches take true or false,
  // refresh_local_jacobians and nominal_scaling included (they were read as numbers).
  void every_solver_key_is_set_and_switches_take_true_or_false() {
    dydp::gui::SceneController c;
    c.new_scene();
    for (const char* key : dydp::engine::kSolverSwitches) {
      QCOMPARE(c.set_solver(key, "false"), QString());
      QVERIFY(c.set_solver(key, "0.5").contains("expected true or false"));
    }
    QCOMPARE(c.set_solver("max_order", "3"), QString());
    QCOMPARE(c.set_solver("newton_coefficient", "0.25"), QString());
    QVERIFY(c.set_solver("newton_coefficient", "false").contains("malformed number"));
    for (const char* key : {"sens_error_test", "nominal_scaling", "refresh_local_jacobians"})
      QCOMPARE(QString::fromStdString(*dydp::gui::find_field(c.document().solver, key)), QString("false"));
    QCOMPARE(QString::fromStdString(*dydp::gui::find_field(c.document().solver, "max_order")), QString("3"));
  }

  void palette_lists_every_registered_type_in_sections() {
    MainWindow w;
    const QStringList sections = w.palette()->sections();
    QVERIFY(sections.contains("Sources"));
    QVERIFY(sections.contains("Objectives"));
    QVERIFY(sections.contains("Math"));
    QVERIFY(sections.indexOf("Sources") < sections.indexOf("Objectives"));
    int entries = 0;
    for (int i = 0; i < w.palette()->topLevelItemCount(); ++i) entries += w.palette()->topLevelItem(i)->childCount();
    QCOMPARE(entries, static_cast<int>(dydp::engine::Registry::global().all().size()));
  }

  void build_save_reopen_run() {
    QTemporaryDir dir;
    const QString path = dir.filePath("ramp.yaml");
    {
      MainWindow w;
      build_ramp_scene(w);
      QCOMPARE(w.canvas()->wire_count(), 2);
      QVERIFY(w.canvas()->block_item("integrator") != nullptr);
      QVERIFY(w.save_file(path));
    }
    MainWindow w;
    QVERIFY(w.open_file(path, true));
    QCOMPARE(w.canvas()->wire_count(), 2);
    const DocBlock* b = w.controller()->document().find_block("integrator");
    QVERIFY(b);
    QCOMPARE(b->x, 260.0);
    QCOMPARE(QString::fromStdString(w.controller()->document().find_block("constant")->find("value")->text()),
             QString("$v"));
    const RunOutcome out = run_and_wait(w);
    QVERIFY2(out.status == RunOutcome::Status::finished, out.message.toUtf8().constData());
    QCOMPARE(out.result->objectives.size(), size_t(1));
    const auto& psi = out.result->objectives.front();
    QCOMPARE(QString::fromStdString(psi.name), QString("final"));
    QVERIFY(std::abs(psi.value - 3.0) < 1e-6);            // 2 s * 1.5
    QVERIFY(std::abs(psi.sensitivity.at(0) - 2.0) < 1e-6);  // d/dv
    QCOMPARE(w.results()->objectives()->rowCount(), 2);  // psi and dpsi/dv
    QCOMPARE(w.results()->objectives()->item(0, 0)->text(), QString("final"));
    QCOMPARE(w.results()->find_row("final", "dψ/dv"), 1);
    QCOMPARE(w.progress_bar()->value(), 1000);

    // An edit that is not saved yet runs too (from a temporary copy of the document).
    QCOMPARE(w.controller()->update_scene_parameter("v", {"v", "4.0", "", "", "", ""}), QString());
    const RunOutcome edited = run_and_wait(w);
    QVERIFY(edited.status == RunOutcome::Status::finished);
    QVERIFY(std::abs(edited.result->objectives.front().value - 8.0) < 1e-6);
    // The plot keeps the previous run beside the new one, for comparison.
    const QList<QAbstractSeries*> series = w.results()->value_chart()->chart()->series();
    QCOMPARE(series.size(), 2);
    QVERIFY(series.at(1)->name().endsWith("(previous run)"));
  }

  void wires_with_mismatches_are_refused_with_the_reason() {
    MainWindow w;
    Canvas* canvas = w.canvas();
    SceneController* c = w.controller();
    canvas->drop_block("source.constant", {0, 0});
    canvas->drop_block("math.gain", {260, 0});
    canvas->drop_block("source.sine", {0, 200});
    QCOMPARE(c->set_block_value("gain", "width", "3"), QString());
    const int steps = c->undo_stack()->count();

    const QString width = canvas->wire(port("constant", "y"), false, port("gain", "u"), true);
    QVERIFY2(width.contains("width mismatch"), width.toUtf8().constData());
    QVERIFY(width.contains("3"));
    const QString outputs = canvas->wire(port("constant", "y"), false, port("sine", "y"), false);
    QVERIFY2(outputs.contains("is an output"), outputs.toUtf8().constData());
    QVERIFY(c->check_connection("gain.u", "gain.y").contains("is an input"));
    QVERIFY(c->check_connection("constant.nope", "gain.u").contains("no output 'nope'"));
    QCOMPARE(canvas->wire_count(), 0);
    QCOMPARE(c->undo_stack()->count(), steps);

    QCOMPARE(c->set_block_value("gain", "width", ""), QString());
    QCOMPARE(canvas->wire(port("constant", "y"), false, port("gain", "u"), true), QString());
    const QString twice = canvas->wire(port("sine", "y"), false, port("gain", "u"), true);
    QVERIFY2(twice.contains("already driven by constant.y"), twice.toUtf8().constData());
    QCOMPARE(canvas->wire_count(), 1);
  }

  void parameters_are_checked_against_bounds_and_scene_parameters() {
    MainWindow w;
    SceneController* c = w.controller();
    w.canvas()->drop_block("source.sine", {0, 0});
    QVERIFY(c->set_block_value("sine", "frequency", "-1").contains("outside"));
    QVERIFY(c->set_block_value("sine", "frequency", "abc").contains("malformed"));
    QVERIFY(c->set_block_value("sine", "frequency", "$nope").contains("unknown scene parameter"));
    QVERIFY(c->set_block_value("sine", "nope", "1").contains("unknown parameter"));
    QCOMPARE(c->set_block_value("sine", "frequency", "2.5"), QString());
    // The property editor goes through the same call and reverts a refused value.
    w.property_editor()->set_block("sine");
    QVERIFY(!w.property_editor()->edit_value("amplitude", "x").isEmpty());
    QCOMPARE(w.property_editor()->edit_value("amplitude", "4"), QString());
    QCOMPARE(QString::fromStdString(c->document().find_block("sine")->find("amplitude")->text()), QString("4"));
    QCOMPARE(QString::fromStdString(c->document().find_block("sine")->find("frequency")->text()), QString("2.5"));
  }

  void a_setting_that_changes_ports_drops_the_wires_they_break() {
    MainWindow w;
    SceneController* c = w.controller();
    w.canvas()->drop_block("source.constant", {0, 0});
    w.canvas()->drop_block("math.gain", {260, 0});
    QCOMPARE(c->connect_ports("constant.y", "gain.u"), QString());
    c->set_output("gain.y", true);
    QCOMPARE(c->set_block_value("gain", "width", "2"), QString());
    QCOMPARE(w.canvas()->wire_count(), 0);
    QCOMPARE(c->document().outputs.size(), size_t(1));  // gain.y still exists (width 2)
    QCOMPARE(w.canvas()->block_item("gain")->port("u", true)->width(), 2);
    c->undo_stack()->undo();
    QCOMPARE(w.canvas()->wire_count(), 1);
    QCOMPARE(w.canvas()->block_item("gain")->port("u", true)->width(), 1);
  }

  void undo_and_redo_of_add_move_delete_rename() {
    MainWindow w;
    SceneController* c = w.controller();
    Canvas* canvas = w.canvas();
    canvas->drop_block("source.constant", {0, 0});
    canvas->drop_block("math.gain", {260, 0});
    QCOMPARE(c->connect_ports("constant.y", "gain.u"), QString());
    c->move_block("gain", {400, 120});
    QCOMPARE(canvas->block_item("gain")->pos(), QPointF(400, 120));
    QCOMPARE(c->rename_block("gain", "amplifier"), QString());
    QVERIFY(c->rename_block("amplifier", "bad name").contains("without"));
    QCOMPARE(QString::fromStdString(c->document().connections.front().text()), QString("constant.y -> amplifier.u"));
    canvas->select_block("constant");
    canvas->delete_selection();
    QCOMPARE(c->document().blocks.size(), size_t(1));
    QCOMPARE(canvas->wire_count(), 0);
    QVERIFY(canvas->block_item("constant") == nullptr);

    c->undo_stack()->undo();  // delete
    QCOMPARE(canvas->wire_count(), 1);
    QVERIFY(canvas->block_item("constant") != nullptr);
    c->undo_stack()->undo();  // rename
    QVERIFY(canvas->block_item("gain") != nullptr);
    c->undo_stack()->undo();  // move
    QCOMPARE(canvas->block_item("gain")->pos(), QPointF(260, 0));
    c->undo_stack()->redo();
    QCOMPARE(canvas->block_item("gain")->pos(), QPointF(400, 120));
    while (c->undo_stack()->canUndo()) c->undo_stack()->undo();
    QVERIFY(c->document().blocks.empty());
    while (c->undo_stack()->canRedo()) c->undo_stack()->redo();
    QCOMPARE(c->document().blocks.size(), size_t(1));
  }

  void validation_errors_are_shown_on_the_block() {
    MainWindow w;
    Canvas* canvas = w.canvas();
    SceneController* c = w.controller();
    canvas->drop_block("source.constant", {0, 0});
    canvas->drop_block("math.integrator", {260, 0});
    c->set_output("integrator.y", true);  // integrator.u is not driven
    QVERIFY(!w.start_run());
    QVERIFY2(w.last_error().contains("integrator.u"), w.last_error().toUtf8().constData());
    QVERIFY(canvas->block_item("integrator")->has_error());
    QVERIFY(!canvas->block_item("constant")->has_error());
    QCOMPARE(canvas->selected_blocks(), QStringList{"integrator"});
    // Fixing the scene clears the mark and the run goes through.
    QCOMPARE(c->connect_ports("constant.y", "integrator.u"), QString());
    QVERIFY(!canvas->block_item("integrator")->has_error());
    const RunOutcome out = run_and_wait(w);
    QVERIFY(out.status == RunOutcome::Status::finished);
  }

  void an_algebraic_loop_marks_its_blocks() {
    MainWindow w;
    SceneController* c = w.controller();
    w.canvas()->drop_block("math.sum", {0, 0});
    w.canvas()->drop_block("math.gain", {260, 0});
    w.canvas()->drop_block("source.constant", {-260, 0});
    QCOMPARE(c->connect_ports("constant.y", "sum.in1"), QString());
    QCOMPARE(c->connect_ports("sum.y", "gain.u"), QString());
    QCOMPARE(c->connect_ports("gain.y", "sum.in2"), QString());
    c->set_output("gain.y", true);
    QVERIFY(!w.start_run());
    QVERIFY(w.last_error().contains("algebraic loop"));
    QVERIFY(w.canvas()->block_item("sum")->has_error());
    QVERIFY(w.canvas()->block_item("gain")->has_error());
    QVERIFY(!w.canvas()->block_item("constant")->has_error());
  }

  void mouse_drags_wire_ports_and_move_blocks() {
    MainWindow w;
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    Canvas* canvas = w.canvas();
    SceneController* c = w.controller();
    canvas->drop_block("source.constant", {0, 0});
    canvas->drop_block("math.gain", {260, 0});
    canvas->resetTransform();
    canvas->centerOn(200, 40);
    QWidget* vp = canvas->viewport();
    auto at = [&](PortItem* p) { return canvas->mapFromScene(p->anchor()); };
    // Output to output: refused, nothing wired.
    PortItem* y = canvas->block_item("constant")->port("y", false);
    PortItem* gy = canvas->block_item("gain")->port("y", false);
    QTest::mousePress(vp, Qt::LeftButton, {}, at(y));
    QTest::mouseMove(vp, at(gy));
    QTest::mouseRelease(vp, Qt::LeftButton, {}, at(gy));
    QCOMPARE(canvas->wire_count(), 0);
    // Output to input: wired.
    PortItem* u = canvas->block_item("gain")->port("u", true);
    QTest::mousePress(vp, Qt::LeftButton, {}, at(y));
    QTest::mouseMove(vp, at(u));
    QTest::mouseRelease(vp, Qt::LeftButton, {}, at(u));
    QCOMPARE(canvas->wire_count(), 1);
    QCOMPARE(QString::fromStdString(c->document().connections.front().text()), QString("constant.y -> gain.u"));
    // Dragging a block by its header moves it, as one undo step.
    const int steps = c->undo_stack()->count();
    const QPoint header = canvas->mapFromScene(QPointF(330, 10));
    QTest::mousePress(vp, Qt::LeftButton, {}, header);
    QTest::mouseMove(vp, header + QPoint(20, 30));
    QTest::mouseMove(vp, header + QPoint(40, 60));
    QTest::mouseRelease(vp, Qt::LeftButton, {}, header + QPoint(40, 60));
    const DocBlock* gain = c->document().find_block("gain");
    QVERIFY2(gain->x > 260.0 && gain->y > 0.0, QString("%1, %2").arg(gain->x).arg(gain->y).toUtf8().constData());
    QCOMPARE(c->undo_stack()->count(), steps + 1);
    c->undo_stack()->undo();
    QCOMPARE(c->document().find_block("gain")->x, 260.0);

    // A palette entry dropped on the canvas: the mime data the palette makes, delivered as a drop.
    QTreeWidgetItem* sine = nullptr;
    for (int i = 0; i < w.palette()->topLevelItemCount() && !sine; ++i)
      for (int k = 0; k < w.palette()->topLevelItem(i)->childCount(); ++k)
        if (w.palette()->topLevelItem(i)->child(k)->text(0) == "source.sine") sine = w.palette()->topLevelItem(i)->child(k);
    QVERIFY(sine);
    std::unique_ptr<QMimeData> mime(w.palette()->model()->mimeData({w.palette()->indexFromItem(sine)}));
    QVERIFY(mime && mime->hasFormat(kBlockTypeMime));
    const QPoint drop = canvas->mapFromScene(QPointF(100, 200));
    QDragEnterEvent enter(drop, Qt::CopyAction, mime.get(), Qt::LeftButton, {});
    QApplication::sendEvent(vp, &enter);
    QVERIFY(enter.isAccepted());
    QDropEvent dropped(QPointF(drop), Qt::CopyAction, mime.get(), Qt::LeftButton, {});
    QApplication::sendEvent(vp, &dropped);
    const DocBlock* added = c->document().find_block("sine");
    QVERIFY(added);
    QVERIFY(std::abs(added->x - 100) <= 1 && std::abs(added->y - 200) <= 1);
    QCOMPARE(canvas->selected_blocks(), QStringList{"sine"});
  }

  void a_run_can_be_cancelled_and_run_again() {
    MainWindow w;
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/msd_sensitivity.yaml", true));
    // Long enough that the run is still going when the first progress report arrives.
    QCOMPARE(w.controller()->set_time("stop", "20000.0"), QString());
    QSignalSpy ended(&w, &MainWindow::run_ended);
    QSignalSpy progress(w.worker(), &RunWorker::progress);
    QVERIFY(w.start_run());
    QVERIFY(w.worker()->running());
    QVERIFY(progress.wait(60000));
    w.worker()->cancel();
    QVERIFY(ended.wait(60000));
    const RunOutcome out = ended.takeFirst().at(0).value<RunOutcome>();
    QVERIFY(out.status == RunOutcome::Status::cancelled);
    QVERIFY(!w.worker()->running());

    QCOMPARE(w.controller()->set_time("stop", "10.0"), QString());
    const RunOutcome again = run_and_wait(w);
    QVERIFY(again.status == RunOutcome::Status::finished);
    QCOMPARE(again.result->objectives.front().sensitivity.size(), size_t(3));
    QCOMPARE(w.results()->objectives()->rowCount(), 4);  // psi and three directions, one row each
    for (const char* p : {"mass", "stiffness", "damping"})
      QVERIFY(w.results()->find_row("x_rms", QString("dψ/d") + p) >= 0);
  }
};

QTEST_MAIN(GuiEditing)
#include "test_gui_editing.moc"
