// The GUI driven as a user drives it, by synthesised mouse and keyboard events on the real
// widgets: two blocks dragged from the palette onto the canvas (the palette's own drag data
// delivered as drag-enter, drag-move and drop events), a wire dragged from port to port with
// the mouse, a value typed into the property table, a parameter made a sensitivity direction
// with the mouse, F5, and psi and dpsi/dp read from the objectives table against the closed form.
#include <QDropEvent>
#include <QLineEdit>
#include <QMimeData>
#include <QSignalSpy>
#include <QStatusBar>
#include <QtTest>

#include "gui/main_window.hpp"

using namespace dydp::gui;

namespace {

/// Drags palette entry `type` to `at` (viewport coordinates of the canvas) and drops it.
void drag_from_palette(MainWindow& w, const QString& type, QPoint at) {
  QTreeWidgetItem* entry = w.palette()->entry(type);
  QVERIFY2(entry, qPrintable(type));
  std::unique_ptr<QMimeData> data(w.palette()->drag_data(entry));
  QVERIFY(data);
  QWidget* target = w.canvas()->viewport();
  QDragEnterEvent enter(at, Qt::CopyAction, data.get(), Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(target, &enter);
  QVERIFY(enter.isAccepted());
  QDragMoveEvent move(at, Qt::CopyAction, data.get(), Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(target, &move);
  QDropEvent drop(QPointF(at), Qt::CopyAction, data.get(), Qt::LeftButton, Qt::NoModifier);
  QApplication::sendEvent(target, &drop);
  QVERIFY(drop.isAccepted());
}

QPoint port_in_view(Canvas* canvas, const std::string& block, const std::string& port, bool input) {
  return canvas->mapFromScene(canvas->block_item(block)->port(port, input)->anchor());
}

QPoint cell_centre(QTableWidget* table, int row, int column) {
  return table->visualItemRect(table->item(row, column)).center();
}

int row_of(QTableWidget* table, const QString& key) {
  for (int row = 0; row < table->rowCount(); ++row)
    if (table->item(row, 0) && table->item(row, 0)->text() == key) return row;
  return -1;
}



}  // namespace

class GuiMouse : public QObject {
  Q_OBJECT

 private slots:
  // source.constant (value v) -> objective.integral over the run [0, 10] s: psi = 10 s * v,
  // dpsi/dv = 10 s, for v = 1.5 typed into the property table.
  void build_wire_direction_run_and_read_the_table() {
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    Canvas* canvas = w.canvas();
    const QRect view = canvas->viewport()->rect();
    drag_from_palette(w, "source.constant", view.center() - QPoint(250, 0));
    drag_from_palette(w, "objective.integral", view.center() + QPoint(100, 0));
    QVERIFY(canvas->block_item("constant"));
    QVERIFY(canvas->block_item("integral"));
    // A new objective is computed by default.
    QCOMPARE(w.controller()->document().outputs, std::vector<std::string>{"integral"});

    // A wire dragged with the mouse from the constant's output to the objective's input.
    QWidget* vp = canvas->viewport();
    const QPoint from = port_in_view(canvas, "constant", "y", false);
    const QPoint to = port_in_view(canvas, "integral", "in", true);
    QTest::mousePress(vp, Qt::LeftButton, {}, from);
    QTest::mouseMove(vp, (from + to) / 2);
    QTest::mouseMove(vp, to);
    QTest::mouseRelease(vp, Qt::LeftButton, {}, to);
    QCOMPARE(canvas->wire_count(), 1);
    QCOMPARE(w.controller()->document().connections.front().text(), std::string("constant.y -> integral.in"));

    // Select the constant with a click, type its value into the table.
    QTest::mouseClick(vp, Qt::LeftButton, {}, canvas->mapFromScene(canvas->block_item("constant")->sceneBoundingRect().center()));
    QCOMPARE(w.property_editor()->block(), QString("constant"));
    QTest::qWait(50);  // the editor's table is refilled after each edit (queued): let that happen
    QTableWidget* table = w.property_editor()->table();
    const int value_row = row_of(table, "value");
    QVERIFY(value_row >= 0);
    // Click the value cell, F2 opens its editor.
    QTest::mouseClick(table->viewport(), Qt::LeftButton, {}, cell_centre(table, value_row, 1));
    QCOMPARE(table->currentRow(), value_row);
    QTest::qWait(50);
    QTest::keyClick(table, Qt::Key_F2);
    auto* editor = qobject_cast<QLineEdit*>(table->indexWidget(table->currentIndex()));
    QVERIFY2(editor && editor->isVisible(), "F2 on the value cell opens its editor");
    editor->selectAll();
    QTest::keyClicks(editor, "1.5");
    QTest::keyClick(editor, Qt::Key_Return);
    QApplication::processEvents();
    const SceneValue* typed = w.controller()->document().find_block("constant")->find("value");
    QVERIFY2(typed, "the typed value reached the document");
    QCOMPARE(QString::fromStdString(typed->text()), QString("1.5"));

    // The parameter row selected with the mouse, then "Make direction": one step.
    QApplication::processEvents();
    const int row = row_of(table, "value");
    QTest::mouseClick(table->viewport(), Qt::LeftButton, {}, cell_centre(table, row, 0));
    QTest::mouseClick(w.property_editor()->make_direction_button(), Qt::LeftButton);
    const SceneDocument& doc = w.controller()->document();
    QCOMPARE(doc.sensitivities, std::vector<std::string>{"constant_value"});
    QVERIFY(doc.find_parameter("constant_value"));
    QCOMPARE(QString::fromStdString(doc.find_parameter("constant_value")->value), QString("1.5"));
    QCOMPARE(QString::fromStdString(doc.find_block("constant")->find("value")->text()), QString("$constant_value"));

    // F5 runs; the table shows psi and dpsi/dp with every digit and the units.
    QSignalSpy ended(&w, &MainWindow::run_ended);
    QTest::keyClick(&w, Qt::Key_F5);
    QVERIFY(ended.wait(60000));
    QTableWidget* objectives = w.results()->objectives();
    const int psi_row = w.results()->find_row("integral", "ψ");
    const int sens_row = w.results()->find_row("integral", "dψ/dconstant_value");
    QVERIFY(psi_row >= 0 && sens_row >= 0);
    bool ok = false;
    const double psi = objectives->item(psi_row, 2)->text().toDouble(&ok);
    QVERIFY(ok);
    const double dpsi = objectives->item(sens_row, 2)->text().toDouble(&ok);
    QVERIFY(ok);
    QVERIFY2(std::abs(psi - 15.0) < 1e-9, qPrintable(objectives->item(psi_row, 2)->text()));
    QVERIFY2(std::abs(dpsi - 10.0) < 1e-9, qPrintable(objectives->item(sens_row, 2)->text()));
    QCOMPARE(objectives->item(psi_row, 3)->text(), QString("s"));
    // The text is the value to the last digit: read back, it is the number the engine computed.
    QCOMPARE(objectives->item(psi_row, 2)->text().toDouble(), ended.takeFirst().at(0).value<RunOutcome>().result->objectives.front().value);
  }

  // A diagram with nothing to compute says where outputs are ticked; the message goes once
  // the diagram is edited.
  void first_run_says_where_to_tick_outputs_and_the_message_clears() {
    MainWindow w;
    w.resize(1200, 800);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    drag_from_palette(w, "source.sine", w.canvas()->viewport()->rect().center());
    QTest::keyClick(&w, Qt::Key_F5);
    const QString said = w.status_text();
    QVERIFY2(said.contains("Logged outputs") && said.contains("Block tab"), qPrintable(said));
    drag_from_palette(w, "source.constant", w.canvas()->viewport()->rect().center() + QPoint(0, 150));
    QVERIFY2(!w.status_text().contains("Logged outputs"), qPrintable(w.status_text()));
  }
};

QTEST_MAIN(GuiMouse)
#include "test_gui_mouse.moc"
