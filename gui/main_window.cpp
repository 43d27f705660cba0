#include "gui/main_window.hpp"

#include <QApplication>
#include <QCloseEvent>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QLineEdit>
#include <QMenuBar>
#include <QMessageBox>
#include <QScrollArea>
#include <QStatusBar>
#include <QTabWidget>
#include <QToolBar>

#include "engine/framework/errors.hpp"

namespace dydp::gui {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
  QTabWidget* tabs = set_up_docks();

  // Actions.
  set_up_menus();

  // Where the canvas is: the scene, or the subsystem instances opened; each entry goes back there.
  set_up_level_toolbar();

  status_label_ = new QLabel;
  statusBar()->addWidget(status_label_, 1);

  connect_panels(tabs);
  resize(1500, 950);
  update_title();
}

// The canvas and the docks around it (blocks, properties, results); returns the properties tabs.
QTabWidget* MainWindow::set_up_docks() {
  canvas_ = new Canvas(&controller_);
  setCentralWidget(canvas_);

  palette_ = new Palette;
  auto* palette_dock = new QDockWidget(tr("Blocks"));
  palette_dock->setObjectName("palette");
  palette_dock->setWidget(palette_);
  palette_->setMinimumWidth(270);
  addDockWidget(Qt::LeftDockWidgetArea, palette_dock);

  properties_ = new PropertyEditor(&controller_);
  scene_panel_ = new ScenePanel(&controller_);
  auto* tabs = new QTabWidget;
  tabs->addTab(properties_, tr("Block"));
  // Scrolled: the panel lists every solver key, taller than a small window's dock, and its
  // height must not squeeze the canvas.
  auto* scene_scroll = new QScrollArea;
  scene_scroll->setWidget(scene_panel_);
  scene_scroll->setWidgetResizable(true);
  scene_scroll->setFrameShape(QFrame::NoFrame);
  tabs->addTab(scene_scroll, tr("Scene"));
  auto* right_dock = new QDockWidget(tr("Properties"));
  right_dock->setObjectName("properties");
  right_dock->setWidget(tabs);
  addDockWidget(Qt::RightDockWidgetArea, right_dock);

  results_ = new ResultsPanel;
  linear_ = new LinearPanel(&controller_, &worker_);
  bottom_tabs_ = new QTabWidget;
  bottom_tabs_->addTab(results_, tr("Run results"));
  bottom_tabs_->addTab(linear_, tr("Modes && FRF"));
  auto* results_dock = new QDockWidget(tr("Results"));
  results_dock->setObjectName("results");
  results_dock->setWidget(bottom_tabs_);
  addDockWidget(Qt::BottomDockWidgetArea, results_dock);
  return tabs;
}

// The File, Edit, View and Run menus and the main toolbar, in that order.
void MainWindow::set_up_menus() {
  auto* file = menuBar()->addMenu(tr("&File"));
  auto* edit = menuBar()->addMenu(tr("&Edit"));
  auto* run_menu = menuBar()->addMenu(tr("&Run"));
  auto* tools = addToolBar(tr("Main"));
  tools->setObjectName("main_toolbar");
  const QList<QAction*> file_actions = add_file_actions(file);
  const QList<QAction*> edit_actions = add_edit_actions(edit);
  add_view_actions(menuBar()->addMenu(tr("&View")));
  add_run_actions(run_menu);
  fill_main_toolbar(tools, file_actions, edit_actions);
}

// File: new, open, save, save as, quit; returns new, open and save for the toolbar.
QList<QAction*> MainWindow::add_file_actions(QMenu* file) {
  auto* act_new = file->addAction(tr("&New"), QKeySequence::New, this, [this] {
    if (maybe_save()) controller_.new_scene();
  });
  auto* act_open = file->addAction(tr("&Open..."), QKeySequence::Open, this, [this] {
    if (!maybe_save()) return;
    const QString path = QFileDialog::getOpenFileName(this, tr("Open scene"), {}, tr("Scenes (*.yaml *.yml)"));
    if (!path.isEmpty()) open_file(path);
  });
  auto* act_save = file->addAction(tr("&Save"), QKeySequence::Save, this, [this] {
    QString path = controller_.file_path();
    if (path.isEmpty()) path = QFileDialog::getSaveFileName(this, tr("Save scene"), {}, tr("Scenes (*.yaml)"));
    if (!path.isEmpty()) save_file(path);
  });
  file->addAction(tr("Save &as..."), QKeySequence::SaveAs, this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save scene"), controller_.file_path(), tr("Scenes (*.yaml)"));
    if (!path.isEmpty()) save_file(path);
  });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);
  return {act_new, act_open, act_save};
}

// Edit: undo, redo, delete, fit, group, lay out; returns undo, redo and delete for the toolbar.
QList<QAction*> MainWindow::add_edit_actions(QMenu* edit) {
  QAction* undo = controller_.undo_stack()->createUndoAction(this, tr("&Undo"));
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = controller_.undo_stack()->createRedoAction(this, tr("&Redo"));
  redo->setShortcut(QKeySequence::Redo);
  edit->addAction(undo);
  edit->addAction(redo);
  auto* act_delete = edit->addAction(tr("&Delete"), this, [this] { canvas_->delete_selection(); });
  edit->addAction(tr("&Fit diagram"), this, [this] { canvas_->fit_all(); });
  edit->addAction(tr("&Group into subsystem"), QKeySequence(Qt::CTRL | Qt::Key_G), this,
                  [this] { canvas_->group_selection(); });
  edit->addAction(tr("&Lay out diagram"), QKeySequence(Qt::CTRL | Qt::Key_L), this, [this] {
    if (!canvas_->at_scene_level()) return status(tr("Lay out works on the scene's level: go back up first"));
    controller_.lay_out();
    canvas_->fit_all();
  });
  return {undo, redo, act_delete};
}

// View: open a subsystem, show all ports, up from a subsystem.
void MainWindow::add_view_actions(QMenu* view) {
  view->addAction(tr("&Open subsystem"), QKeySequence(Qt::ALT | Qt::Key_Down), this, [this] {
    const QStringList sel = canvas_->selected_blocks();
    if (sel.size() != 1 || !canvas_->open_subsystem(sel.front()))
      status(tr("select one subsystem block (or double-click it) to open it"));
  });
  view->addAction(tr("Show &all ports of the selected block"), this, [this] {
    for (const QString& b : canvas_->selected_blocks()) canvas_->toggle_all_ports(b);
  });
  view->addAction(tr("&Up from subsystem"), QKeySequence(Qt::ALT | Qt::Key_Up), this, [this] { canvas_->close_subsystem(); });
}

// Run: run, cancel, modes, frequency response.
void MainWindow::add_run_actions(QMenu* run_menu) {
  run_action_ = run_menu->addAction(tr("&Run"), QKeySequence(Qt::Key_F5), this, [this] { start_run(); });
  cancel_action_ = run_menu->addAction(tr("&Cancel"), QKeySequence(Qt::Key_Escape), this, [this] { worker_.cancel(); });
  cancel_action_->setEnabled(false);
  run_menu->addSeparator();
  run_menu->addAction(tr("&Modes about the equilibrium"), QKeySequence(Qt::CTRL | Qt::Key_M), this, [this] { start_modes(); });
  run_menu->addAction(tr("&Frequency response"), this, [this] { start_frf(); });
}

// The main toolbar: the file and edit actions, run and cancel, the progress bar.
void MainWindow::fill_main_toolbar(QToolBar* tools, const QList<QAction*>& file_actions,
                                   const QList<QAction*>& edit_actions) {
  for (QAction* a : file_actions) tools->addAction(a);
  tools->addSeparator();
  for (QAction* a : edit_actions) tools->addAction(a);
  tools->addSeparator();
  tools->addAction(run_action_);
  tools->addAction(cancel_action_);
  progress_ = new QProgressBar;
  progress_->setRange(0, 1000);
  progress_->setValue(0);
  progress_->setMaximumWidth(220);
  progress_->setFormat("%p%");
  tools->addWidget(progress_);
}

// The Level toolbar: the find field (Ctrl+F) and the breadcrumb of the levels opened.
void MainWindow::set_up_level_toolbar() {
  auto* where = addToolBar(tr("Level"));
  where->setObjectName("level_toolbar");
  find_ = new QLineEdit;
  find_->setObjectName("find_block");
  find_->setPlaceholderText(tr("find block (Ctrl+F)"));
  find_->setMaximumWidth(220);
  where->addWidget(find_);
  connect(find_, &QLineEdit::returnPressed, this, [this] { canvas_->find_block(find_->text().trimmed()); });
  auto* find_action = new QAction(this);
  find_action->setShortcut(QKeySequence::Find);
  connect(find_action, &QAction::triggered, this, [this] {
    find_->setFocus();
    find_->selectAll();
  });
  addAction(find_action);
  breadcrumb_ = new QLabel;
  breadcrumb_->setTextFormat(Qt::RichText);
  where->addWidget(breadcrumb_);
  connect(breadcrumb_, &QLabel::linkActivated, this, [this](const QString& link) {
    canvas_->close_subsystem(static_cast<int>(canvas_->level().size()) - link.toInt());
  });
  connect(canvas_, &Canvas::level_changed, this, &MainWindow::update_breadcrumb);
  update_breadcrumb(canvas_->level());
}

// The messages, selection, palette, title, run and analysis connections (tabs: the properties tabs).
void MainWindow::connect_panels(QTabWidget* tabs) {
  connect(canvas_, &Canvas::message, this, &MainWindow::status);
  connect(properties_, &PropertyEditor::message, this, &MainWindow::status);
  connect(scene_panel_, &ScenePanel::message, this, &MainWindow::status);
  connect(canvas_, &Canvas::selection_changed, this, [this, tabs](const QString& block) {
    properties_->set_block(block, canvas_->definition_name());
    if (!block.isEmpty()) tabs->setCurrentWidget(properties_);
  });
  connect(palette_, &Palette::activated_type, this, [this](const QString& type) {
    const QRectF r = canvas_->mapToScene(canvas_->viewport()->rect()).boundingRect();
    canvas_->drop_block(type, r.center() - QPointF(75, 40));
  });
  connect(&controller_, &SceneController::file_changed, this, &MainWindow::update_title);
  connect(controller_.undo_stack(), &QUndoStack::cleanChanged, this, &MainWindow::update_title);
  // An edit makes the last message stale (a refusal, an invalid scene): clear it; a message the
  // edit itself sends comes after this.
  connect(&controller_, &SceneController::document_changed, this, [this] {
    canvas_->clear_errors();
    status({});
  });
  connect(&worker_, &RunWorker::progress, this, [this](double f) { progress_->setValue(static_cast<int>(f * 1000)); });
  connect(&worker_, &RunWorker::finished, this, &MainWindow::run_finished);
  connect(linear_, &LinearPanel::analysis_ended, this, [this](const QString& error) {
    run_action_->setEnabled(true);
    status(error.isEmpty() ? linear_->message() : tr("analysis failed: %1").arg(error));
  });
}

void MainWindow::status(const QString& text) { status_label_->setText(text); }

bool MainWindow::start_modes() {
  bottom_tabs_->setCurrentWidget(linear_);
  if (!linear_->compute_modes()) return status(linear_->message()), false;
  run_action_->setEnabled(false);
  status(linear_->message());
  return true;
}

bool MainWindow::start_frf() {
  bottom_tabs_->setCurrentWidget(linear_);
  if (!linear_->compute_frf()) return status(linear_->message()), false;
  run_action_->setEnabled(false);
  status(linear_->message());
  return true;
}

void MainWindow::update_breadcrumb(const QStringList& level) {
  QString text = level.isEmpty() ? tr("<b>scene</b>") : QString("<a href=\"0\">%1</a>").arg(tr("scene"));
  for (qsizetype i = 0; i < level.size(); ++i)
    text += " \u25b8 " + (i + 1 == level.size() ? "<b>" + level[i].toHtmlEscaped() + "</b>"
                                                : QString("<a href=\"%1\">%2</a>").arg(i + 1).arg(level[i].toHtmlEscaped()));
  if (!level.isEmpty())
    text += canvas_->level_editable() ? tr("  <i>(Alt+Up: back)</i>") : tr("  <i>(read only; Alt+Up: back)</i>");
  breadcrumb_->setText(text);
}

void MainWindow::update_title() {
  const QString path = controller_.file_path();
  setWindowTitle(QString("%1%2 - dydp").arg(path.isEmpty() ? tr("untitled") : QFileInfo(path).fileName(),
                                             controller_.modified() ? "*" : ""));
}

bool MainWindow::open_file(const QString& path, bool quiet) {
  try {
    controller_.open(path);
  } catch (const engine::InputError& e) {
    last_error_ = QString::fromUtf8(e.what());
    if (!quiet) QMessageBox::warning(this, tr("Cannot open scene"), last_error_);
    status(last_error_);
    return false;
  }
  results_->forget_runs();
  linear_->refresh_signals();
  canvas_->fit_all();
  status(tr("opened %1").arg(path));
  return true;
}

bool MainWindow::save_file(const QString& path) {
  try {
    controller_.save(path);
  } catch (const std::exception& e) {
    QMessageBox::warning(this, tr("Cannot save scene"), QString::fromUtf8(e.what()));
    return false;
  }
  status(tr("saved %1").arg(path));
  return true;
}

bool MainWindow::maybe_save() {
  if (!controller_.modified()) return true;
  const auto answer = QMessageBox::question(this, tr("Unsaved changes"), tr("Save the changes to this scene?"),
                                            QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
  if (answer == QMessageBox::Cancel) return false;
  if (answer == QMessageBox::Discard) return true;
  QString path = controller_.file_path();
  if (path.isEmpty()) path = QFileDialog::getSaveFileName(this, tr("Save scene"), {}, tr("Scenes (*.yaml)"));
  return !path.isEmpty() && save_file(path);
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!maybe_save()) return e->ignore();
  worker_.cancel();
  e->accept();
}

bool MainWindow::start_run() {
  if (worker_.running()) return false;
  canvas_->clear_errors();
  canvas_->set_notes({});
  engine::Diagram d;
  try {
    d = controller_.load_for_run();
  } catch (const engine::InputError& e) {
    last_error_ = QString::fromUtf8(e.what());
    const QStringList blocks = controller_.blocks_of_error(e);
    canvas_->show_error(blocks, last_error_);
    if (blocks.size() == 1) canvas_->select_block(blocks.front());
    if (e.field() == "outputs" && controller_.document().outputs.empty())
      // A new diagram: say where outputs are chosen rather than what the file lacks.
      status(tr("Nothing to compute yet: select a block and tick the signals to log under \"Logged outputs\" "
                "in the Block tab, or drop an objective block (objectives are computed by default)."));
    else
      status(tr("invalid scene: %1").arg(last_error_));
    return false;
  }
  last_error_.clear();
  progress_->setValue(0);
  run_action_->setEnabled(false);
  cancel_action_->setEnabled(true);
  status(tr("running..."));
  worker_.start(std::move(d));
  return true;
}

void MainWindow::run_finished(const RunOutcome& outcome) {
  run_action_->setEnabled(true);
  cancel_action_->setEnabled(false);
  switch (outcome.status) {
    case RunOutcome::Status::finished: {
      progress_->setValue(1000);
      bottom_tabs_->setCurrentWidget(results_);
      results_->show_result(outcome.result, outcome.diagram);
      std::map<std::string, QString> notes;
      for (const auto& o : outcome.result->objectives) notes[o.name] = QString("ψ = %1").arg(o.value, 0, 'g', 6);
      canvas_->set_notes(notes);
      const auto& st = outcome.result->stats;
      status(tr("done: %1 steps, %2 s CPU").arg(st.steps).arg(st.cpu_seconds, 0, 'g', 3));
      break;
    }
    case RunOutcome::Status::cancelled:
      status(tr("run cancelled"));
      break;
    case RunOutcome::Status::failed:
      last_error_ = outcome.message;
      if (!outcome.block.isEmpty()) canvas_->show_error({outcome.block}, outcome.message);
      status(tr("solver failure: %1").arg(outcome.message));
      break;
  }
  emit run_ended(outcome);
}

}  // namespace dydp::gui
