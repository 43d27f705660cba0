// dydp-gui: edit and run dydp scenes as block diagrams.
//   dydp-gui [SCENE] [--run] [--plot SIGNAL,SIGNAL] [--modes] [--frf] [--hold SIGNAL=VALUE,...]
//            [--screenshot FILE.png]
// With --screenshot the window is shown, the scene run (with --run) or its modes and FRF computed
// (--modes, --frf) and the window saved as an image, then the program exits (used by
// scripts/gui_screenshot.sh).
#include <QApplication>
#include <QCommandLineParser>
#include <QScreen>
#include <QTimer>
#include <cstdio>

#include "gui/main_window.hpp"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  QApplication::setApplicationName("dydp-gui");
  QCommandLineParser cli;
  cli.setApplicationDescription("Edit and run dydp scenes as block diagrams.");
  cli.addHelpOption();
  cli.addPositionalArgument("scene", "scene file to open");
  const QCommandLineOption run_option("run", "run the scene once opened");
  const QCommandLineOption shot_option("screenshot", "save the window to FILE and exit", "FILE");
  const QCommandLineOption size_option("size", "window size WxH", "WxH", "1600x1000");
  const QCommandLineOption plot_option("plot", "after the run, plot these logged signals overlaid (comma-separated)",
                                       "SIGNALS");
  const QCommandLineOption modes_option("modes", "compute the modes about the equilibrium once opened");
  const QCommandLineOption frf_option("frf", "compute the frequency response (the default input and output) once opened");
  const QCommandLineOption hold_option("hold", "signals the equilibrium holds, SIGNAL=VALUE,...", "HOLDS");
  cli.addOptions({run_option, shot_option, size_option, plot_option, modes_option, frf_option, hold_option});
  cli.process(app);

  dydp::gui::MainWindow window;
  const QStringList size = cli.value(size_option).split('x');
  if (size.size() == 2) window.resize(size[0].toInt(), size[1].toInt());
  window.show();
  const QStringList args = cli.positionalArguments();
  if (!args.isEmpty() && !window.open_file(args.front(), cli.isSet(shot_option))) {
    std::fprintf(stderr, "%s\n", window.last_error().toUtf8().constData());
    if (cli.isSet(shot_option)) return 2;
  }
  const QString shot = cli.value(shot_option);
  auto take_shot = [&] {
    QTimer::singleShot(300, &window, [&] {
      // Show the property editor filled: select the block with the most parameters.
      const auto& blocks = window.controller()->document().blocks;
      size_t most = 0;
      QString richest;
      for (const auto& b : blocks)
        if (const auto* type = dydp::engine::Registry::global().find(b.type); type && type->parameters.size() > most) {
          most = type->parameters.size();
          richest = QString::fromStdString(b.name);
        }
      if (!richest.isEmpty()) window.canvas()->select_block(richest);
      window.canvas()->fit_all();
      QApplication::processEvents();
      const bool ok = window.grab().save(shot);
      if (!ok) std::fprintf(stderr, "cannot write %s\n", shot.toUtf8().constData());
      QApplication::exit(ok ? 0 : 1);
    });
  };
  if (cli.isSet(plot_option))
    QObject::connect(&window, &dydp::gui::MainWindow::run_ended, &window, [&] {
      std::vector<int> chosen;
      QListWidget* list = window.results()->signal_list();
      for (const QString& name : cli.value(plot_option).split(','))
        for (int row = 0; row < list->count(); ++row)
          if (list->item(row)->text().section(' ', 0, 0) == name.trimmed()) chosen.push_back(row);
      const QString why = window.results()->plot_signals(chosen);
      if (!why.isEmpty()) std::fprintf(stderr, "--plot: %s\n", why.toUtf8().constData());
    });
  if (cli.isSet(hold_option)) window.linear()->hold_field()->setText(cli.value(hold_option));
  if (cli.isSet(modes_option) || cli.isSet(frf_option)) {
    // The modes first, then the FRF, then the screenshot (without --run).
    const bool modes = cli.isSet(modes_option), frf = cli.isSet(frf_option);
    QTimer::singleShot(200, &window, [&window, modes, frf] {
      if (!(modes ? window.start_modes() : window.start_frf()))
        std::fprintf(stderr, "%s\n", window.linear()->message().toUtf8().constData());
    });
    QObject::connect(window.linear(), &dydp::gui::LinearPanel::analysis_ended, &window,
                     [&, modes, frf, done = 0](const QString& error) mutable {
                       if (!error.isEmpty()) std::fprintf(stderr, "%s\n", error.toUtf8().constData());
                       ++done;
                       if (modes && frf && done == 1) {
                         QTimer::singleShot(0, &window, [&window] { window.start_frf(); });
                         return;
                       }
                       if (!shot.isEmpty() && !cli.isSet(run_option)) take_shot();
                     });
  }
  if (cli.isSet(run_option)) {
    QTimer::singleShot(200, &window, [&] {
      if (!window.start_run()) {
        std::fprintf(stderr, "%s\n", window.last_error().toUtf8().constData());
        if (!shot.isEmpty()) take_shot();
      }
    });
    if (!shot.isEmpty())
      QObject::connect(&window, &dydp::gui::MainWindow::run_ended, &window, [&] { take_shot(); });
  } else if (!shot.isEmpty() && !cli.isSet(modes_option) && !cli.isSet(frf_option)) {
    take_shot();
  }
  return app.exec();
}
