// The layered automatic layout: every scene of scenarios/ and scenarios/stress/ without a
// `layout:` section opened in the window is drawn with every source (a block without inputs)
// left of every objective and no two blocks overlapping; Edit > Lay out diagram (Ctrl+L) lays
// out a scene that has a layout the same way, as one undo step; crossing wires are uncrossed.
#include <QFile>
#include <QtTest>

#include "gui/main_window.hpp"
#include "gui/tests/shipped_scenes.hpp"

using namespace dydp::gui;

namespace {

struct Drawn {
  QString name;
  QRectF rect;  ///< the block's frame in scene coordinates
  bool source = false, objective = false;
};

std::vector<Drawn> drawn_blocks(MainWindow& w) {
  std::vector<Drawn> out;
  for (const DocBlock& b : w.controller()->document().blocks) {
    BlockItem* item = w.canvas()->block_item(b.name);
    if (!item) continue;
    const BlockPorts ports = w.controller()->ports(b.name);
    out.push_back({QString::fromStdString(b.name), item->mapRectToScene(item->rect()),
                   ports.inputs.empty() && !ports.is_objective, ports.is_objective});
  }
  return out;
}

/// "" when no blocks overlap and every source lies left of every objective, else what does not.
QString layout_faults(const std::vector<Drawn>& blocks) {
  QStringList faults;
  for (size_t i = 0; i < blocks.size(); ++i)
    for (size_t j = i + 1; j < blocks.size(); ++j)
      if (blocks[i].rect.intersects(blocks[j].rect)) faults << blocks[i].name + " overlaps " + blocks[j].name;
  for (const Drawn& s : blocks)
    for (const Drawn& o : blocks)
      if (s.source && o.objective && !(s.rect.right() < o.rect.left()))
        faults << "source " + s.name + " not left of objective " + o.name;
  return faults.join("; ");
}

bool has_layout_section(const QString& path) {
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly)) return false;
  return QString::fromUtf8(f.readAll()).contains(QRegularExpression("(^|\\n)layout:"));
}

}  // namespace

class GuiLayout : public QObject {
  Q_OBJECT
  int pairs_checked_ = 0;  ///< (source, objective) pairs whose order was checked over the scenes

 private slots:
  void scenes_without_layout_are_layered_data() {
    QTest::addColumn<QString>("path");
    int n = 0;
    for (const QString& path : testing::shipped_scenes()) {
      if (has_layout_section(path)) continue;
      QTest::newRow(testing::scene_row_name(path).constData()) << path;
      ++n;
    }
    QVERIFY(n >= 10);  // six scenes of scenarios/ and the eight stress scenes have none today
  }

  void scenes_without_layout_are_layered() {
    QFETCH(QString, path);
    MainWindow w;
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY2(w.open_file(path, true), qPrintable(w.last_error()));
    const std::vector<Drawn> blocks = drawn_blocks(w);
    QCOMPARE(blocks.size(), w.controller()->document().blocks.size());
    for (const Drawn& s : blocks)
      for (const Drawn& o : blocks) pairs_checked_ += s.source && o.objective ? 1 : 0;
    const QString faults = layout_faults(blocks);
    QVERIFY2(faults.isEmpty(), qPrintable(faults));
    // Opening is not an edit.
    QVERIFY(!w.controller()->modified());
  }

  // Not every scene has a source and an objective (the pendulums run free): enough do.
  void sources_and_objectives_were_compared() { QVERIFY2(pairs_checked_ >= 10, qPrintable(QString::number(pairs_checked_))); }

  // The sedan scene has a hand-made layout; Ctrl+L replaces it by the layered one in one undo
  // step: the rig left, the car between the corners and the objectives, nothing overlapping.
  void lay_out_on_demand_and_undo() {
    MainWindow w;
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/fourposter_comfort.yaml", true));
    const SceneDocument before = w.controller()->document();
    QTest::keyClick(&w, Qt::Key_L, Qt::ControlModifier);
    QApplication::processEvents();
    const SceneDocument& after = w.controller()->document();
    QVERIFY(!(after == before));
    const QString faults = layout_faults(drawn_blocks(w));
    QVERIFY2(faults.isEmpty(), qPrintable(faults));
    const auto x = [&](const char* name) { return w.canvas()->block_item(name)->pos().x(); };
    QVERIFY(x("rig") < x("corner_fl"));
    QVERIFY(x("corner_fl") < x("car"));
    QVERIFY(x("car") < x("comfort"));
    QCOMPARE(w.controller()->undo_stack()->undoText(), QString("Lay out diagram"));
    w.controller()->undo_stack()->undo();
    QVERIFY(w.controller()->document() == before);
  }

  // Sources wired crosswise to two gains (a -> g2, b -> g1): the layout orders the gains so
  // that the wires do not cross, whatever the order the blocks were written in.
  void crossing_wires_are_uncrossed() {
    MainWindow w;
    SceneController* c = w.controller();
    for (const char* type : {"source.constant", "source.constant", "math.gain", "math.gain"})
      QVERIFY(!c->add_block(type, {0, 0}).isEmpty());
    QCOMPARE(c->connect_ports("constant.y", "gain2.u"), QString());
    QCOMPARE(c->connect_ports("constant2.y", "gain.u"), QString());
    c->lay_out();
    const auto y = [&](const char* name) { return c->document().find_block(name)->y; };
    QVERIFY(c->document().find_block("gain")->x > c->document().find_block("constant")->x);
    QCOMPARE(y("constant") < y("constant2"), y("gain2") < y("gain"));
    const QString faults = layout_faults(drawn_blocks(w));
    QVERIFY2(faults.isEmpty(), qPrintable(faults));
  }
};

QTEST_MAIN(GuiLayout)
#include "test_gui_layout.moc"
