#include "gui/scene_controller.hpp"

#include "gui/automatic_layout.hpp"
#include "gui/subsystem_grouping.hpp"
#include "gui/subsystem_ports.hpp"
#include "gui/subsystem_yaml.hpp"

#include <QDir>
#include <QFileInfo>
#include <QRegularExpression>
#include <QTemporaryFile>
#include <QUndoCommand>
#include <yaml-cpp/yaml.h>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "engine/scene/scene_keys.hpp"

namespace dydp::gui {

/// One undo step: the document before and after the edit.
class DocumentEdit : public QUndoCommand {
 public:
  DocumentEdit(SceneController* c, const QString& label, SceneDocument before, SceneDocument after)
      : QUndoCommand(label), c_(c), before_(std::move(before)), after_(std::move(after)) {}
  void undo() override { c_->replace(before_); }
  void redo() override { c_->replace(after_); }

 private:
  SceneController* c_;
  SceneDocument before_, after_;
};

namespace {

std::string s(const QString& q) { return q.toStdString(); }
QString q(const std::string& s) { return QString::fromStdString(s); }

std::string number_text(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

bool valid_name(const std::string& name) {
  return !name.empty() && name.find_first_of(". \t:#$[]{},") == std::string::npos;
}

const engine::PortDecl* find_port(const std::vector<engine::PortDecl>& ports, const std::string& name) {
  for (const auto& p : ports)
    if (p.name == name) return &p;
  return nullptr;
}

/// Why `text` is not a value of parameter `spec` ("" when it is, or when it is empty or a $reference).
QString check_number(const engine::ParamSpec& spec, const QString& field, const std::string& text) {
  if (text.empty()) return spec.required ? QObject::tr("%1: required parameter").arg(field) : QString();
  if (text[0] == '$') return {};
  double v = 0;
  if (!engine::parse_number(text, v)) return QObject::tr("%1: malformed number '%2'").arg(field, q(text));
  if (v < spec.lower || v > spec.upper)
    return QObject::tr("%1: value %2 outside [%3, %4] %5")
        .arg(field, q(text)).arg(spec.lower).arg(spec.upper).arg(q(spec.unit)).trimmed();
  return {};
}

}  // namespace

SceneController::SceneController(QObject* parent) : QObject(parent) { new_scene(); }

void SceneController::new_scene() {
  SceneDocument doc;
  doc.scene = "untitled";
  doc.time = {{"start", "0.0"}, {"stop", "10.0"}, {"output_step", "0.01"}};
  doc.solver = {{"method", "bdf"}, {"rtol", "1.0e-6"}, {"atol", "1.0e-8"}};
  undo_.clear();
  path_.clear();
  replace(doc);
  emit file_changed();
}

void SceneController::open(const QString& path) {
  SceneDocument doc = read_scene_file(s(path));
  lay_out_scene(doc, LayoutScope::unplaced_blocks);
  for (DocSubsystem& def : doc.subsystems) lay_out_definition(doc, def, LayoutScope::unplaced_blocks);
  undo_.clear();
  path_ = path;
  replace(doc);
  emit file_changed();
}

void SceneController::save(const QString& path) {
  write_scene_file(doc_, s(path));
  path_ = path;
  undo_.setClean();
  emit file_changed();
}

void SceneController::replace(const SceneDocument& doc) {
  doc_ = doc;
  emit document_changed();
}

void SceneController::commit(const QString& label, SceneDocument after) {
  if (after == doc_) return;
  undo_.push(new DocumentEdit(this, label, doc_, std::move(after)));
}

const engine::BlockType* SceneController::type_of(const std::string& block) const {
  const DocBlock* b = doc_.find_block(block);
  return b ? engine::Registry::global().find(b->type) : nullptr;
}

BlockPorts SceneController::ports(const std::string& block) const {
  const DocBlock* b = doc_.find_block(block);
  if (b && doc_.subsystem_of(*b)) return instance_ports(doc_, *b);
  const engine::BlockType* type = b ? engine::Registry::global().find(b->type) : nullptr;
  if (!type) {
    BlockPorts none;
    none.error = b ? "unknown block type '" + b->type + "'" : "no block '" + block + "'";
    return none;
  }
  std::string key = b->type;
  for (const auto& spec : type->settings)
    if (const SceneValue* v = b->find(spec.name)) key += "\n" + spec.name + "=" + v->text();
  auto it = ports_cache_.find(key);
  if (it == ports_cache_.end()) it = ports_cache_.emplace(key, ports_of(*type, *b)).first;
  return it->second;
}

void SceneController::lay_out() {
  SceneDocument after = doc_;
  lay_out_scene(after, LayoutScope::all_blocks);
  commit(tr("Lay out diagram"), std::move(after));
}

QString SceneController::group_into_subsystem(const QStringList& blocks, QString* instance) {
  std::vector<std::string> names;
  for (const QString& b : blocks) names.push_back(s(b));
  Grouping g = dydp::gui::group_into_subsystem(doc_, names);
  if (!g.error.empty()) return q(g.error);
  if (instance) *instance = q(g.instance);
  commit(tr("Group %1 blocks into subsystem %2").arg(blocks.size()).arg(q(g.instance)), std::move(g.after));
  return {};
}

namespace {

DocSubsystem* editable(SceneDocument& doc, const std::string& name) {
  for (DocSubsystem& d : doc.subsystems)
    if (d.name == name) return d.file.empty() && d.error.empty() ? &d : nullptr;
  return nullptr;
}

}  // namespace

bool SceneController::definition_editable(const QString& subsystem) const {
  const DocSubsystem* d = doc_.find_subsystem(s(subsystem));
  return d && d->file.empty() && d->error.empty();
}

void SceneController::move_block_in(const QString& subsystem, const QString& block, QPointF pos) {
  SceneDocument after = doc_;
  DocSubsystem* def = editable(after, s(subsystem));
  DocBlock* b = def ? def->find_block(s(block)) : nullptr;
  if (!b) return;
  b->x = std::round(pos.x());
  b->y = std::round(pos.y());
  store_inside(*def);
  commit(tr("Move %1.%2").arg(subsystem, block), std::move(after));
}

QString SceneController::set_block_value_in(const QString& subsystem, const QString& block_name,
                                            const QString& key_q, const QString& text_q) {
  const std::string key = s(key_q), text = s(text_q).empty() ? "" : SceneValue::parse(s(text_q)).text();
  SceneDocument after = doc_;
  DocSubsystem* def = editable(after, s(subsystem));
  if (!def) return tr("subsystem %1 is defined in a file of its own: edit it there").arg(subsystem);
  DocBlock* b = def->find_block(s(block_name));
  const QString field = subsystem + "." + block_name + "." + key_q;
  if (!b) return tr("no block '%1' in subsystem %2").arg(block_name, subsystem);
  const engine::BlockType* type = engine::Registry::global().find(b->type);
  if (!type) return tr("%1: only blocks of the library are edited inside a subsystem").arg(field);
  const bool own_parameter = !text.empty() && text[0] == '$' &&
                             std::any_of(def->parameters.begin(), def->parameters.end(),
                                         [&](const auto& p) { return "$" + p.first == text; });
  if (!text.empty() && text[0] == '$' && !own_parameter)
    return tr("%1: '%2' is not a parameter of subsystem %3 (inside, $name names the subsystem's own)")
        .arg(field, q(text), subsystem);
  if (const int j = parameter_index(*type, key); j >= 0) {
    if (const QString why = check_number(type->parameters[j], field, text); !why.isEmpty()) return why;
    b->set(key, SceneValue::scalar(text));
  } else if (setting_index(*type, key) >= 0) {
    b->set(key, text.empty() ? SceneValue::scalar("") : SceneValue::parse(text));
    if (!own_parameter)
      if (const BlockPorts p = ports_of(*type, *b); !p.error.empty()) return q(p.error);
  } else {
    return tr("%1: unknown parameter of %2").arg(field, q(type->name));
  }
  store_inside(*def);
  commit(tr("Set %1").arg(field), std::move(after));
  return {};
}

QString SceneController::add_block(const QString& type_name, QPointF pos) {
  const engine::BlockType* type = engine::Registry::global().find(s(type_name));
  if (!type) return {};
  SceneDocument after = doc_;
  DocBlock b;
  b.type = type->name;
  b.name = doc_.unique_block_name(name_stem(type->name));
  b.x = std::round(pos.x());
  b.y = std::round(pos.y());
  b.placed = true;
  // Required parameters start at their default so the scene stays loadable.
  for (const auto& p : type->parameters)
    if (p.required) b.set(p.name, SceneValue::scalar(number_text(p.default_value)));
  after.blocks.push_back(b);
  // A new objective is computed by default: that is what it was dropped for.
  if (ports_of(*type, b).is_objective) after.outputs.push_back(b.name);
  commit(tr("Add %1").arg(q(b.name)), std::move(after));
  return q(b.name);
}

void SceneController::remove_blocks(const QStringList& names) {
  SceneDocument after = doc_;
  for (const QString& qn : names) {
    const std::string name = s(qn);
    std::erase_if(after.blocks, [&](const DocBlock& b) { return b.name == name; });
    std::erase_if(after.connections,
                  [&](const DocConnection& c) { return c.from.block == name || c.to.block == name; });
    std::erase_if(after.outputs, [&](const std::string& o) {
      PortRef r;
      return o == name || (PortRef::parse(o, r) && r.block == name);
    });
  }
  commit(names.size() == 1 ? tr("Delete %1").arg(names.front()) : tr("Delete %1 blocks").arg(names.size()),
         std::move(after));
}

void SceneController::move_block(const QString& name, QPointF pos) {
  SceneDocument after = doc_;
  DocBlock* b = after.find_block(s(name));
  if (!b) return;
  b->x = std::round(pos.x());
  b->y = std::round(pos.y());
  b->placed = true;
  commit(tr("Move %1").arg(name), std::move(after));
}

QString SceneController::check_connection(const QString& from_text, const QString& to_text) const {
  PortRef from, to;
  if (!PortRef::parse(s(from_text), from) || !PortRef::parse(s(to_text), to))
    return tr("both ends need block.port");
  if (!doc_.find_block(from.block)) return tr("no block '%1'").arg(q(from.block));
  if (!doc_.find_block(to.block)) return tr("no block '%1'").arg(q(to.block));
  const BlockPorts pf = ports(from.block), pt = ports(to.block);
  if (!pf.error.empty()) return q(from.block + ": " + pf.error);
  if (!pt.error.empty()) return q(to.block + ": " + pt.error);
  const engine::PortDecl* out = find_port(pf.outputs, from.port);
  const engine::PortDecl* in = find_port(pt.inputs, to.port);
  if (!out)
    return find_port(pf.inputs, from.port)
               ? tr("%1 is an input: a wire runs from an output to an input").arg(from_text)
               : tr("block '%1' has no output '%2'").arg(q(from.block), q(from.port));
  if (!in)
    return find_port(pt.outputs, to.port)
               ? tr("%1 is an output: a wire runs from an output to an input").arg(to_text)
               : tr("block '%1' has no input '%2'").arg(q(to.block), q(to.port));
  if (out->width != in->width)
    return tr("width mismatch: %1 has width %2, %3 expects %4")
        .arg(from_text).arg(out->width).arg(to_text).arg(in->width);
  if (const DocConnection* c = doc_.driver_of(to))
    return tr("%1 is already driven by %2").arg(to_text, q(c->from.text()));
  return {};
}

QString SceneController::connect_ports(const QString& from, const QString& to) {
  const QString why = check_connection(from, to);
  if (!why.isEmpty()) return why;
  SceneDocument after = doc_;
  DocConnection c;
  PortRef::parse(s(from), c.from);
  PortRef::parse(s(to), c.to);
  after.connections.push_back(c);
  commit(tr("Connect %1 -> %2").arg(from, to), std::move(after));
  return {};
}

void SceneController::remove_connections(const std::vector<DocConnection>& connections) {
  SceneDocument after = doc_;
  std::erase_if(after.connections, [&](const DocConnection& c) {
    return std::find(connections.begin(), connections.end(), c) != connections.end();
  });
  commit(tr("Delete wire"), std::move(after));
}

void SceneController::drop_dangling(SceneDocument& doc, const std::string& block) const {
  // ports() reads doc_, so ask with a controller-independent lookup of the edited block.
  const DocBlock* b = doc.find_block(block);
  const engine::BlockType* type = b ? engine::Registry::global().find(b->type) : nullptr;
  if (!type) return;
  const BlockPorts p = ports_of(*type, *b);
  auto width_of = [&](const std::string& other, const std::string& port, bool input) -> int {
    if (other == block) {
      const engine::PortDecl* d = find_port(input ? p.inputs : p.outputs, port);
      return d ? d->width : -1;
    }
    const BlockPorts op = ports(other);
    const engine::PortDecl* d = find_port(input ? op.inputs : op.outputs, port);
    return d ? d->width : -1;
  };
  std::erase_if(doc.connections, [&](const DocConnection& c) {
    if (c.from.block != block && c.to.block != block) return false;
    const int wf = width_of(c.from.block, c.from.port, false), wt = width_of(c.to.block, c.to.port, true);
    return wf < 0 || wt < 0 || wf != wt;
  });
  std::erase_if(doc.outputs, [&](const std::string& o) {
    PortRef r;
    return PortRef::parse(o, r) && r.block == block && !find_port(p.outputs, r.port);
  });
}

QString SceneController::set_block_value(const QString& block_name, const QString& key_q,
                                         const QString& text_q) {
  const std::string key = s(key_q), text = s(text_q).empty() ? "" : SceneValue::parse(s(text_q)).text();
  SceneDocument after = doc_;
  DocBlock* b = after.find_block(s(block_name));
  if (!b) return tr("no block '%1'").arg(block_name);
  const QString field = block_name + "." + key_q;
  if (const DocSubsystem* def = doc_.subsystem_of(*b)) {
    // An instance's parameter: a value for the subsystem (checked by the engine where it is used).
    const bool known = std::any_of(def->parameters.begin(), def->parameters.end(),
                                   [&](const auto& p) { return p.first == key; });
    if (!known) return tr("%1: unknown parameter of subsystem %2").arg(field, q(def->name));
    if (!text.empty() && text[0] == '$' && !doc_.find_parameter(text.substr(1)))
      return tr("%1: unknown scene parameter '%2'").arg(field, q(text));
    b->set(key, text.empty() ? SceneValue::scalar("") : SceneValue::parse(text));
    commit(tr("Set %1").arg(field), std::move(after));
    return {};
  }
  const engine::BlockType* type = engine::Registry::global().find(b->type);
  if (!type) return tr("unknown block type '%1'").arg(q(b->type));

  if (const int j = parameter_index(*type, key); j >= 0) {
    const engine::ParamSpec& spec = type->parameters[j];
    if (text.empty() && spec.required) return tr("%1: required parameter").arg(field);
    if (!text.empty() && text[0] == '$') {
      const DocParameter* sp = doc_.find_parameter(text.substr(1));
      if (!sp) return tr("%1: unknown scene parameter '%2'").arg(field, q(text));
      const bool direction = std::find(doc_.sensitivities.begin(), doc_.sensitivities.end(), sp->name) !=
                             doc_.sensitivities.end();
      if (!spec.differentiable && direction)
        return tr("%1: not differentiable, cannot be driven by sensitivity parameter '%2'")
            .arg(field, q(sp->name));
    } else if (const QString why = check_number(spec, field, text); !why.isEmpty()) {
      return why;
    }
    b->set(key, SceneValue::scalar(text));
  } else if (setting_index(*type, key) >= 0) {
    b->set(key, text.empty() ? SceneValue::scalar("") : SceneValue::parse(text));
    const BlockPorts p = ports_of(*type, *b);
    if (!p.error.empty()) return q(p.error);
    drop_dangling(after, b->name);
  } else {
    std::string known;
    for (const auto& p : type->parameters) known += " " + p.name;
    for (const auto& p : type->settings) known += " " + p.name;
    return tr("%1: unknown parameter of %2 (known:%3)").arg(field, q(type->name), q(known));
  }
  commit(tr("Set %1").arg(field), std::move(after));
  return {};
}

QString SceneController::rename_block(const QString& from_q, const QString& to_q) {
  const std::string from = s(from_q), to = s(to_q);
  if (from == to) return {};
  if (!valid_name(to)) return tr("block name '%1' must be non-empty, without '.', spaces or YAML marks").arg(to_q);
  if (doc_.find_block(to)) return tr("a block named '%1' exists").arg(to_q);
  SceneDocument after = doc_;
  DocBlock* b = after.find_block(from);
  if (!b) return tr("no block '%1'").arg(from_q);
  b->name = to;
  for (auto& c : after.connections) {
    if (c.from.block == from) c.from.block = to;
    if (c.to.block == from) c.to.block = to;
  }
  for (auto& o : after.outputs) {
    PortRef r;
    if (o == from) o = to;
    else if (PortRef::parse(o, r) && r.block == from) o = to + "." + r.port;
  }
  commit(tr("Rename %1 to %2").arg(from_q, to_q), std::move(after));
  return {};
}

void SceneController::set_output(const QString& ref_q, bool logged) {
  const std::string ref = s(ref_q);
  SceneDocument after = doc_;
  const auto it = std::find(after.outputs.begin(), after.outputs.end(), ref);
  if (logged && it == after.outputs.end()) after.outputs.push_back(ref);
  if (!logged && it != after.outputs.end()) after.outputs.erase(it);
  commit(logged ? tr("Log %1").arg(ref_q) : tr("Stop logging %1").arg(ref_q), std::move(after));
}

QString SceneController::set_time(const QString& key, const QString& text) {
  double v = 0;
  if (!text.isEmpty() && !engine::parse_number(s(text), v))
    return tr("time.%1: malformed number '%2'").arg(key, text);
  SceneDocument after = doc_;
  set_field(after.time, s(key), s(text.trimmed()));
  commit(tr("Set time.%1").arg(key), std::move(after));
  return {};
}

QString SceneController::set_solver(const QString& key, const QString& text) {
  if (key == "method") {
    static const QStringList methods = {"bdf", "adams", "rk4", "sdirk2", "rosw"};
    if (!text.isEmpty() && !methods.contains(text))
      return tr("solver.method: unknown method '%1' (%2)").arg(text, methods.join(", "));
  } else if (std::find(engine::kSolverSwitches.begin(), engine::kSolverSwitches.end(), s(key)) !=
             engine::kSolverSwitches.end()) {
    if (!text.isEmpty() && text != "true" && text != "false")
      return tr("solver.%1: expected true or false").arg(key);
  } else {
    double v = 0;
    if (!text.isEmpty() && !engine::parse_number(s(text), v))
      return tr("solver.%1: malformed number '%2'").arg(key, text);
  }
  SceneDocument after = doc_;
  set_field(after.solver, s(key), s(text.trimmed()));
  commit(tr("Set solver.%1").arg(key), std::move(after));
  return {};
}

QString SceneController::set_initial(const QString& text) {
  const std::string t = s(text.trimmed());
  if (!t.empty()) {
    try {
      YAML::Load(t);
    } catch (const YAML::Exception& e) {
      return tr("initial: not YAML: %1").arg(QString::fromStdString(e.msg));
    }
  }
  SceneDocument after = doc_;
  after.initial = t;
  commit(tr("Set initial"), std::move(after));
  return {};
}

void SceneController::set_scene_info(const QString& name, const QString& description) {
  SceneDocument after = doc_;
  after.scene = s(name);
  after.description = s(description);
  commit(tr("Edit scene name"), std::move(after));
}

QString SceneController::add_scene_parameter(const QString& name, const QString& value) {
  DocParameter p;
  p.name = s(name);
  p.value = s(value);
  if (!valid_name(p.name)) return tr("parameter name '%1' must be non-empty, without '.' or spaces").arg(name);
  if (doc_.find_parameter(p.name)) return tr("parameters.%1: defined twice").arg(name);
  double v = 0;
  if (!engine::parse_number(p.value, v)) return tr("parameters.%1: malformed number '%2'").arg(name, value);
  SceneDocument after = doc_;
  after.parameters.push_back(p);
  commit(tr("Add parameter %1").arg(name), std::move(after));
  return {};
}

QString SceneController::update_scene_parameter(const QString& name_q, const DocParameter& p) {
  const std::string name = s(name_q);
  const QString field = "parameters." + q(p.name);
  if (!doc_.find_parameter(name)) return tr("no scene parameter '%1'").arg(name_q);
  if (!valid_name(p.name)) return tr("parameter name '%1' must be non-empty, without '.' or spaces").arg(q(p.name));
  if (p.name != name && doc_.find_parameter(p.name)) return tr("%1: defined twice").arg(field);
  double v = 0, lo = -INFINITY, hi = INFINITY;
  if (!engine::parse_number(p.value, v)) return tr("%1: malformed number '%2'").arg(field, q(p.value));
  if (p.low.empty() != p.high.empty()) return tr("%1.range: give both ends or neither").arg(field);
  if (!p.low.empty()) {
    if (!engine::parse_number(p.low, lo) || !engine::parse_number(p.high, hi))
      return tr("%1.range: malformed number").arg(field);
    if (!(lo <= hi)) return tr("%1.range: low is above high").arg(field);
    if (v < lo || v > hi) return tr("%1: value %2 outside its range").arg(field, q(p.value));
  }
  SceneDocument after = doc_;
  *after.find_parameter(name) = p;
  if (p.name != name) {
    for (auto& b : after.blocks)
      for (auto& [k, val] : b.values)
        if (!val.is_list && val.text() == "$" + name) val = SceneValue::scalar("$" + p.name);
    for (auto& sname : after.sensitivities)
      if (sname == name) sname = p.name;
  }
  commit(tr("Edit parameter %1").arg(name_q), std::move(after));
  return {};
}

QString SceneController::remove_scene_parameter(const QString& name_q) {
  const std::string ref = "$" + s(name_q);
  for (const auto& b : doc_.blocks)
    for (const auto& [k, v] : b.values)
      if (!v.is_list && v.text() == ref)
        return tr("%1 drives %2.%3: change that first").arg(q(ref), q(b.name), q(k));
  SceneDocument after = doc_;
  std::erase_if(after.parameters, [&](const DocParameter& p) { return p.name == s(name_q); });
  std::erase(after.sensitivities, s(name_q));
  commit(tr("Delete parameter %1").arg(name_q), std::move(after));
  return {};
}

QString SceneController::make_direction(const QString& block_q, const QString& key_q, QString* parameter) {
  const std::string block = s(block_q), key = s(key_q);
  const DocBlock* b = doc_.find_block(block);
  if (!b) return tr("no block '%1'").arg(block_q);
  const engine::BlockType* type = engine::Registry::global().find(b->type);
  const int j = type ? parameter_index(*type, key) : -1;
  if (j < 0) return tr("%1.%2: not a numeric parameter of %3").arg(block_q, key_q, q(b->type));
  const engine::ParamSpec& spec = type->parameters[j];
  if (!spec.differentiable)
    return tr("%1.%2: not differentiable, cannot be a sensitivity direction").arg(block_q, key_q);
  SceneDocument after = doc_;
  DocBlock* target = after.find_block(block);
  const SceneValue* v = target->find(key);
  std::string name;
  if (v && !v->is_list && !v->is_map && !v->items.empty() && v->items.front().size() > 1 && v->items.front()[0] == '$') {
    // Already driven by a scene parameter: that one becomes the direction.
    name = v->items.front().substr(1);
    if (!after.find_parameter(name)) return tr("%1.%2: unknown scene parameter '$%3'").arg(block_q, key_q, q(name));
  } else {
    // A new scene parameter named after the block and parameter, starting at the value in use.
    name = after.unique_parameter_name(block + "_" + key);
    DocParameter p;
    p.name = name;
    p.value = v && !v->items.empty() && !v->items.front().empty() ? v->items.front() : number_text(spec.default_value);
    p.unit = spec.unit;
    double value = 0;
    if (!engine::parse_number(p.value, value)) return tr("%1.%2: malformed number '%3'").arg(block_q, key_q, q(p.value));
    after.parameters.push_back(p);
    target->set(key, SceneValue::scalar("$" + name));
  }
  if (std::find(after.sensitivities.begin(), after.sensitivities.end(), name) == after.sensitivities.end())
    after.sensitivities.push_back(name);
  if (parameter) *parameter = q(name);
  commit(tr("Make %1.%2 a direction").arg(block_q, key_q), std::move(after));
  return {};
}

void SceneController::set_sensitivity(const QString& name_q, bool on) {
  const std::string name = s(name_q);
  SceneDocument after = doc_;
  const auto it = std::find(after.sensitivities.begin(), after.sensitivities.end(), name);
  if (on && it == after.sensitivities.end()) after.sensitivities.push_back(name);
  if (!on && it != after.sensitivities.end()) after.sensitivities.erase(it);
  commit(on ? tr("Add direction d/d%1").arg(name_q) : tr("Remove direction d/d%1").arg(name_q),
         std::move(after));
}

engine::Diagram SceneController::load_for_run() const {
  if (!path_.isEmpty() && !modified() && QFileInfo::exists(path_)) return engine::load_scene(s(path_));
  // Relative file settings (source.table) resolve against the scene's folder: write beside it.
  const QString folder = path_.isEmpty() ? QDir::tempPath() : QFileInfo(path_).absolutePath();
  QTemporaryFile file(folder + "/.dydp-gui-run-XXXXXX.yaml");
  if (!file.open()) {
    file.setFileTemplate(QDir::tempPath() + "/dydp-gui-run-XXXXXX.yaml");
    if (!file.open()) throw engine::InputError("", 0, "", "cannot write a temporary scene file");
  }
  const std::string text = write_scene(doc_);
  file.write(text.data(), static_cast<qint64>(text.size()));
  file.close();
  try {
    return engine::load_scene(s(file.fileName()));
  } catch (const engine::InputError& e) {
    // Report against the document, not the temporary file; its lines are not the user's.
    const std::string what = e.what();
    const std::string prefix = e.field().empty() ? "" : e.field() + ": ";
    const auto at = prefix.empty() ? what.find(": ") : what.find(prefix);
    const std::string message =
        at == std::string::npos ? what : what.substr(at + (prefix.empty() ? 2 : prefix.size()));
    throw engine::InputError(path_.isEmpty() ? "unsaved scene" : s(path_), 0, e.field(), message);
  }
}

QStringList SceneController::blocks_of_error(const engine::InputError& e) const {
  QStringList out;
  const std::string prefix = e.field().substr(0, e.field().find('.'));
  if (doc_.find_block(prefix)) return {q(prefix)};
  // An algebraic loop names its blocks in the message.
  const QString what = QString::fromUtf8(e.what());
  for (const auto& b : doc_.blocks) {
    const QRegularExpression word("(^|[^\\w.])" + QRegularExpression::escape(q(b.name)) + "($|[^\\w])");
    if (e.field() == "connections" && what.contains(word)) out << q(b.name);
  }
  return out;
}

}  // namespace dydp::gui
