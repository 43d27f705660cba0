// Every scene in scenarios/ and scenarios/stress/ opened in the GUI and saved again means the same
// to the engine (settings and nominal magnitudes included);
// a hand-written scene using every key of the format (the loader's own list, scene_format_keys)
// does too and keeps each key; and a second round-trip changes nothing.
#include <yaml-cpp/yaml.h>

#include <QDir>
#include <QTemporaryFile>
#include <QtTest>
#include <functional>
#include <sstream>

#include "engine/scene/scene_keys.hpp"
#include "gui/scene_controller.hpp"
#include "gui/tests/diagram_meaning.hpp"

using dydp::gui::SceneController;
using dydp::gui::testing::diagram_meaning;

namespace {

/// Saves the controller's scene to a temporary file in `folder` (so relative file settings
/// still resolve) and returns the engine's meaning of it; the file is removed afterwards.
/// `same_document`: whether reopening the saved file gives back the document that was saved.
std::string meaning_after_save(SceneController& c, const QString& folder, std::string& text,
                               bool& same_document) {
  QTemporaryFile file(folder + "/.roundtrip-XXXXXX.yaml");
  if (!file.open()) throw std::runtime_error("cannot create a file in " + folder.toStdString());
  file.close();
  c.save(file.fileName());
  QFile f(file.fileName());
  f.open(QIODevice::ReadOnly);
  text = f.readAll().toStdString();
  SceneController again;
  again.open(file.fileName());
  same_document = again.document() == c.document();
  return diagram_meaning(dydp::engine::load_scene(file.fileName().toStdString()));
}

/// Whether the YAML document has a key at `path` ("solver.max_order"; `*` is any entry of a
/// mapping or of a list: "directions.*.of").
bool has_key(const YAML::Node& node, const std::string& path) {
  std::vector<std::string> parts;
  std::istringstream in(path);
  for (std::string part; std::getline(in, part, '.');) parts.push_back(part);
  const std::function<bool(const YAML::Node&, size_t)> at = [&](const YAML::Node& n, size_t i) {
    if (i == parts.size()) return true;
    if (parts[i] == "*") {
      if (n.IsMap())
        for (auto kv : n)
          if (at(kv.second, i + 1)) return true;
      if (n.IsSequence())
        for (auto item : n)
          if (at(item, i + 1)) return true;
      return false;
    }
    return n.IsMap() && n[parts[i]] && at(n[parts[i]], i + 1);
  };
  return at(node, 0);
}

// Every key of the scene format, each with a value other than its default so that a key the GUI
// dropped changes the meaning. A key added to the format (engine/scene/scene_keys.hpp) fails
// the test until it is written here and the GUI keeps it.
constexpr const char* kEveryKeyScene = R"(# Every key of the scene format.
scene: every_key
description: "every key of the scene format"
time: {start: 0.5, stop: 3.0, output_step: 0.05}
solver: {method: bdf, rtol: 1.0e-5, atol: 1.0e-7, step: 0.001, max_steps: 20000, min_step: 1.0e-11, sens_error_test: false, nominal_scaling: false, newton_coefficient: 0.25, refresh_local_jacobians: false, max_order: 3}
initial: {state: equilibrium, hold: {wave.y: 0.5}}
parameters:
  gain: {value: 2.5, unit: "1", range: [0.0, 10.0], description: forcing gain}
directions:
  - {name: lag_time, of: lag.tau, range: [0.1, 0.4], unit: s}
sensitivities: [gain, lag_time]
subsystems:
  scaled: {file: scaled.yaml}
blocks:
  wave: {type: source.sine, amplitude: 3}
  scale: {type: subsystem.scaled, k: $gain}
  lag: {type: math.lag, tau: 0.2}
  peak: {type: objective.max_abs, window: [1.0, 3.0]}
connections:
  - wave.y -> scale.u
  - scale.y -> lag.u
  - lag.y -> peak.in
outputs: [lag.y, peak]
layout:
  wave: [0, 0]
  scale: [290, 0]
  lag: [580, 0]
  peak: [870, 0]
)";

}  // namespace

class SceneRoundTrip : public QObject {
  Q_OBJECT

 private slots:
  void every_scenario_keeps_its_meaning_data() {
    QTest::addColumn<QString>("path");
    // the shipped scenes and the stress scenes
    for (const QString& folder : {QString(DYDP_SCENARIOS_DIR), QString(DYDP_SCENARIOS_DIR) + "/stress"}) {
      const QDir dir(folder);
      const QStringList scenes = dir.entryList({"*.yaml"}, QDir::Files, QDir::Name);
      QVERIFY(!scenes.isEmpty());
      for (const QString& name : scenes) {
        if (name.startsWith('.')) continue;
        const QString row = QDir(DYDP_SCENARIOS_DIR).relativeFilePath(dir.filePath(name));
        QTest::newRow(row.toUtf8().constData()) << dir.filePath(name);
      }
    }
  }

  void every_scenario_keeps_its_meaning() {
    QFETCH(QString, path);
    const std::string original = diagram_meaning(dydp::engine::load_scene(path.toStdString()));
    SceneController c;
    c.open(path);
    QVERIFY(!c.document().blocks.empty());
    for (const auto& b : c.document().blocks) QVERIFY2(b.placed, b.name.c_str());
    std::string text;
    bool same = false;
    const std::string round = meaning_after_save(c, QFileInfo(path).absolutePath(), text, same);
    QVERIFY2(same, "the saved file reopens as a different document");
    QCOMPARE(QString::fromStdString(round), QString::fromStdString(original));
    QVERIFY(text.find("layout:") != std::string::npos);
    QVERIFY(!c.modified());
  }

  void hand_written_scene_with_every_key() {
    QTemporaryDir dir;
    const QString path = dir.filePath("hand.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(R"(# A hand-written scene: comments at the top are kept.
scene: hand
description: "every key: short parameters, lists, settings, solver options"
time: {start: 0.5, stop: 3.0, output_step: 0.05}
solver: {method: sdirk2, rtol: 1.0e-5, atol: 1.0e-7, step: 0.001, max_steps: 20000, sens_error_test: false}
parameters:
  gain: 2.5
  freq: {value: 1.25, unit: Hz, range: [0.1, 10.0], description: forcing frequency}
  start: {value: 1.0, unit: s}
sensitivities: [gain, freq]
blocks:
  wave:   {type: source.sine, frequency: $freq, amplitude: 3}
  step:   {type: source.step, time: $start, after: -1.0}
  sum:    {type: math.sum, signs: "+-"}
  k:      {type: math.gain, k: $gain}
  lag:    {type: math.lag, tau: 0.2}
  unused: {type: source.constant, value: 7}
  peak:   {type: objective.max_abs, window: [1.0, 3.0]}
  energy: {type: objective.integral}
connections:
  - wave.y -> sum.in1
  - step.y -> sum.in2
  - sum.y -> k.u
  - k.y -> lag.u
  - lag.y -> peak.in
  - lag.y -> energy.in
outputs: [lag.y, sum, peak, energy]
)");
    f.close();
    const std::string original = diagram_meaning(dydp::engine::load_scene(path.toStdString()));
    QVERIFY(original.find("pruned unused") != std::string::npos);
    QVERIFY(original.find("($freq)") != std::string::npos);
    SceneController c;
    c.open(path);
    std::string text;
    bool same = false;
    const std::string round = meaning_after_save(c, dir.path(), text, same);
    QVERIFY2(same, "the saved file reopens as a different document");
    QCOMPARE(QString::fromStdString(round), QString::fromStdString(original));
    QVERIFY(text.rfind("# A hand-written scene", 0) == 0);
    QVERIFY(text.find("description: forcing frequency") != std::string::npos);
    // Numbers keep the text they were written with.
    QVERIFY(text.find("rtol: 1.0e-5") != std::string::npos);
  }

  void every_key_of_the_scene_format_is_kept() {
    const std::vector<std::string> keys = dydp::engine::scene_format_keys();
    QVERIFY(keys.size() >= 30);
    const YAML::Node written = YAML::Load(kEveryKeyScene);
    for (const std::string& key : keys)
      QVERIFY2(has_key(written, key), ("the test scene does not use " + key + ": add it, and keep it in the GUI").c_str());
    QTemporaryDir dir;
    QFile sub(dir.filePath("scaled.yaml"));
    QVERIFY(sub.open(QIODevice::WriteOnly));
    sub.write("subsystem: scaled\nparameters: {k: {}}\ninputs: {u: g.u}\noutputs: {y: g.y}\nblocks:\n  g: {type: math.gain, k: $k}\n");
    sub.close();
    const QString path = dir.filePath("every_key.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(kEveryKeyScene);
    f.close();
    const std::string original = diagram_meaning(dydp::engine::load_scene(path.toStdString()));
    QVERIFY(original.find("solver newton_coefficient 0.25 max_order 3 refresh_local_jacobians 0\n") != std::string::npos);
    QVERIFY(original.find("initial equilibrium hold ") != std::string::npos);
    QVERIFY(original.find("=0.5\n") != std::string::npos);
    SceneController c;
    c.open(path);
    std::string text;
    bool same = false;
    const std::string round = meaning_after_save(c, dir.path(), text, same);
    QVERIFY2(same, "the saved file reopens as a different document");
    const YAML::Node saved = YAML::Load(text);
    for (const std::string& key : keys) QVERIFY2(has_key(saved, key), ("the GUI dropped " + key + ":\n" + text).c_str());
    QCOMPARE(QString::fromStdString(round), QString::fromStdString(original));
  }

  // Block settings of every kind (road class and seed, steering mode, input files and columns,
  // demux indices, signs, objective windows), a state's nominal magnitude and every solver key,
  // each on a block that feeds an output so that none is pruned before the comparison.
  void hand_written_settings_and_nominals() {
    QTemporaryDir dir;
    QFile table(dir.filePath("bench.csv"));
    QVERIFY(table.open(QIODevice::WriteOnly));
    table.write("time,z,rack\n0.0,0.0,0.0\n1.0,0.01,0.002\n2.0,-0.01,0.004\n");
    table.close();
    const QString path = dir.filePath("settings.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(R"(scene: settings
time: {start: 0.0, stop: 2.0, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8, max_steps: 4000, sens_error_test: false, min_step: 1.0e-10, nominal_scaling: false}
parameters:
  tau: {value: 0.2, unit: s}
sensitivities: [tau]
blocks:
  road:  {type: road.iso8608, speed: 15, class: D, seed: 7, components: 40, n_min: 0.02, n_max: 2.0}
  pick:  {type: math.demux, width: 4, indices: [3, 1]}
  split: {type: math.demux, width: 2, indices: [1]}
  both:  {type: math.sum, signs: "-+"}
  lag:   {type: math.lag, tau: $tau, nominal: {x: 0.01}}
  table: {type: source.table, file: bench.csv, column: z, time_column: time}
  sine:  {type: steering, mode: sine, amplitude: 0.005, frequency: 1.5, start: 0.2}
  rack:  {type: steering, mode: csv, file: bench.csv, column: rack, time_column: time}
  rms:   {type: objective.rms, window: [0.5, 2.0]}
connections:
  - road.z -> pick.u
  - pick.y -> split.u
  - split.y -> both.in1
  - table.y -> both.in2
  - both.y -> lag.u
  - lag.y -> rms.in
outputs: [lag.y, sine.rack, rack.rack, rms]
)");
    f.close();
    const std::string original = diagram_meaning(dydp::engine::load_scene(path.toStdString()));
    QVERIFY(original.find("pruned") == std::string::npos);
    QVERIFY(original.find("setting class = D") != std::string::npos);
    QVERIFY(original.find("setting indices = 3 1") != std::string::npos);
    QVERIFY(original.find("nominal 0.01") != std::string::npos);
    QVERIFY(original.find(" 1e-10 0\n") != std::string::npos);  // min_step, nominal_scaling off
    SceneController c;
    c.open(path);
    std::string text;
    bool same = false;
    const std::string round = meaning_after_save(c, dir.path(), text, same);
    QVERIFY2(same, "the saved file reopens as a different document");
    QCOMPARE(QString::fromStdString(round), QString::fromStdString(original));
  }

  void hand_placed_layout_is_kept() {
    QTemporaryDir dir;
    const QString path = dir.filePath("placed.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write("scene: placed\nblocks:\n  c: {type: source.constant}\noutputs: [c.y]\nlayout:\n  c: [310, -45]\n");
    f.close();
    SceneController c;
    c.open(path);
    QCOMPARE(c.document().blocks.front().x, 310.0);
    QCOMPARE(c.document().blocks.front().y, -45.0);
  }

  void not_a_scene_is_refused_with_its_line() {
    QTemporaryDir dir;
    const QString path = dir.filePath("bad.yaml");
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write("scene: bad\nblocks:\n  c: {type: source.constant}\noutputs: [c.y]\nwhatever: 1\n");
    f.close();
    SceneController c;
    try {
      c.open(path);
      QFAIL("an unknown top-level key must be refused");
    } catch (const dydp::engine::InputError& e) {
      QCOMPARE(e.line(), 5);
      QCOMPARE(QString::fromStdString(e.field()), QString("whatever"));
    }
  }
};

QTEST_MAIN(SceneRoundTrip)
#include "test_scene_roundtrip.moc"
