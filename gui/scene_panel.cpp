#include "gui/scene_panel.hpp"

#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QPushButton>
#include <QVBoxLayout>
#include <algorithm>

#include "engine/scene/scene_keys.hpp"

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }
std::string s(const QString& q) { return q.trimmed().toStdString(); }

enum Column { kName, kValue, kUnit, kLow, kHigh, kDirection };

}  // namespace

ScenePanel::ScenePanel(SceneController* controller, QWidget* parent)
    : QWidget(parent), controller_(controller) {
  auto* layout = new QVBoxLayout(this);
  auto* info = new QFormLayout;
  name_ = new QLineEdit;
  description_ = new QLineEdit;
  info->addRow(tr("Scene"), name_);
  info->addRow(tr("Description"), description_);
  layout->addLayout(info);
  auto edited = [this] {
    if (!refreshing_) controller_->set_scene_info(name_->text().trimmed(), description_->text().trimmed());
  };
  connect(name_, &QLineEdit::editingFinished, this, edited);
  connect(description_, &QLineEdit::editingFinished, this, edited);

  auto* time_box = new QGroupBox(tr("Time [s]"));
  auto* time_form = new QFormLayout(time_box);
  for (const char* key : engine::kTimeKeys) {
    auto* e = new QLineEdit;
    time_[key] = e;
    time_form->addRow(key, e);
    connect(e, &QLineEdit::editingFinished, this, [this, key, e] {
      if (!refreshing_) report(controller_->set_time(key, e->text().trimmed()));
    });
  }
  layout->addWidget(time_box);

  auto* solver_box = new QGroupBox(tr("Solver"));
  auto* solver_form = new QFormLayout(solver_box);
  method_ = new QComboBox;
  method_->addItems({"", "bdf", "adams", "rk4", "sdirk2", "rosw"});
  method_->setToolTip(tr("bdf: stiff scenes; adams: non-stiff; rk4, sdirk2, rosw: fixed step (empty: bdf)"));
  solver_form->addRow("method", method_);
  connect(method_, &QComboBox::currentTextChanged, this, [this](const QString& m) {
    if (!refreshing_) report(controller_->set_solver("method", m));
  });
  // Every key of `solver:` the loader accepts (method above): a scene's settings are all shown
  // and editable, not only the tolerances.
  for (const char* key : engine::kSolverKeys) {
    if (std::string_view(key) == "method") continue;
    const bool is_switch = std::find(engine::kSolverSwitches.begin(), engine::kSolverSwitches.end(),
                                     std::string_view(key)) != engine::kSolverSwitches.end();
    auto* e = new QLineEdit;
    e->setPlaceholderText(is_switch ? tr("default (true or false)") : tr("default"));
    solver_[key] = e;
    solver_form->addRow(key, e);
    connect(e, &QLineEdit::editingFinished, this, [this, key, e] {
      if (!refreshing_) report(controller_->set_solver(key, e->text().trimmed()));
    });
  }
  layout->addWidget(solver_box);

  // Where runs start (docs/scenes.md, "Where a run starts"), as YAML on one line.
  auto* initial_box = new QGroupBox(tr("Initial state"));
  auto* initial_form = new QFormLayout(initial_box);
  initial_ = new QLineEdit;
  initial_->setObjectName("scene_initial");
  initial_->setPlaceholderText(tr("declared (or: equilibrium, {state: equilibrium, hold: {SIGNAL: VALUE}})"));
  initial_->setToolTip(tr("equilibrium: runs start at the static equilibrium at time.start, with the inputs held "
                          "there and the hold signals at their values"));
  initial_form->addRow("initial", initial_);
  connect(initial_, &QLineEdit::editingFinished, this, [this] {
    if (!refreshing_) report(controller_->set_initial(initial_->text()));
  });
  layout->addWidget(initial_box);

  auto* param_box = new QGroupBox(tr("Scene parameters (blocks use them as $name)"));
  auto* param_layout = new QVBoxLayout(param_box);
  params_ = new QTableWidget(0, 6);
  params_->setHorizontalHeaderLabels({tr("Name"), tr("Value"), tr("Unit"), tr("Low"), tr("High"), tr("d/dp")});
  params_->verticalHeader()->hide();
  params_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  params_->horizontalHeader()->setStretchLastSection(true);
  param_layout->addWidget(params_);
  auto* buttons = new QHBoxLayout;
  auto* add = new QPushButton(tr("Add"));
  auto* remove = new QPushButton(tr("Remove"));
  buttons->addWidget(add);
  buttons->addWidget(remove);
  buttons->addStretch();
  param_layout->addLayout(buttons);
  layout->addWidget(param_box, 1);
  status_ = new QLabel;
  status_->setWordWrap(true);
  status_->setStyleSheet("color: #c02020;");
  layout->addWidget(status_);

  connect(add, &QPushButton::clicked, this, [this] {
    const std::string stem = "p";
    std::string name = stem;
    for (int i = 1; controller_->document().find_parameter(name); ++i) name = stem + std::to_string(i);
    report(controller_->add_scene_parameter(q(name), "1.0"));
  });
  connect(remove, &QPushButton::clicked, this, [this] {
    const int row = params_->currentRow();
    if (row >= 0) report(controller_->remove_scene_parameter(params_->item(row, kName)->data(Qt::UserRole).toString()));
  });
  connect(params_, &QTableWidget::itemChanged, this, [this](QTableWidgetItem* item) {
    if (refreshing_) return;
    if (item->column() == kDirection)
      controller_->set_sensitivity(params_->item(item->row(), kName)->data(Qt::UserRole).toString(),
                                   item->checkState() == Qt::Checked);
    else
      edit_parameter(item->row());
  });
  connect(controller_, &SceneController::document_changed, this, &ScenePanel::refresh, Qt::QueuedConnection);
  refresh();
}

void ScenePanel::report(const QString& why) {
  status_->setText(why);
  if (!why.isEmpty()) {
    emit message(tr("refused: %1").arg(why));
    QMetaObject::invokeMethod(this, &ScenePanel::refresh, Qt::QueuedConnection);
  }
}

void ScenePanel::edit_parameter(int row) {
  DocParameter p;
  const QString old = params_->item(row, kName)->data(Qt::UserRole).toString();
  if (const DocParameter* current = controller_->document().find_parameter(s(old))) p = *current;
  p.name = s(params_->item(row, kName)->text());
  p.value = s(params_->item(row, kValue)->text());
  p.unit = s(params_->item(row, kUnit)->text());
  p.low = s(params_->item(row, kLow)->text());
  p.high = s(params_->item(row, kHigh)->text());
  report(controller_->update_scene_parameter(old, p));
}

void ScenePanel::refresh() {
  refreshing_ = true;
  const SceneDocument& doc = controller_->document();
  name_->setText(q(doc.scene));
  description_->setText(q(doc.description));
  for (auto& [key, e] : time_) {
    const std::string* v = find_field(doc.time, s(key));
    e->setText(v ? q(*v) : QString());
  }
  for (auto& [key, e] : solver_) {
    const std::string* v = find_field(doc.solver, s(key));
    e->setText(v ? q(*v) : QString());
  }
  initial_->setText(q(doc.initial));
  const std::string* method = find_field(doc.solver, "method");
  method_->setCurrentText(method ? q(*method) : QString());
  params_->setRowCount(0);
  for (const DocParameter& p : doc.parameters) {
    const int row = params_->rowCount();
    params_->insertRow(row);
    auto* name = new QTableWidgetItem(q(p.name));
    name->setData(Qt::UserRole, q(p.name));
    if (!p.description.empty()) name->setToolTip(q(p.description));
    params_->setItem(row, kName, name);
    params_->setItem(row, kValue, new QTableWidgetItem(q(p.value)));
    params_->setItem(row, kUnit, new QTableWidgetItem(q(p.unit)));
    params_->setItem(row, kLow, new QTableWidgetItem(q(p.low)));
    params_->setItem(row, kHigh, new QTableWidgetItem(q(p.high)));
    auto* dir = new QTableWidgetItem;
    dir->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    const bool on = std::find(doc.sensitivities.begin(), doc.sensitivities.end(), p.name) != doc.sensitivities.end();
    dir->setCheckState(on ? Qt::Checked : Qt::Unchecked);
    dir->setToolTip(tr("a sensitivity direction: compute d(signal)/d(%1)").arg(q(p.name)));
    params_->setItem(row, kDirection, dir);
  }
  refreshing_ = false;
}

}  // namespace dydp::gui
