#include "gui/property_editor.hpp"

#include <QMenu>
#include <QPushButton>

#include <QFormLayout>
#include <QHeaderView>
#include <QVBoxLayout>
#include <cmath>
#include <sstream>

namespace dydp::gui {
namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

QString number(double v) {
  std::ostringstream s;
  s << v;
  return q(s.str());
}

QString bounds(const engine::ParamSpec& p) {
  if (!std::isfinite(p.lower) && !std::isfinite(p.upper)) return {};
  return QString("[%1, %2]").arg(number(p.lower), number(p.upper));
}

enum Column { kName, kValue, kUnit, kDefault, kBounds };

}  // namespace

PropertyEditor::PropertyEditor(SceneController* controller, QWidget* parent)
    : QWidget(parent), controller_(controller) {
  auto* layout = new QVBoxLayout(this);
  auto* form = new QFormLayout;
  name_ = new QLineEdit;
  type_ = new QLabel;
  summary_ = new QLabel;
  summary_->setWordWrap(true);
  summary_->setStyleSheet("color: #555;");
  form->addRow(tr("Block"), name_);
  form->addRow(tr("Type"), type_);
  layout->addLayout(form);
  layout->addWidget(summary_);
  table_ = new QTableWidget(0, 5);
  table_->setHorizontalHeaderLabels({tr("Parameter"), tr("Value"), tr("Unit"), tr("Default"), tr("Bounds")});
  table_->verticalHeader()->hide();
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  table_->horizontalHeader()->setStretchLastSection(true);
  layout->addWidget(table_, 3);
  // A block parameter as a sensitivity direction in one step (also on the row's context menu).
  make_direction_ = new QPushButton(tr("Make direction d/dp of the selected parameter"));
  make_direction_->setObjectName("make_direction");
  make_direction_->setToolTip(tr("drive the parameter by a scene parameter (new, or the one already in $name) and "
                                 "add it to the sensitivity directions"));
  layout->addWidget(make_direction_);
  connect(make_direction_, &QPushButton::clicked, this, [this] {
    const int row = table_->currentRow();
    if (row < 0 || !table_->item(row, kName)) {
      status_->setText(tr("select a parameter row first"));
      return;
    }
    make_direction(table_->item(row, kName)->text());
  });
  table_->setContextMenuPolicy(Qt::CustomContextMenu);
  connect(table_, &QWidget::customContextMenuRequested, this, [this](const QPoint& at) {
    const QTableWidgetItem* item = table_->itemAt(at);
    if (!item || !table_->item(item->row(), kName)) return;
    const QString key = table_->item(item->row(), kName)->text();
    QMenu menu;
    menu.addAction(tr("Make %1 a direction d/dp").arg(key), this, [this, key] { make_direction(key); });
    menu.exec(table_->viewport()->mapToGlobal(at));
  });
  layout->addWidget(new QLabel(tr("Logged outputs")));
  outputs_ = new QListWidget;
  layout->addWidget(outputs_, 1);
  status_ = new QLabel;
  status_->setWordWrap(true);
  status_->setStyleSheet("color: #c02020;");
  layout->addWidget(status_);

  // Queued: an edit made from a table cell must not rebuild the table inside that cell's signal.
  connect(controller_, &SceneController::document_changed, this, &PropertyEditor::refresh,
          Qt::QueuedConnection);
  connect(name_, &QLineEdit::editingFinished, this, [this] {
    if (refreshing_ || block_.isEmpty() || !subsystem_.isEmpty() || name_->text() == block_) return;
    const QString to = name_->text().trimmed();
    const QString why = controller_->rename_block(block_, to);
    if (why.isEmpty()) {
      block_ = to;
    } else {
      status_->setText(why);
      name_->setText(block_);
    }
  });
  connect(table_, &QTableWidget::itemChanged, this, [this](QTableWidgetItem* item) {
    if (refreshing_ || item->column() != kValue) return;
    edit_value(table_->item(item->row(), kName)->text(), item->text());
  });
  connect(outputs_, &QListWidget::itemChanged, this, [this](QListWidgetItem* item) {
    if (refreshing_) return;
    controller_->set_output(item->data(Qt::UserRole).toString(), item->checkState() == Qt::Checked);
  });
  refresh();
}

QString PropertyEditor::make_direction(const QString& key) {
  QString parameter;
  const QString why = controller_->make_direction(block_, key, &parameter);
  status_->setText(why);
  if (why.isEmpty()) emit message(tr("%1.%2 is driven by $%3, a sensitivity direction: run to get dψ/d%3")
                                      .arg(block_, key, parameter));
  else emit message(tr("refused: %1").arg(why));
  return why;
}

void PropertyEditor::set_block(const QString& name, const QString& subsystem) {
  block_ = name;
  subsystem_ = name.isEmpty() ? QString() : subsystem;
  status_->clear();
  refresh();
}

QString PropertyEditor::edit_value(const QString& key, const QString& text) {
  const QString why = subsystem_.isEmpty() ? controller_->set_block_value(block_, key, text.trimmed())
                                           : controller_->set_block_value_in(subsystem_, block_, key, text.trimmed());
  status_->setText(why);
  if (!why.isEmpty()) emit message(tr("refused: %1").arg(why));
  // A refused value goes back to the document's.
  QMetaObject::invokeMethod(this, &PropertyEditor::refresh, Qt::QueuedConnection);
  return why;
}

void PropertyEditor::refresh() {
  refreshing_ = true;
  const SceneDocument& doc = controller_->document();
  const DocSubsystem* inside = subsystem_.isEmpty() ? nullptr : doc.find_subsystem(subsystem_.toStdString());
  const DocBlock* b = inside ? inside->find_block(block_.toStdString())
                             : subsystem_.isEmpty() ? doc.find_block(block_.toStdString()) : nullptr;
  name_->setReadOnly(inside != nullptr);
  make_direction_->setEnabled(inside == nullptr);
  outputs_->setEnabled(inside == nullptr);
  const engine::BlockType* type = b ? engine::Registry::global().find(b->type) : nullptr;
  setEnabled(b != nullptr);
  table_->setRowCount(0);
  outputs_->clear();
  if (!b) {
    block_.clear();
    subsystem_.clear();
    name_->clear();
    type_->clear();
    summary_->setText(tr("Select a block on the canvas."));
    refreshing_ = false;
    return;
  }
  name_->setText(inside ? subsystem_ + "." + block_ : block_);
  type_->setText(q(b->type));
  const DocSubsystem* def = doc.subsystem_of(*b);
  summary_->setText(type ? q(type->summary)
                         : def ? tr("subsystem %1: %2 (double-click the block to open it)").arg(q(def->name), q(def->description))
                               : tr("unknown block type"));
  auto add_row = [&](const QString& key, const QString& value, const QString& unit, const QString& def,
                     const QString& range, const QString& tip, bool setting) {
    const int row = table_->rowCount();
    table_->insertRow(row);
    auto* name = new QTableWidgetItem(key);
    name->setFlags(Qt::ItemIsEnabled);
    name->setToolTip(tip);
    if (setting) name->setForeground(QColor(40, 90, 160));
    table_->setItem(row, kName, name);
    auto* v = new QTableWidgetItem(value);
    v->setToolTip(setting ? tr("setting: a plain value, [a, b] for a list")
                  : inside ? tr("a number, or $name of a parameter of subsystem %1; empty: the default").arg(subsystem_)
                           : tr("a number, or $name of a scene parameter; empty: the default"));
    table_->setItem(row, kValue, v);
    for (auto [col, text] : {std::pair{kUnit, unit}, {kDefault, def}, {kBounds, range}}) {
      auto* item = new QTableWidgetItem(text);
      item->setFlags(Qt::ItemIsEnabled);
      item->setForeground(QColor(90, 90, 90));
      table_->setItem(row, col, item);
    }
  };
  if (type) {
    for (const auto& p : type->parameters) {
      const SceneValue* v = b->find(p.name);
      add_row(q(p.name), v ? q(v->text()) : QString(), q(p.unit), number(p.default_value), bounds(p),
              q(p.description) + (p.differentiable ? "" : tr(" (not differentiable)")), false);
    }
    for (const auto& s : type->settings) {
      const SceneValue* v = b->find(s.name);
      add_row(q(s.name), v ? q(v->text()) : QString(), tr("setting"),
              s.required ? tr("required") : q(s.default_value), {}, q(s.description), true);
    }
  }
  if (def)
    for (const auto& [name, default_value] : def->parameters) {
      const SceneValue* v = b->find(name);
      add_row(q(name), v ? q(v->text()) : QString(), {}, default_value.items.empty() ? tr("required") : q(default_value.text()),
              {}, tr("parameter of subsystem %1").arg(q(def->name)), false);
    }
  if (inside) {
    // Outputs inside are logged through the instance (`corner_fl.damper.force`) at the scene's level.
    refreshing_ = false;
    return;
  }
  const BlockPorts ports = controller_->ports(b->name);
  auto add_output = [&](const QString& label, const QString& ref) {
    auto* item = new QListWidgetItem(label, outputs_);
    item->setData(Qt::UserRole, ref);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    const bool on = std::find(doc.outputs.begin(), doc.outputs.end(), ref.toStdString()) != doc.outputs.end();
    item->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  };
  if (ports.is_objective) add_output(tr("objective ψ (%1)").arg(block_), block_);
  else if (!ports.outputs.empty()) add_output(tr("all outputs (%1)").arg(block_), block_);
  for (const auto& p : ports.outputs) add_output(q(b->name + "." + p.name), q(b->name + "." + p.name));
  if (!ports.error.empty()) status_->setText(q(ports.error));
  refreshing_ = false;
}

}  // namespace dydp::gui
