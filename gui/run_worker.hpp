// Runs a loaded diagram in a worker thread: progress as a fraction of the time span, a cancel
// that stops the solver at the next output time, and the result (or the failure) delivered
// back on the thread that owns the worker.
#pragma once

#include <QObject>
#include <QString>
#include <QThread>
#include <atomic>
#include <functional>
#include <memory>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::gui {

struct RunOutcome {
  enum class Status { finished, cancelled, failed };
  Status status = Status::failed;
  QString message;                             ///< the failure ("t = T s: block B: reason")
  QString block;                               ///< the block a solver failure names, if any
  std::shared_ptr<const engine::Diagram> diagram;
  std::shared_ptr<const engine::RunResult> result;  ///< set when finished
};

class RunWorker : public QObject {
  Q_OBJECT

 public:
  explicit RunWorker(QObject* parent = nullptr);
  ~RunWorker() override;

  /// Starts running d; false when a run is already going on.
  bool start(engine::Diagram d, bool sensitivities = true);
  /// Runs `job` on the worker thread instead of a run (the linear analyses, gui/linear_panel.hpp);
  /// job_finished(message) follows on the owner's thread: "" when the job returned, else what it
  /// threw. False when a run or a job is going on. The job must not touch widgets.
  bool start_job(std::function<void()> job);
  /// Asks the running solver to stop at its next output time; finished() follows (cancelled).
  void cancel();
  bool running() const { return thread_ != nullptr; }
  /// Blocks until the current run (if any) has ended and finished() was emitted.
  void wait();

 signals:
  void progress(double fraction);
  void finished(const dydp::gui::RunOutcome& outcome);
  void job_finished(const QString& message);

 private:
  void deliver(RunOutcome outcome);
  void end_thread();
  QThread* thread_ = nullptr;
  std::shared_ptr<std::atomic<bool>> cancel_;
};

}  // namespace dydp::gui

Q_DECLARE_METATYPE(dydp::gui::RunOutcome)
