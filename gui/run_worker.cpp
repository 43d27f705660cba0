#include "gui/run_worker.hpp"

#include <QCoreApplication>
#include <QMetaObject>

#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"

namespace dydp::gui {
namespace {

/// Thrown from the progress callback to stop a run. The solvers let exceptions from the callback
/// through; their SUNDIALS objects are released by their owners' destructors on the way out.
struct RunCancelled {};

}  // namespace

RunWorker::RunWorker(QObject* parent) : QObject(parent) { qRegisterMetaType<RunOutcome>(); }

RunWorker::~RunWorker() {
  if (thread_) {
    cancel();
    thread_->wait();
  }
}

bool RunWorker::start(engine::Diagram d, bool sensitivities) {
  if (thread_) return false;
  auto diagram = std::make_shared<engine::Diagram>(std::move(d));
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  cancel_ = cancel;
  thread_ = QThread::create([this, diagram, cancel, sensitivities] {
    RunOutcome outcome;
    outcome.diagram = diagram;
    const double t0 = diagram->time.start, span = diagram->time.stop - diagram->time.start;
    double last = -1.0;
    engine::RunOptions options;
    options.sensitivities = sensitivities;
    options.progress = [&](double t) {
      if (cancel->load()) throw RunCancelled{};
      const double fraction = (t - t0) / span;
      if (fraction - last >= 0.01 || fraction >= 1.0) {
        last = fraction;
        QMetaObject::invokeMethod(this, [this, fraction] { emit progress(fraction); }, Qt::QueuedConnection);
      }
    };
    try {
      // `initial: equilibrium`: the start is found here, off the GUI thread, before the run.
      outcome.result = std::make_shared<const engine::RunResult>(engine::run_from_initial(*diagram, options));
      outcome.status = RunOutcome::Status::finished;
    } catch (const RunCancelled&) {
      outcome.status = RunOutcome::Status::cancelled;
    } catch (const engine::SolverError& e) {
      outcome.message = QString::fromStdString(e.what());
      outcome.block = QString::fromStdString(e.block());
    } catch (const std::exception& e) {
      outcome.message = QString::fromStdString(e.what());
    }
    QMetaObject::invokeMethod(this, [this, outcome] { deliver(outcome); }, Qt::QueuedConnection);
  });
  thread_->start();
  return true;
}

bool RunWorker::start_job(std::function<void()> job) {
  if (thread_) return false;
  thread_ = QThread::create([this, job = std::move(job)] {
    QString message;
    try {
      job();
    } catch (const std::exception& e) {
      message = QString::fromStdString(e.what());
      if (message.isEmpty()) message = tr("failed");
    } catch (...) {
      message = tr("failed");
    }
    QMetaObject::invokeMethod(
        this,
        [this, message] {
          end_thread();
          emit job_finished(message);
        },
        Qt::QueuedConnection);
  });
  thread_->start();
  return true;
}

void RunWorker::end_thread() {
  thread_->wait();
  delete thread_;
  thread_ = nullptr;
  cancel_.reset();
}

void RunWorker::deliver(RunOutcome outcome) {
  end_thread();
  emit finished(outcome);
}

void RunWorker::cancel() {
  if (cancel_) cancel_->store(true);
}

void RunWorker::wait() {
  while (thread_) QCoreApplication::processEvents(QEventLoop::WaitForMoreEvents, 50);
}

}  // namespace dydp::gui
