// The linear analyses of the open scene (engine/linear/, as `dydp modes` and `dydp frf` compute
// them): the modes about its static equilibrium as a table (frequency, damping ratio, a name from
// the states that dominate the mode, the dominant states with their shares) and the frequency
// response from a chosen input (with its rate, for a road's height and zdot) to a chosen output,
// magnitude and phase over a log-spaced frequency grid. The equilibrium holds the scene's
// `initial.hold` and the signals of the hold field. Computed on the run worker's thread; a
// failure (no equilibrium in reach, an unknown signal) is shown in the panel.
#pragma once

#include <QComboBox>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QTableWidget>
#include <QWidget>
#include <memory>
#include <string>
#include <vector>

#include "engine/linear/equilibrium.hpp"
#include "engine/linear/frequency_response.hpp"
#include "engine/linear/modes.hpp"

QT_BEGIN_NAMESPACE
class QChartView;
class QDoubleSpinBox;
QT_END_NAMESPACE

namespace dydp::gui {

class RunWorker;
class SceneController;

/// What one analysis asks for, and what it gives (filled on the worker's thread).
struct LinearRequest {
  bool frf = false;                  ///< false: the modes
  std::vector<std::string> holds;    ///< SIGNAL=VALUE, beside the scene's initial.hold
  std::string input, rate, output;   ///< FRF: signal names (rate "" for none)
  double low_hz = 0.5, high_hz = 30.0;
  int points = 200;
};
struct LinearResult {
  engine::Equilibrium equilibrium;
  engine::LinearModel model;
  std::vector<engine::Mode> modes;
  engine::FrequencyResponse response;
};

/// The analysis itself, without widgets (the panel runs it on the worker): the equilibrium at
/// time.start with the scene's initial.hold and the request's holds (one of the same signal
/// replacing the scene's), the model about it, then the modes or the frequency response.
/// Throws InputError (a bad signal or hold) or SolverError (no equilibrium in reach).
LinearResult compute_linear(engine::Diagram& d, const LinearRequest& request);

/// A name for a mode from the state that dominates it most: "body heave", "body pitch", "body
/// roll" (a multibody model's z, pitch, roll), "wheel hop (car.q.lca_fr)" (a wheel's coordinate or
/// its link's), "damper hydraulics (corner_fl.damper)", "filter (wk)", else that state's label.
QString mode_name(const engine::Mode& mode);

class LinearPanel : public QWidget {
  Q_OBJECT

 public:
  LinearPanel(SceneController* controller, RunWorker* worker, QWidget* parent = nullptr);

  /// Starts the modes (or the FRF) of the open scene on the worker; false when it could not start
  /// (the worker busy, the scene invalid: message() says why).
  bool compute_modes();
  bool compute_frf();
  /// Whether an analysis started here is still going on.
  bool busy() const { return busy_; }

  QTableWidget* modes_table() { return table_; }
  QChartView* frf_chart() { return chart_; }
  QComboBox* input_box() { return input_; }
  QComboBox* rate_box() { return rate_; }
  QComboBox* output_box() { return output_; }
  QLineEdit* hold_field() { return hold_; }
  QSpinBox* points_box() { return points_; }
  /// The last error shown ("" after an analysis that succeeded), and the status line.
  QString error() const { return error_; }
  QString message() const { return message_->text(); }
  /// The last result (modes or FRF) and the modes shown in the table, in row order.
  const LinearResult& result() const { return result_; }
  const std::vector<engine::Mode>& shown_modes() const { return shown_; }
  /// Lists the open scene's output ports in the signal boxes (their texts stay editable).
  void refresh_signals();

 signals:
  /// An analysis ended: `error` empty when it succeeded.
  void analysis_ended(const QString& error);

 private:
  bool start(const LinearRequest& request);
  void finished(const QString& error);
  void show_modes();
  void show_response();
  void show_error(const QString& error);

  SceneController* controller_;
  RunWorker* worker_;
  bool busy_ = false;
  bool frf_pending_ = false;
  std::shared_ptr<LinearResult> pending_;
  LinearRequest request_;
  LinearResult result_;
  std::vector<engine::Mode> shown_;
  QString error_;

  QLineEdit* hold_;
  QPushButton* modes_button_;
  QPushButton* frf_button_;
  QComboBox* input_;
  QComboBox* rate_;
  QComboBox* output_;
  QDoubleSpinBox* low_;
  QDoubleSpinBox* high_;
  QSpinBox* points_;
  QLabel* message_;
  QTableWidget* table_;
  QChartView* chart_;
};

}  // namespace dydp::gui
