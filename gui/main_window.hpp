// The main window: palette (left), canvas (centre), block and scene panels (right), results
// (bottom, beside the modes table and FRF plot); File, Edit and Run actions; runs and the linear
// analyses go to a worker thread, runs with progress and cancel.
#pragma once

#include <QAction>
#include <QLabel>
#include <QLineEdit>
#include <QMainWindow>
#include <QMenu>
#include <QProgressBar>
#include <QTabWidget>
#include <QToolBar>

#include "gui/canvas.hpp"
#include "gui/linear_panel.hpp"
#include "gui/palette.hpp"
#include "gui/property_editor.hpp"
#include "gui/results_panel.hpp"
#include "gui/run_worker.hpp"
#include "gui/scene_controller.hpp"
#include "gui/scene_panel.hpp"

namespace dydp::gui {

class MainWindow : public QMainWindow {
  Q_OBJECT

 public:
  explicit MainWindow(QWidget* parent = nullptr);

  SceneController* controller() { return &controller_; }
  Canvas* canvas() { return canvas_; }
  Palette* palette() { return palette_; }
  PropertyEditor* property_editor() { return properties_; }
  ScenePanel* scene_panel() { return scene_panel_; }
  ResultsPanel* results() { return results_; }
  /// The modes table and FRF plot of the open scene (the "Modes & FRF" tab beside the results).
  LinearPanel* linear() { return linear_; }
  /// Shows the "Modes & FRF" tab and starts the modes (or the FRF); false when it did not start.
  bool start_modes();
  bool start_frf();
  QLabel* breadcrumb() { return breadcrumb_; }
  QLineEdit* find_field() { return find_; }
  /// The message shown in the status bar.
  QString status_text() const { return status_label_->text(); }
  RunWorker* worker() { return &worker_; }
  QProgressBar* progress_bar() { return progress_; }

  /// Opens a scene; false (with a message box unless quiet) when it is not a scene.
  bool open_file(const QString& path, bool quiet = false);
  bool save_file(const QString& path);
  /// Validates and starts a run; false when validation failed (the block is marked).
  bool start_run();
  /// The last validation or solver error shown, "" after a successful run.
  const QString& last_error() const { return last_error_; }

 signals:
  void run_ended(const dydp::gui::RunOutcome& outcome);

 protected:
  void closeEvent(QCloseEvent* e) override;

 private:
  QTabWidget* set_up_docks();
  void set_up_menus();
  QList<QAction*> add_file_actions(QMenu* file);
  QList<QAction*> add_edit_actions(QMenu* edit);
  void add_view_actions(QMenu* view);
  void add_run_actions(QMenu* run_menu);
  void fill_main_toolbar(QToolBar* tools, const QList<QAction*>& file_actions, const QList<QAction*>& edit_actions);
  void set_up_level_toolbar();
  void connect_panels(QTabWidget* tabs);
  bool maybe_save();
  void update_title();
  void run_finished(const RunOutcome& outcome);
  void status(const QString& text);
  void update_breadcrumb(const QStringList& level);

  SceneController controller_;
  RunWorker worker_;
  Canvas* canvas_;
  Palette* palette_;
  PropertyEditor* properties_;
  ScenePanel* scene_panel_;
  ResultsPanel* results_;
  LinearPanel* linear_;
  QTabWidget* bottom_tabs_;
  QProgressBar* progress_;
  QAction* run_action_;
  QAction* cancel_action_;
  QLabel* status_label_;
  QLabel* breadcrumb_;
  QLineEdit* find_;
  QString last_error_;
};

}  // namespace dydp::gui
