#include "gui/linear_panel.hpp"

#include <QChart>
#include <QChartView>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLegend>
#include <QSplitter>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "engine/framework/errors.hpp"
#include "engine/linear/signal_lookup.hpp"
#include "gui/chart_curves.hpp"
#include "gui/run_worker.hpp"
#include "gui/scene_controller.hpp"

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

constexpr double kDegrees = 57.29577951308232;
/// |lambda| below this [1/s]: a coordinate no force holds or a conserved quantity, not a mode
/// (as `dydp modes` prints them).
constexpr double kRigid = 1e-3;

/// The state's own name: the label after its block ("car.q.pitch" -> "pitch").
std::string state_of(const std::string& label, std::string& block) {
  const auto dot = label.rfind('.');
  block = dot == std::string::npos ? "" : label.substr(0, dot);
  return dot == std::string::npos ? label : label.substr(dot + 1);
}

bool contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }

}  // namespace

LinearResult compute_linear(engine::Diagram& d, const LinearRequest& request) {
  engine::EquilibriumOptions o;
  o.time = d.time.start;
  o.held = d.initial.held;
  for (const auto& [offset, value] : engine::held_signals(d, request.holds, "hold")) {
    auto same = std::find_if(o.held.begin(), o.held.end(), [o = offset](const auto& h) { return h.first == o; });
    if (same != o.held.end()) same->second = value;
    else o.held.push_back({offset, value});
  }
  LinearResult r;
  if (request.frf) {  // the names checked before the equilibrium's work
    engine::signal_offsets(d, request.input, "input");
    if (!request.rate.empty()) engine::signal_offsets(d, request.rate, "rate");
    if (engine::signal_offsets(d, request.output, "output").size() != 1)
      throw engine::InputError("output", 0, request.output, "a port of several elements: name one, BLOCK.PORT[i]");
    if (!(request.low_hz > 0) || !(request.high_hz > request.low_hz) || request.points < 2)
      throw engine::InputError("frequencies", 0, "", "expected 0 < low < high and at least 2 points");
  }
  r.equilibrium = engine::find_equilibrium(d, o);
  const engine::Equilibrium& eq = r.equilibrium;
  if (!request.frf) {
    r.model = engine::linearize(d, eq.t, eq.x, {}, {}, eq.held);
    r.modes = engine::modes(r.model);
    return r;
  }
  std::vector<std::string> inputs = {request.input};
  if (!request.rate.empty()) inputs.push_back(request.rate);
  r.model = engine::linearize(d, eq.t, eq.x, inputs, {request.output}, eq.held);
  r.response = engine::frequency_response(r.model, {0, request.rate.empty() ? -1 : 1},
                                          engine::log_frequencies(request.low_hz, request.high_hz, request.points));
  return r;
}

QString mode_name(const engine::Mode& mode) {
  if (mode.dominant.empty()) return {};
  std::string block;
  const std::string first = mode.dominant.front().first;
  const std::string state = state_of(first, block);
  // A multibody model's coordinates (q) and speeds (u, qd): the body's heave, pitch and roll;
  // a wheel's coordinate or a suspension link's: wheel hop.
  const bool coordinate = contains(block, ".q") || contains(block, ".u") || contains(block, ".qd");
  if (coordinate || block.empty()) {
    if (state == "z" || state == "z_body" || state == "heave") return QObject::tr("body heave");
    if (state == "pitch") return QObject::tr("body pitch");
    if (state == "roll") return QObject::tr("body roll");
    if (state == "yaw") return QObject::tr("body yaw");
    // The wheel's own coordinate, or that of the link carrying it (lower control arm, trailing link).
    for (const char* part : {"wheel", "arm", "link", "knuckle", "lca", "uca", "trailing"})
      if (contains(state, part)) return QObject::tr("wheel hop (%1)").arg(q(first));
  }
  if (contains(block, "damper")) return QObject::tr("damper hydraulics (%1)").arg(q(block));
  if (contains(block, "wk") || contains(block, "filter")) return QObject::tr("filter (%1)").arg(q(block));
  return q(first);
}

LinearPanel::LinearPanel(SceneController* controller, RunWorker* worker, QWidget* parent)
    : QWidget(parent), controller_(controller), worker_(worker) {
  auto* layout = new QHBoxLayout(this);
  auto* left = new QWidget;
  auto* form = new QFormLayout(left);
  form->setContentsMargins(0, 0, 0, 0);
  hold_ = new QLineEdit;
  hold_->setObjectName("linear_hold");
  hold_->setPlaceholderText(tr("SIGNAL=VALUE, ... (e.g. rig.zdot=0)"));
  hold_->setToolTip(tr("Signals the equilibrium holds at other values, beside the scene's initial.hold"));
  form->addRow(tr("Hold"), hold_);
  modes_button_ = new QPushButton(tr("Compute modes"));
  modes_button_->setObjectName("compute_modes");
  form->addRow(modes_button_);
  const auto signal_box = [](const char* name) {
    auto* box = new QComboBox;
    box->setObjectName(name);
    box->setEditable(true);
    box->setInsertPolicy(QComboBox::NoInsert);
    box->setMinimumContentsLength(22);
    return box;
  };
  input_ = signal_box("frf_input");
  rate_ = signal_box("frf_rate");
  output_ = signal_box("frf_output");
  rate_->setToolTip(tr("The signal that is the input's time derivative (a pad's zdot beside its z), or empty"));
  form->addRow(tr("FRF input"), input_);
  form->addRow(tr("its rate"), rate_);
  form->addRow(tr("output"), output_);
  low_ = new QDoubleSpinBox;
  high_ = new QDoubleSpinBox;
  for (QDoubleSpinBox* b : {low_, high_}) {
    b->setDecimals(3);
    b->setRange(0.001, 1e5);
    b->setSuffix(" Hz");
  }
  low_->setValue(0.5);
  high_->setValue(30.0);
  points_ = new QSpinBox;
  points_->setRange(2, 5000);
  points_->setValue(200);
  auto* range = new QHBoxLayout;
  range->addWidget(low_);
  range->addWidget(high_);
  range->addWidget(points_);
  form->addRow(tr("from, to, points"), range);
  frf_button_ = new QPushButton(tr("Compute FRF"));
  frf_button_->setObjectName("compute_frf");
  form->addRow(frf_button_);
  message_ = new QLabel;
  message_->setWordWrap(true);
  message_->setObjectName("linear_message");
  form->addRow(message_);

  table_ = new QTableWidget(0, 4);
  table_->setObjectName("modes_table");
  table_->setHorizontalHeaderLabels({tr("f [Hz]"), tr("ζ"), tr("mode"), tr("dominant states")});
  table_->verticalHeader()->hide();
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  table_->horizontalHeader()->setStretchLastSection(true);
  chart_ = new QChartView(new QChart);
  chart_->setObjectName("frf_chart");
  chart_->setRenderHint(QPainter::Antialiasing);
  chart_->chart()->legend()->setAlignment(Qt::AlignBottom);
  chart_->chart()->setMargins(QMargins(4, 4, 4, 4));
  chart_->setMinimumHeight(140);
  auto* split = new QSplitter(Qt::Horizontal);
  split->addWidget(left);
  split->addWidget(table_);
  split->addWidget(chart_);
  split->setStretchFactor(1, 3);
  split->setStretchFactor(2, 4);
  split->setSizes({330, 760, 900});
  layout->addWidget(split);

  connect(modes_button_, &QPushButton::clicked, this, [this] { compute_modes(); });
  connect(frf_button_, &QPushButton::clicked, this, [this] { compute_frf(); });
  connect(worker_, &RunWorker::job_finished, this, [this](const QString& error) {
    if (busy_) finished(error);
  });
  connect(controller_, &SceneController::file_changed, this, &LinearPanel::refresh_signals);
  refresh_signals();
}

void LinearPanel::refresh_signals() {
  std::vector<QString> names;
  for (const DocBlock& b : controller_->document().blocks) {
    const BlockPorts ports = controller_->ports(b.name);
    for (const auto& p : ports.outputs) names.push_back(q(b.name + "." + p.name));
  }
  const QString input = input_->currentText(), rate = rate_->currentText(), output = output_->currentText();
  for (QComboBox* box : {input_, rate_, output_}) {
    box->clear();
    if (box == rate_) box->addItem(QString());
    for (const QString& n : names) box->addItem(n);
  }
  // The first choice: a pad's height and its rate (z, zdot) for a road input, the first logged
  // signal for the output; what was chosen before stays when the scene has it.
  QString first_input, first_rate;
  for (const QString& n : names)
    if (n.endsWith(".z") && std::find(names.begin(), names.end(), n + "dot") != names.end()) {
      first_input = n;
      first_rate = n + "dot";
      break;
    }
  QString first_output;  // the first logged port (not an objective, which is no signal here)
  for (const std::string& o : controller_->document().outputs)
    if (o.find('.') != std::string::npos) {
      first_output = q(o);
      break;
    }
  // A choice of another scene is not kept.
  const auto known = [&](const QString& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
  const bool keep = known(input);
  input_->setCurrentText(keep ? input : first_input);
  rate_->setCurrentText(keep && (rate.isEmpty() || known(rate)) ? rate : first_rate);
  output_->setCurrentText(!output.isEmpty() && known(output.section('[', 0, 0)) ? output : first_output);
}

bool LinearPanel::compute_modes() {
  LinearRequest r;
  r.frf = false;
  return start(r);
}

bool LinearPanel::compute_frf() {
  LinearRequest r;
  r.frf = true;
  r.input = input_->currentText().trimmed().toStdString();
  r.rate = rate_->currentText().trimmed().toStdString();
  r.output = output_->currentText().trimmed().toStdString();
  r.low_hz = low_->value();
  r.high_hz = high_->value();
  r.points = points_->value();
  return start(r);
}

bool LinearPanel::start(const LinearRequest& base) {
  if (busy_ || worker_->running()) {
    message_->setText(tr("busy: a run or an analysis is going on"));
    return false;
  }
  LinearRequest request = base;
  for (const QString& h : hold_->text().split(',', Qt::SkipEmptyParts))
    if (!h.trimmed().isEmpty()) request.holds.push_back(h.trimmed().toStdString());
  auto diagram = std::make_shared<engine::Diagram>();
  try {
    *diagram = controller_->load_for_run();
  } catch (const engine::InputError& e) {
    show_error(tr("invalid scene: %1").arg(QString::fromUtf8(e.what())));
    return false;
  }
  auto out = std::make_shared<LinearResult>();
  pending_ = out;
  request_ = request;
  busy_ = true;
  modes_button_->setEnabled(false);
  frf_button_->setEnabled(false);
  message_->setText(request.frf ? tr("computing the frequency response...") : tr("computing the modes..."));
  worker_->start_job([diagram, request, out] { *out = compute_linear(*diagram, request); });
  return true;
}

void LinearPanel::finished(const QString& error) {
  busy_ = false;
  modes_button_->setEnabled(true);
  frf_button_->setEnabled(true);
  if (!error.isEmpty()) {
    show_error(error);
  } else {
    error_.clear();
    result_ = std::move(*pending_);
    if (request_.frf) show_response();
    else show_modes();
  }
  pending_.reset();
  emit analysis_ended(error);
}

void LinearPanel::show_error(const QString& error) {
  error_ = error;
  message_->setText(error);
  message_->setStyleSheet("color: #c02020;");
  if (!request_.frf) {
    table_->setRowCount(0);
    shown_.clear();
  }
}

void LinearPanel::show_modes() {
  message_->setStyleSheet({});
  shown_.clear();
  int rigid = 0;
  for (const engine::Mode& m : result_.modes) {
    if (std::abs(m.eigenvalue) < kRigid) ++rigid;
    else shown_.push_back(m);
  }
  table_->setRowCount(static_cast<int>(shown_.size()));
  for (int row = 0; row < static_cast<int>(shown_.size()); ++row) {
    const engine::Mode& m = shown_[row];
    auto* f = new QTableWidgetItem(QString::number(m.frequency_hz, 'f', 3));
    f->setData(Qt::UserRole, m.frequency_hz);
    f->setToolTip(tr("eigenvalue %1 %2 %3i 1/s")
                      .arg(m.eigenvalue.real(), 0, 'g', 10)
                      .arg(m.eigenvalue.imag() < 0 ? "-" : "+")
                      .arg(std::abs(m.eigenvalue.imag()), 0, 'g', 10));
    auto* zeta = new QTableWidgetItem(QString::number(m.damping_ratio, 'f', 3));
    zeta->setData(Qt::UserRole, m.damping_ratio);
    QStringList dominant;
    for (const auto& [state, share] : m.dominant)
      dominant << QString("%1 %2 %").arg(q(state)).arg(100 * share, 0, 'f', 0);
    table_->setItem(row, 0, f);
    table_->setItem(row, 1, zeta);
    table_->setItem(row, 2, new QTableWidgetItem(mode_name(m)));
    table_->setItem(row, 3, new QTableWidgetItem(dominant.join(", ")));
  }
  message_->setText(tr("%1 modes of %2 states about the equilibrium at t = %3 s (residual %4)%5")
                        .arg(shown_.size())
                        .arg(result_.model.states.size())
                        .arg(result_.equilibrium.t)
                        .arg(result_.equilibrium.residual, 0, 'g', 2)
                        .arg(rigid ? tr("; %1 eigenvalues below 1e-3 1/s left out: coordinates no force holds, "
                                        "conserved quantities")
                                         .arg(rigid)
                                   : QString()));
}

void LinearPanel::show_response() {
  message_->setStyleSheet({});
  const engine::FrequencyResponse& h = result_.response;
  const QString name = q(request_.output) + " / " + q(request_.input);
  Curve magnitude{tr("|%1|").arg(name), "magnitude", &h.frequency_hz, {}, false};
  Curve phase{tr("phase of %1").arg(name), "phase", &h.frequency_hz, {}, false};
  for (const auto& row : h.H) {
    magnitude.v.push_back(std::abs(row[0]));
    phase.v.push_back(std::arg(row[0]) * kDegrees);
  }
  draw_curves(chart_->chart(), tr("frequency response %1 about the equilibrium").arg(name), {magnitude, phase},
              [](const QString& unit) { return unit == "phase" ? QObject::tr("phase [deg]") : QObject::tr("|H|"); },
              ChartAxes{tr("f [Hz]"), true, true});
  size_t peak = 0;
  for (size_t f = 0; f < h.H.size(); ++f)
    if (std::abs(h.H[f][0]) > std::abs(h.H[peak][0])) peak = f;
  message_->setText(tr("%1 at %2 frequencies, %3 to %4 Hz: peak |H| %5 at %6 Hz")
                        .arg(name)
                        .arg(h.frequency_hz.size())
                        .arg(request_.low_hz)
                        .arg(request_.high_hz)
                        .arg(h.H.empty() ? 0.0 : std::abs(h.H[peak][0]), 0, 'g', 4)
                        .arg(h.frequency_hz.empty() ? 0.0 : h.frequency_hz[peak], 0, 'g', 4));
}

}  // namespace dydp::gui
