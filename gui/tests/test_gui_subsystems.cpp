// Subsystems made and edited in the GUI. Blocks selected on the canvas with the mouse and
// grouped with Ctrl+G become one instance of a new inline definition; the scene saved, loaded
// by the engine and run gives the objectives and their sensitivities of the scene before
// grouping; undo restores it. Inside the opened instance a block dragged with the mouse and a
// value typed into the Block tab are written to the definition, saved, and read back by the
// engine. The same grouping of the quarter car's tyre and damper (wires crossing the boundary
// both ways, through the car's loop, scene parameters passed through) runs alike.
#include <QLineEdit>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QtTest>
#include <cmath>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "gui/main_window.hpp"

using namespace dydp::gui;
namespace engine = dydp::engine;

namespace {

QPoint centre_of(Canvas* canvas, const std::string& block) {
  BlockItem* b = canvas->block_item(block);
  return b ? canvas->mapFromScene(QPointF(b->sceneBoundingRect().center().x(), b->sceneBoundingRect().top() + 10))
           : QPoint();
}

/// Objective name -> {psi, dpsi/dp...} of a run of the scene at path.
std::map<std::string, std::vector<double>> objectives_of(const std::string& path) {
  const engine::Diagram d = engine::load_scene(path);
  const engine::RunResult r = engine::run(d);
  std::map<std::string, std::vector<double>> out;
  for (const auto& o : r.objectives) {
    std::vector<double> v{o.value};
    v.insert(v.end(), o.sensitivity.begin(), o.sensitivity.end());
    out[o.name] = v;
  }
  return out;
}

/// Every objective of `before` is in `after` under `prefix` + its name, with the same values.
QString compare_objectives(const std::map<std::string, std::vector<double>>& before,
                           const std::map<std::string, std::vector<double>>& after, const std::string& prefix,
                           double relative) {
  if (before.size() != after.size()) return "objective count differs";
  for (const auto& [name, values] : before) {
    const auto it = after.count(name) ? after.find(name) : after.find(prefix + name);
    if (it == after.end()) return QString::fromStdString("no objective " + name + " after grouping");
    if (it->second.size() != values.size()) return QString::fromStdString(name + ": direction count differs");
    for (size_t k = 0; k < values.size(); ++k)
      if (std::abs(it->second[k] - values[k]) > relative * std::max(1e-12, std::abs(values[k])))
        return QString("%1[%2]: %3 before, %4 after").arg(QString::fromStdString(name)).arg(k)
            .arg(values[k], 0, 'g', 17).arg(it->second[k], 0, 'g', 17);
  }
  return {};
}

int row_of(QTableWidget* table, const QString& key) {
  for (int row = 0; row < table->rowCount(); ++row)
    if (table->item(row, 0) && table->item(row, 0)->text() == key) return row;
  return -1;
}

}  // namespace

class GuiSubsystems : public QObject {
  Q_OBJECT

 private slots:
  // msd_sensitivity: the force and the body selected with the mouse (click, Ctrl+click) and
  // grouped by Ctrl+G. The wire body.x -> x_rms.in crosses out: output port body_x; force -> body
  // stays inside; $mass, $stiffness, $damping become the definition's parameters.
  void group_selection_with_the_mouse_save_and_run() {
    const std::string scene = std::string(DYDP_SCENARIOS_DIR) + "/msd_sensitivity.yaml";
    QTemporaryDir dir;
    const QString saved = dir.filePath("grouped.yaml");
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(QString::fromStdString(scene), true));
    Canvas* canvas = w.canvas();
    canvas->fit_all();
    QApplication::processEvents();
    const SceneDocument before = w.controller()->document();
    QTest::mouseClick(canvas->viewport(), Qt::LeftButton, {}, centre_of(canvas, "force"));
    QTest::mouseClick(canvas->viewport(), Qt::LeftButton, Qt::ControlModifier, centre_of(canvas, "body"));
    QCOMPARE(canvas->selected_blocks().size(), 2);
    QTest::keyClick(&w, Qt::Key_G, Qt::ControlModifier);

    const SceneDocument& doc = w.controller()->document();
    QVERIFY2(!doc.find_block("force") && !doc.find_block("body"), qPrintable(w.status_text()));
    const DocBlock* instance = doc.find_block("group");
    QVERIFY(instance);
    QCOMPARE(QString::fromStdString(instance->type), QString("subsystem.group"));
    QCOMPARE(QString::fromStdString(instance->find("mass")->text()), QString("$mass"));
    const DocSubsystem* def = doc.find_subsystem("group");
    QVERIFY(def && def->file.empty());
    QCOMPARE(def->blocks.size(), size_t{2});
    QCOMPARE(def->connections.size(), size_t{1});  // force.y -> body.f stays inside
    QVERIFY(def->inputs.empty());
    QCOMPARE(def->outputs.size(), size_t{1});
    QCOMPARE(QString::fromStdString(def->outputs.front().second), QString("body.x"));
    QCOMPARE(doc.connections.size(), size_t{1});
    QCOMPARE(QString::fromStdString(doc.connections.front().text()), QString("group.body_x -> x_rms.in"));
    // Logged signals of the blocks inside are logged through the instance.
    QVERIFY(std::find(doc.outputs.begin(), doc.outputs.end(), "group.body.x") != doc.outputs.end());
    QCOMPARE(canvas->selected_blocks(), QStringList{"group"});
    QVERIFY(canvas->block_item("group")->port("body_x", false));

    QVERIFY(w.save_file(saved));
    const QString faults = compare_objectives(objectives_of(scene), objectives_of(saved.toStdString()), "group.", 1e-12);
    QVERIFY2(faults.isEmpty(), qPrintable(faults));
    // The definition is written inline in the scene's subsystems: section.
    QFile file(saved);
    QVERIFY(file.open(QIODevice::ReadOnly));
    const QString text = QString::fromUtf8(file.readAll());
    QVERIFY2(text.contains("subsystems:\n  group:\n"), qPrintable(text));
    QVERIFY(!text.contains("file:"));

    // One undo step brings the scene back as it was.
    QTest::keyClick(&w, Qt::Key_Z, Qt::ControlModifier);
    QVERIFY(w.controller()->document() == before);
    QVERIFY(canvas->block_item("force"));
  }

  // Inside the new subsystem: the body dragged with the mouse and its damping typed into the
  // Block tab; both reach the inline definition, the file and the engine.
  void edit_inside_the_opened_subsystem() {
    QTemporaryDir dir;
    const QString saved = dir.filePath("edited.yaml");
    MainWindow w;
    w.resize(1500, 950);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/msd_sensitivity.yaml", true));
    SceneController* c = w.controller();
    QCOMPARE(c->group_into_subsystem({"force", "body"}), QString());
    Canvas* canvas = w.canvas();
    canvas->fit_all();
    QApplication::processEvents();
    QTest::mouseDClick(canvas->viewport(), Qt::LeftButton, {}, centre_of(canvas, "group"));
    QCOMPARE(canvas->level(), QStringList{"group"});
    QVERIFY(canvas->level_editable());
    QVERIFY(!w.breadcrumb()->text().contains("read only"));

    // Drag the body by (120, 80) in scene units.
    const DocBlock start = *c->document().find_subsystem("group")->find_block("body");
    canvas->resetTransform();
    canvas->centerOn(canvas->block_item("body"));
    QApplication::processEvents();
    QWidget* vp = canvas->viewport();
    const QPoint grab = centre_of(canvas, "body");
    QTest::mousePress(vp, Qt::LeftButton, {}, grab);
    QTest::mouseMove(vp, grab + QPoint(60, 40));
    QTest::mouseMove(vp, grab + QPoint(120, 80));
    QTest::mouseRelease(vp, Qt::LeftButton, {}, grab + QPoint(120, 80));
    const DocBlock* moved = c->document().find_subsystem("group")->find_block("body");
    QCOMPARE(moved->x - start.x, 120.0);
    QCOMPARE(moved->y - start.y, 80.0);
    QCOMPARE(c->undo_stack()->undoText(), QString("Move"));

    // The body is selected: the Block tab shows it; its damping typed as 2.5.
    QCOMPARE(w.property_editor()->block(), QString("body"));
    QCOMPARE(w.property_editor()->subsystem(), QString("group"));
    QTest::qWait(50);
    QTableWidget* table = w.property_editor()->table();
    const int row = row_of(table, "c");
    QVERIFY(row >= 0);
    QCOMPARE(table->item(row, 1)->text(), QString("$damping"));
    QTest::mouseClick(table->viewport(), Qt::LeftButton, {}, table->visualItemRect(table->item(row, 1)).center());
    QTest::qWait(50);
    QTest::keyClick(table, Qt::Key_F2);
    auto* editor = qobject_cast<QLineEdit*>(table->indexWidget(table->currentIndex()));
    QVERIFY2(editor && editor->isVisible(), "F2 on the value cell opens its editor");
    editor->selectAll();
    QTest::keyClicks(editor, "2.5");
    QTest::keyClick(editor, Qt::Key_Return);
    QApplication::processEvents();
    QCOMPARE(QString::fromStdString(c->document().find_subsystem("group")->find_block("body")->find("c")->text()),
             QString("2.5"));
    // Inside, $name is the subsystem's own parameter: a scene parameter's name that is not one is refused.
    QVERIFY(c->set_block_value_in("group", "body", "c", "$nope").contains("not a parameter of subsystem group"));
    QVERIFY(c->set_block_value_in("group", "body", "c", "-1").contains("outside"));

    QVERIFY(w.save_file(saved));
    const engine::Diagram d = engine::load_scene(saved.toStdString());
    bool found = false;
    for (const auto& n : d.nodes)
      if (n.name == "group.body") {
        for (size_t j = 0; j < n.p.size(); ++j)
          if (n.type->parameters[j].name == "c") {
            QCOMPARE(n.p[j], 2.5);
            found = true;
          }
      }
    QVERIFY(found);
    // Reopened, the inside keeps the position it was dragged to.
    MainWindow again;
    QVERIFY(again.open_file(saved, true));
    const DocBlock* reread = again.controller()->document().find_subsystem("group")->find_block("body");
    QVERIFY(reread);
    QCOMPARE(reread->x, moved->x);
    QCOMPARE(reread->y, moved->y);
  }

  // The quarter car's tyre, damper and the gains around them: wires in from the car and the
  // road, out to the car and the objectives, the damper's $valve_current and $pipe_length
  // passed through, an objective's input inside. The same objectives and sensitivities to the
  // solver's tolerance.
  void group_across_the_cars_loop_runs_alike() {
    const std::string scene = std::string(DYDP_SCENARIOS_DIR) + "/quarter_car_cdc.yaml";
    QTemporaryDir dir;
    const QString saved = dir.filePath("grouped.yaml");
    MainWindow w;
    QVERIFY(w.open_file(QString::fromStdString(scene), true));
    QString instance;
    QCOMPARE(w.controller()->group_into_subsystem({"tyre", "damper", "stroke", "stroke_rate", "wheel_force"}, &instance),
             QString());
    const DocSubsystem* def = w.controller()->document().find_subsystem(instance.toStdString());
    QVERIFY(def);
    QVERIFY(def->inputs.size() >= 3);
    QVERIFY(def->outputs.size() >= 2);
    QVERIFY(w.save_file(saved));
    // The grouped blocks' states come in another order (those of blocks between them follow
    // the instance): the same equations, rounded differently, solved to rtol 1e-6.
    const QString faults = compare_objectives(objectives_of(scene), objectives_of(saved.toStdString()), "group.", 1e-5);
    QVERIFY2(faults.isEmpty(), qPrintable(faults));
  }

  // A file-included definition (the sedan's corners) is shown, not edited; grouping a block a
  // `directions:` pattern may name is refused with the reason.
  void file_definitions_read_only_directions_guarded() {
    MainWindow w;
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/fourposter_comfort.yaml", true));
    SceneController* c = w.controller();
    QVERIFY(!c->definition_editable("corner_rig"));
    QVERIFY(c->set_block_value_in("corner_rig", "damper", "friction", "30").contains("file of its own"));
    const QString why = c->group_into_subsystem({"corner_fl", "arb"});
    QVERIFY2(why.contains("corner_*"), qPrintable(why));
    QCOMPARE(c->group_into_subsystem({"wk", "comfort_wk"}), QString());
  }
};

QTEST_MAIN(GuiSubsystems)
#include "test_gui_subsystems.moc"
