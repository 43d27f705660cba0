// The canvas on whole scenes: every scene of scenarios/ (stress scenes included) opened in the
// window, fitted, and every block inside the visible part of the view; the scene rectangle
// holds the diagram however large; a subsystem instance opened by a double-click on the canvas,
// its inside fitted, and the breadcrumb back to the scene.
#include <QLabel>
#include <QScrollBar>
#include <QtTest>

#include "gui/main_window.hpp"
#include "gui/tests/shipped_scenes.hpp"

using namespace dydp::gui;

namespace {

/// Every block item of the canvas lies within the viewport, in viewport coordinates.
QStringList blocks_outside_view(Canvas* canvas) {
  QStringList outside;
  const QRect view = canvas->viewport()->rect();
  for (QGraphicsItem* item : canvas->scene()->items()) {
    auto* b = qgraphicsitem_cast<BlockItem*>(item);
    if (!b) continue;
    const QRect r = canvas->mapFromScene(b->sceneBoundingRect()).boundingRect();
    if (!view.contains(r)) outside << QString::fromStdString(b->name());
  }
  return outside;
}

int block_items(Canvas* canvas) {
  int n = 0;
  for (QGraphicsItem* item : canvas->scene()->items()) n += qgraphicsitem_cast<BlockItem*>(item) ? 1 : 0;
  return n;
}

QPoint view_centre_of(Canvas* canvas, const std::string& block) {
  BlockItem* b = canvas->block_item(block);
  return b ? canvas->mapFromScene(b->sceneBoundingRect().center()) : QPoint();
}

}  // namespace

class GuiViews : public QObject {
  Q_OBJECT

 private slots:
  void every_scene_fits_in_the_view_data() {
    QTest::addColumn<QString>("path");
    int n = 0;
    for (const QString& path : testing::shipped_scenes()) {
      QTest::newRow(testing::scene_row_name(path).constData()) << path;
      ++n;
    }
    QVERIFY(n >= 15);
  }

  void every_scene_fits_in_the_view() {
    QFETCH(QString, path);
    MainWindow w;
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY2(w.open_file(path, true), qPrintable(w.last_error()));
    Canvas* canvas = w.canvas();
    QCOMPARE(block_items(canvas), static_cast<int>(w.controller()->document().blocks.size()));
    // The scene rectangle holds every block, wherever the layout put them.
    const QRectF items = canvas->scene()->itemsBoundingRect();
    QVERIFY(canvas->sceneRect().contains(items));
    canvas->fit_all();
    QApplication::processEvents();
    const QStringList outside = blocks_outside_view(canvas);
    QVERIFY2(outside.isEmpty(), qPrintable("outside the view after fit: " + outside.join(", ")));
  }

  // A block dragged far out grows the scene with it: it can be scrolled to and fitted.
  void the_scene_grows_with_the_diagram() {
    MainWindow w;
    w.resize(1200, 800);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    Canvas* canvas = w.canvas();
    QCOMPARE(canvas->drop_block("source.constant", {0, 0}), QString("constant"));
    w.controller()->move_block("constant", {12000, 9000});
    QApplication::processEvents();
    QVERIFY(canvas->sceneRect().contains(canvas->block_item("constant")->sceneBoundingRect()));
    canvas->fit_all();
    QApplication::processEvents();
    QVERIFY(blocks_outside_view(canvas).isEmpty());
  }

  // Find: a name typed into the toolbar's field and Return select the block and bring it into
  // view; the middle button drags the view.
  void find_block_and_pan() {
    MainWindow w;
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/fourposter_comfort.yaml", true));
    Canvas* canvas = w.canvas();
    canvas->resetTransform();  // natural size: the diagram is larger than the view
    canvas->centerOn(canvas->block_item("rig"));
    QApplication::processEvents();
    const auto visible = [canvas](const char* block) {
      return canvas->viewport()->rect().contains(
          canvas->mapFromScene(canvas->block_item(block)->sceneBoundingRect().center()));
    };
    QVERIFY(!visible("comfort_wk"));
    QTest::keyClicks(w.find_field(), "comfort_w");
    QTest::keyClick(w.find_field(), Qt::Key_Return);
    QVERIFY(visible("comfort_wk"));
    QCOMPARE(canvas->selected_blocks(), QStringList{"comfort_wk"});
    // Middle-button drag by 200 px to the right moves the diagram 200 px right in the view.
    const QPoint before = canvas->mapFromScene(canvas->block_item("comfort_wk")->pos());
    const QPoint at = canvas->viewport()->rect().center();
    QTest::mousePress(canvas->viewport(), Qt::MiddleButton, {}, at);
    QTest::mouseMove(canvas->viewport(), at + QPoint(100, 0));
    QTest::mouseMove(canvas->viewport(), at + QPoint(200, 0));
    QTest::mouseRelease(canvas->viewport(), Qt::MiddleButton, {}, at + QPoint(200, 0));
    const QPoint after = canvas->mapFromScene(canvas->block_item("comfort_wk")->pos());
    QCOMPARE(after - before, QPoint(200, 0));
  }

  // fourposter_comfort: car, rig, objectives and four corner instances drawn as one block each;
  // a double-click opens corner_fl (its blocks and its ports as edge blocks, wired), the
  // breadcrumb's "scene" entry goes back.
  void subsystem_opens_by_double_click_and_back_by_breadcrumb() {
    MainWindow w;
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    QVERIFY2(w.open_file(QString(DYDP_SCENARIOS_DIR) + "/fourposter_comfort.yaml", true), qPrintable(w.last_error()));
    Canvas* canvas = w.canvas();
    QVERIFY(canvas->block_item("corner_fl"));
    QVERIFY(!canvas->block_item("corner_fl.damper"));
    const int top_wires = canvas->wire_count();
    // The instance's ports are the subsystem's: a wire from the car reaches corner_fl.damper_stroke.
    QVERIFY(canvas->block_item("corner_fl")->port("damper_stroke", true));
    QVERIFY(canvas->block_item("corner_fl")->port("damper_force", false));
    canvas->fit_all();
    QApplication::processEvents();

    QTest::mouseDClick(canvas->viewport(), Qt::LeftButton, {}, view_centre_of(canvas, "corner_fl"));
    QApplication::processEvents();
    QCOMPARE(canvas->level(), QStringList{"corner_fl"});
    for (const char* inside : {"spring", "damper", "tyre", "pad_z", "pad_zdot", "zero", "in damper_stroke", "out damper_force"})
      QVERIFY2(canvas->block_item(inside), inside);
    QVERIFY(!canvas->block_item("car"));
    // Wires inside: the two pad connections, seven input ports and six output ports.
    QCOMPARE(canvas->wire_count(), 2 + 7 + 6);
    QVERIFY(blocks_outside_view(canvas).isEmpty());
    QVERIFY(w.breadcrumb()->text().contains("corner_fl"));
    // Inside is read only: a drop is refused with the reason.
    QCOMPARE(canvas->drop_block("source.constant", {0, 0}), QString());

    emit w.breadcrumb()->linkActivated("0");
    QApplication::processEvents();
    QVERIFY(canvas->level().isEmpty());
    QVERIFY(canvas->block_item("car"));
    QCOMPARE(canvas->wire_count(), top_wires);
    QVERIFY(!w.breadcrumb()->text().contains("corner_fl"));
  }
};

QTEST_MAIN(GuiViews)
#include "test_gui_views.moc"
