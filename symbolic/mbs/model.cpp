// Loader of `*.mbs.yaml` model descriptions. Every error names the file, the line and the field.
#include "symbolic/mbs/model.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "symbolic/eqs_reader.hpp"  // ParseError

namespace dydp::mbs {
namespace {

using symbolic::ParseError;

// The two unit normals of a hinge's axis a (Cut::normals_a): n1 = the frame axis e with the
// smallest |a . e|, minus its component along a, normalised; n2 = a x n1. For a = z: x and y.
std::array<std::array<double, 3>, 2> hinge_normals(const std::array<double, 3>& a) {
  int least = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(a[i]) < std::abs(a[least])) least = i;
  std::array<double, 3> n1{0.0, 0.0, 0.0};
  n1[least] = 1.0;
  for (int i = 0; i < 3; ++i) n1[i] -= a[least] * a[i];
  const double norm = std::sqrt(n1[0] * n1[0] + n1[1] * n1[1] + n1[2] * n1[2]);
  for (double& c : n1) c /= norm;
  const std::array<double, 3> n2{a[1] * n1[2] - a[2] * n1[1], a[2] * n1[0] - a[0] * n1[2], a[0] * n1[1] - a[1] * n1[0]};
  return {n1, n2};
}

class Loader {
 public:
  Loader(Model& model, std::string file) : m_(model), file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field, const std::string& message) const {
    const int line = node.IsDefined() ? node.Mark().line + 1 : 0;
    throw ParseError(file_, line, field + ": " + message);
  }

  double number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a number");
    try {
      std::size_t used = 0;
      const std::string s = node.Scalar();
      const double v = std::stod(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
      return v;
    } catch (const std::exception&) {
      fail(node, field, "expected a number, got '" + node.Scalar() + "'");
    }
  }

  bool boolean(const YAML::Node& node, const std::string& field) const {
    bool v = false;
    if (!node.IsScalar()) fail(node, field, "expected true or false");
    if (!YAML::convert<bool>::decode(node, v)) fail(node, field, "expected true or false, got '" + node.Scalar() + "'");
    return v;
  }

  std::string text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a name");
    return node.Scalar();
  }

  // A number or `$parameter`.
  Value value(const YAML::Node& node, const std::string& field) const {
    const std::string s = node.IsScalar() ? node.Scalar() : std::string();
    const bool negated = s.size() > 1 && s[0] == '-' && s[1] == '$';
    if (!s.empty() && (s[0] == '$' || negated)) {
      const std::string name = s.substr(negated ? 2 : 1);
      for (std::size_t i = 0; i < m_.parameters.size(); ++i)
        if (m_.parameters[i].name == name)
          return Value{(negated ? -1.0 : 1.0) * m_.parameters[i].value, static_cast<int>(i), negated ? -1.0 : 1.0};
      fail(node, field, "unknown parameter '" + name + "'");
    }
    return Value{number(node, field), -1};
  }

  Vec3Value vec3(const YAML::Node& node, const std::string& field) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, field, "expected a list of three values");
    return {value(node[0], field), value(node[1], field), value(node[2], field)};
  }

  Value optional_value(const YAML::Node& parent, const char* key, const std::string& field, double fallback) const {
    const YAML::Node n = parent[key];
    return n ? value(n, field + "." + key) : Value{fallback, -1};
  }

  void check_keys(const YAML::Node& node, const std::string& field, std::initializer_list<const char*> keys) const {
    if (!node.IsMap()) fail(node, field, "expected a mapping");
    for (const auto& kv : node) {
      const std::string k = kv.first.Scalar();
      bool known = false;
      for (const char* allowed : keys) known = known || k == allowed;
      if (!known) fail(kv.first, field + "." + k, "unknown key");
    }
  }

  int body_index(const YAML::Node& node, const std::string& name, const std::string& field) const {
    for (std::size_t i = 0; i < m_.bodies.size(); ++i)
      if (m_.bodies[i].name == name) return static_cast<int>(i);
    fail(node, field, "unknown body '" + name + "'");
  }

  // `body.anchor`
  PointRef point(const YAML::Node& node, const std::string& field) const {
    const std::string s = text(node, field);
    const auto dot = s.find('.');
    if (dot == std::string::npos) fail(node, field, "expected BODY.ANCHOR, got '" + s + "'");
    PointRef p;
    p.body = body_index(node, s.substr(0, dot), field);
    const std::string anchor = s.substr(dot + 1);
    const auto& anchors = m_.bodies[p.body].anchors;
    for (std::size_t i = 0; i < anchors.size(); ++i)
      if (anchors[i].name == anchor) { p.anchor = static_cast<int>(i); return p; }
    fail(node, field, "body '" + m_.bodies[p.body].name + "' has no anchor '" + anchor + "'");
  }

  // A non-empty list of distinct names out of `names`, as indices.
  std::vector<int> components(const YAML::Node& node, const std::string& field,
                              const std::vector<std::string>& names) const {
    std::string allowed;
    for (const auto& n : names) allowed += (allowed.empty() ? "" : ", ") + n;
    if (!node.IsSequence() || node.size() == 0) fail(node, field, "expected a non-empty list of " + allowed);
    std::vector<int> picked;
    for (std::size_t k = 0; k < node.size(); ++k) {
      const std::string s = text(node[k], field);
      int found = -1;
      for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == s) found = static_cast<int>(i);
      if (found < 0) fail(node[k], field, "expected one of " + allowed + ", got '" + s + "'");
      for (int p : picked)
        if (p == found) fail(node[k], field, "'" + s + "' is listed twice");
      picked.push_back(found);
    }
    return picked;
  }

  // A hinge axis: x, y or z of the body's frame, or [x, y, z] in it (normalised).
  std::array<double, 3> hinge_axis(const YAML::Node& node, const std::string& field) const {
    std::array<double, 3> axis{0.0, 0.0, 0.0};
    if (node.IsScalar()) {
      const std::string s = node.Scalar();
      if (s != "x" && s != "y" && s != "z") fail(node, field, "expected x, y, z or [x, y, z], got '" + s + "'");
      axis[s[0] - 'x'] = 1.0;
      return axis;
    }
    if (!node.IsSequence() || node.size() != 3) fail(node, field, "expected x, y, z or [x, y, z]");
    double norm = 0.0;
    for (int i = 0; i < 3; ++i) {
      axis[i] = number(node[i], field);
      norm += axis[i] * axis[i];
    }
    if (norm < 1e-24) fail(node, field, "the axis is zero");
    for (double& c : axis) c /= std::sqrt(norm);
    return axis;
  }

  int joint_index(const YAML::Node& node, const std::string& field) const {
    const std::string s = text(node, field);
    for (std::size_t i = 0; i < m_.joints.size(); ++i)
      if (m_.joints[i].name == s) return static_cast<int>(i);
    fail(node, field, "unknown joint '" + s + "'");
  }

  int frame(const YAML::Node& parent, const std::string& field) const {
    const YAML::Node n = parent["frame"];
    if (!n) return 0;
    return body_index(n, text(n, field + ".frame"), field + ".frame");
  }

  void anchors(const YAML::Node& node, Body& body, const std::string& field) {
    if (!node) return;
    if (!node.IsMap()) fail(node, field, "expected a mapping NAME: [x, y, z]");
    for (const auto& kv : node) {
      const std::string name = kv.first.Scalar();
      for (const Anchor& a : body.anchors)
        if (a.name == name) fail(kv.first, field + "." + name, "duplicate anchor");
      body.anchors.push_back({name, vec3(kv.second, field + "." + name)});
    }
  }

  void load(const YAML::Node& root) {
    read_tree(root);
    if (const YAML::Node cs = root["cuts"]) read_cuts(cs);
    if (const YAML::Node fs = root["forces"]) read_forces(fs);
    if (const YAML::Node ls = root["loads"]) read_loads(ls);
    if (const YAML::Node ss = root["sensors"]) read_sensors(ss);
    if (const YAML::Node js = root["jacobians"]) read_jacobians(js);
    if (const YAML::Node ind = root["independent"]) read_independent(ind);
  }

  // The model's name, gravity, parameters, ground and bodies with their joints, the joints in
  // parent-first order.
  void read_tree(const YAML::Node& root) {
    check_keys(root, "model", {"model", "description", "gravity", "parameters", "ground", "bodies", "cuts",
                               "forces", "loads", "sensors", "jacobians", "independent"});
    if (root["model"]) m_.name = text(root["model"], "model");
    if (const YAML::Node g = root["gravity"]) {
      if (!g.IsSequence() || g.size() != 3) fail(g, "gravity", "expected [gx, gy, gz]");
      for (int i = 0; i < 3; ++i) m_.gravity[i] = number(g[i], "gravity");
    }
    if (const YAML::Node ps = root["parameters"]) read_parameters(ps);
    Body ground;
    ground.name = "ground";
    if (const YAML::Node g = root["ground"]) {
      check_keys(g, "ground", {"anchors"});
      anchors(g["anchors"], ground, "ground.anchors");
    }
    m_.bodies.push_back(ground);

    const YAML::Node bodies = root["bodies"];
    std::vector<PendingParent> parents;
    if (!bodies || !bodies.IsSequence() || bodies.size() == 0) fail(root, "bodies", "expected a non-empty list");
    for (std::size_t bi = 0; bi < bodies.size(); ++bi) read_body(bodies[bi], bi, parents);

    for (const auto& [first_joint, node, field] : parents)
      m_.joints[first_joint].parent = m_.bodies[body_index(node, text(node, field), field)].frame;
    order_joints(bodies);
  }

  // The `parameters:` mapping, NAME: value or NAME: {value, fold, unit}.
  void read_parameters(const YAML::Node& ps) {
    if (!ps.IsMap()) fail(ps, "parameters", "expected a mapping NAME: value");
    for (const auto& kv : ps) {
      Parameter p;
      p.name = kv.first.Scalar();
      const std::string field = "parameters." + p.name;
      if (kv.second.IsMap()) {
        check_keys(kv.second, field, {"value", "fold", "unit"});
        if (!kv.second["value"]) fail(kv.second, field, "missing value");
        p.value = number(kv.second["value"], field + ".value");
        if (kv.second["fold"]) p.symbolic = !boolean(kv.second["fold"], field + ".fold");
        if (kv.second["unit"]) p.unit = text(kv.second["unit"], field + ".unit");
      } else {
        p.value = number(kv.second, field);
      }
      m_.parameters.push_back(p);
    }
  }

  // A body's `parent:`, resolved once every body is known.
  struct PendingParent {
    int first_joint;
    YAML::Node node;
    std::string field;
  };

  // Body bi of `bodies:` with its joints (appended to m_.joints), its parent left in `parents`.
  void read_body(const YAML::Node& b, std::size_t bi, std::vector<PendingParent>& parents) {
    std::string field = "bodies[" + std::to_string(bi) + "]";
    check_keys(b, field, {"name", "parent", "offset", "joints", "mass", "com", "inertia", "anchors"});
    Body body;
    if (!b["name"]) fail(b, field, "missing name");
    body.name = text(b["name"], field + ".name");
    field = "bodies." + body.name;
    for (const Body& other : m_.bodies)
      if (other.name == body.name) fail(b["name"], field, "duplicate body name");
    // parents may be declared later: resolved once every body is known
    if (b["parent"]) parents.push_back({static_cast<int>(m_.joints.size()), b["parent"], field + ".parent"});
    Vec3Value offset{};
    if (b["offset"]) offset = vec3(b["offset"], field + ".offset");
    const YAML::Node js = b["joints"];
    if (!js || !js.IsSequence() || js.size() == 0) fail(b, field + ".joints", "expected a non-empty list of joints");
    int parent_joint = -1;
    for (std::size_t k = 0; k < js.size(); ++k) {
      const std::string jf = field + ".joints[" + std::to_string(k) + "]";
      Joint joint = read_joint(js[k], jf, body.name + "_" + std::to_string(k + 1));
      joint.parent = parent_joint;
      if (k == 0) joint.offset = offset;
      m_.joints.push_back(joint);
      parent_joint = static_cast<int>(m_.joints.size()) - 1;
    }
    body.frame = parent_joint;
    m_.joints[parent_joint].body = static_cast<int>(m_.bodies.size());
    if (!b["mass"]) fail(b, field + ".mass", "missing");
    body.mass = value(b["mass"], field + ".mass");
    if (b["com"]) body.com = vec3(b["com"], field + ".com");
    if (const YAML::Node in = b["inertia"]) {
      if (!in.IsSequence() || (in.size() != 3 && in.size() != 6))
        fail(in, field + ".inertia", "expected [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]");
      for (std::size_t i = 0; i < in.size(); ++i) body.inertia[i] = value(in[i], field + ".inertia");
    }
    anchors(b["anchors"], body, field + ".anchors");
    m_.bodies.push_back(body);
  }

  // A joint's name (`unnamed` when it has none), type, axis, driven and initial (jf: its field).
  Joint read_joint(const YAML::Node& j, const std::string& jf, const std::string& unnamed) const {
    check_keys(j, jf, {"name", "type", "axis", "driven", "initial"});
    Joint joint;
    joint.name = j["name"] ? text(j["name"], jf + ".name") : unnamed;
    for (const Joint& other : m_.joints)
      if (other.name == joint.name) fail(j, jf + ".name", "duplicate joint name '" + joint.name + "'");
    if (!j["type"]) fail(j, jf, "missing type (Rx Ry Rz Tx Ty Tz, or R T with an axis)");
    static const std::map<std::string, JointType> types{{"Rx", JointType::Rx}, {"Ry", JointType::Ry},
        {"Rz", JointType::Rz}, {"Tx", JointType::Tx}, {"Ty", JointType::Ty}, {"Tz", JointType::Tz},
        {"R", JointType::R}, {"T", JointType::T}};
    const auto t = types.find(text(j["type"], jf + ".type"));
    if (t == types.end()) fail(j["type"], jf + ".type", "expected one of Rx Ry Rz Tx Ty Tz R T");
    joint.type = t->second;
    if (axis_of(joint.type) >= 0) {
      if (j["axis"]) fail(j["axis"], jf + ".axis", "only joints of type R or T take an axis");
      joint.axis = {0.0, 0.0, 0.0};
      joint.axis[axis_of(joint.type)] = 1.0;
    } else {
      const YAML::Node a = j["axis"];
      if (!a) fail(j, jf + ".axis", "missing (a joint of type R or T needs an axis [x, y, z])");
      if (!a.IsSequence() || a.size() != 3) fail(a, jf + ".axis", "expected [x, y, z]");
      double norm = 0.0;
      for (int i = 0; i < 3; ++i) {
        joint.axis[i] = number(a[i], jf + ".axis");
        norm += joint.axis[i] * joint.axis[i];
      }
      if (norm < 1e-24) fail(a, jf + ".axis", "the axis is zero");
      for (double& c : joint.axis) c /= std::sqrt(norm);
    }
    if (j["driven"]) joint.driven = boolean(j["driven"], jf + ".driven");
    if (j["initial"]) joint.initial = number(j["initial"], jf + ".initial");
    return joint;
  }

  // m_.order from the joints' parents; a loop among them is an error at `bodies`.
  void order_joints(const YAML::Node& bodies) {
    // Joints in an order where parents come first (coordinates keep the declaration order).
    std::vector<int> state(m_.joints.size(), 0);  // 0 new, 1 visiting, 2 done
    std::function<void(int)> visit = [&](int j) {
      if (state[j] == 2) return;
      if (state[j] == 1) fail(bodies, "bodies", "the parents form a loop (close loops with cuts)");
      state[j] = 1;
      if (m_.joints[j].parent >= 0) visit(m_.joints[j].parent);
      state[j] = 2;
      m_.order.push_back(j);
    };
    for (std::size_t j = 0; j < m_.joints.size(); ++j) visit(static_cast<int>(j));
  }

  // The cuts that close the loops (ball, distance, hinge).
  void read_cuts(const YAML::Node& cs) {
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const YAML::Node c = cs[i];
      const Entry at =
          entry(c, "cuts", i, {"name", "type", "a", "b", "components", "length", "axis", "axis_a", "axis_b"}, "cut");
      const std::string& field = at.field;
      const std::string& type = at.type;
      Cut cut;
      cut.name = at.name;
      if (!c["a"] || !c["b"]) fail(c, field, "needs points a and b (BODY.ANCHOR)");
      cut.a = point(c["a"], field + ".a");
      cut.b = point(c["b"], field + ".b");
      if (type == "ball") {
        cut.type = Cut::Type::Ball;
        if (const YAML::Node comp = c["components"]) {
          for (std::size_t k = 0; k < comp.size(); ++k) {
            const std::string s = text(comp[k], field + ".components");
            if (s != "x" && s != "y" && s != "z") fail(comp[k], field + ".components", "expected x, y or z");
            cut.components.push_back(s[0] - 'x');
          }
        } else {
          cut.components = {0, 1, 2};
        }
      } else if (type == "distance") {
        cut.type = Cut::Type::Distance;
        if (!c["length"]) fail(c, field + ".length", "missing");
        cut.length = value(c["length"], field + ".length");
      } else if (type == "hinge") {
        cut.type = Cut::Type::Hinge;
        for (const char* key : {"components", "length"})
          if (c[key]) fail(c[key], field + "." + key, "not a key of a hinge");
        // `axis` for both bodies (frames parallel in the assembled position), or one each
        auto body_axis = [&](const std::string& key) {
          if (const YAML::Node own = c[key]) return hinge_axis(own, field + "." + key);
          if (const YAML::Node both = c["axis"]) return hinge_axis(both, field + ".axis");
          fail(c, field + "." + key, "missing (a hinge needs axis, or axis_a and axis_b: x, y, z or [x, y, z])");
        };
        cut.axis_a = body_axis("axis_a");
        cut.axis_b = body_axis("axis_b");
        cut.normals_a = hinge_normals(cut.axis_a);
      } else {
        fail(c["type"] ? c["type"] : c, field + ".type", "expected ball, distance or hinge");
      }
      if (cut.type != Cut::Type::Hinge)
        for (const char* key : {"axis", "axis_a", "axis_b"})
          if (c[key]) fail(c[key], field + "." + key, "only a hinge takes " + std::string(key));
      m_.cuts.push_back(cut);
    }
  }

  // The force elements (springs, joint forces).
  void read_forces(const YAML::Node& fs) {
    for (std::size_t i = 0; i < fs.size(); ++i) {
      const YAML::Node f = fs[i];
      const Entry at = entry(
          f, "forces", i, {"name", "type", "a", "b", "stiffness", "rest_length", "damping", "joint", "value"}, "force");
      const std::string& field = at.field;
      const std::string& type = at.type;
      ForceElement e;
      e.name = at.name;
      if (type == "spring") {
        e.type = ForceElement::Type::Spring;
        if (!f["a"] || !f["b"]) fail(f, field, "needs points a and b");
        e.a = point(f["a"], field + ".a");
        e.b = point(f["b"], field + ".b");
        e.stiffness = optional_value(f, "stiffness", field, 0.0);
        e.rest_length = optional_value(f, "rest_length", field, 0.0);
        e.damping = optional_value(f, "damping", field, 0.0);
      } else if (type == "joint_force") {
        e.type = ForceElement::Type::JointForce;
        if (!f["joint"] || !f["value"]) fail(f, field, "needs joint and value");
        e.joint = joint_index(f["joint"], field + ".joint");
        e.value = value(f["value"], field + ".value");
      } else {
        fail(f["type"] ? f["type"] : f, field + ".type", "expected spring or joint_force");
      }
      m_.forces.push_back(e);
    }
  }

  // The load ports (forces, torques, link forces).
  void read_loads(const YAML::Node& ls) {
    for (std::size_t i = 0; i < ls.size(); ++i) {
      const YAML::Node l = ls[i];
      const Entry at =
          entry(l, "loads", i, {"name", "type", "point", "body", "frame", "components", "a", "b", "sense", "reaction"});
      const std::string& field = at.field;
      const std::string& type = at.type;
      Load load;
      load.name = at.name;
      if (type == "force") {
        load.type = Load::Type::Force;
        if (!l["point"]) fail(l, field + ".point", "missing");
        load.point = point(l["point"], field + ".point");
      } else if (type == "torque") {
        load.type = Load::Type::Torque;
        if (!l["body"]) fail(l, field + ".body", "missing");
        load.point.body = body_index(l["body"], text(l["body"], field + ".body"), field + ".body");
        if (l["reaction"])
          load.reaction = body_index(l["reaction"], text(l["reaction"], field + ".reaction"), field + ".reaction");
      } else if (type == "link_force") {
        load.type = Load::Type::LinkForce;
        if (!l["a"] || !l["b"]) fail(l, field, "needs points a and b (BODY.ANCHOR)");
        load.point = point(l["a"], field + ".a");
        load.b = point(l["b"], field + ".b");
        const std::string sense = l["sense"] ? text(l["sense"], field + ".sense") : "tension";
        if (sense != "tension" && sense != "compression")
          fail(l["sense"], field + ".sense", "expected tension or compression");
        load.compression = sense == "compression";
        for (const char* key : {"frame", "components", "point", "body", "reaction"})
          if (l[key]) fail(l[key], field + "." + key, "not a key of a link force");
      } else {
        fail(l["type"] ? l["type"] : l, field + ".type", "expected force, torque or link_force");
      }
      if (load.type == Load::Type::Force && l["reaction"])
        fail(l["reaction"], field + ".reaction", "only a torque takes a reaction body");
      if (load.type != Load::Type::LinkForce) {
        for (const char* key : {"a", "b", "sense"})
          if (l[key]) fail(l[key], field + "." + key, "only a link force takes " + std::string(key));
        if (l["components"]) load.components = components(l["components"], field + ".components", {"x", "y", "z"});
      }
      load.frame = frame(l, field);
      m_.loads.push_back(load);
    }
  }

  // The sensors.
  void read_sensors(const YAML::Node& ss) {
    for (std::size_t i = 0; i < ss.size(); ++i) {
      const YAML::Node s = ss[i];
      const Entry at = entry(
          s, "sensors", i, {"name", "type", "point", "body", "a", "b", "frame", "joint", "components", "reference", "sense"});
      const std::string& field = at.field;
      const std::string& type = at.type;
      Sensor sensor;
      sensor.name = at.name;
      static const std::map<std::string, Sensor::Type> types{{"position", Sensor::Type::Position},
          {"velocity", Sensor::Type::Velocity}, {"acceleration", Sensor::Type::Acceleration},
          {"length", Sensor::Type::Length}, {"joint", Sensor::Type::Joint},
          {"angular_velocity", Sensor::Type::AngularVelocity}};
      const auto t = types.find(type);
      if (t == types.end()) fail(s["type"] ? s["type"] : s, field + ".type",
                                 "expected position, velocity, acceleration, angular_velocity, length or joint");
      sensor.type = t->second;
      if (sensor.type != Sensor::Type::Length)
        for (const char* key : {"reference", "sense"})
          if (s[key]) fail(s[key], field + "." + key, "only a length sensor takes " + std::string(key));
      if (sensor.type == Sensor::Type::Length) {
        if (!s["a"] || !s["b"]) fail(s, field, "needs points a and b");
        sensor.a = point(s["a"], field + ".a");
        sensor.b = point(s["b"], field + ".b");
        if (s["reference"]) sensor.reference = value(s["reference"], field + ".reference");
        const std::string sense = s["sense"] ? text(s["sense"], field + ".sense") : "extension";
        if (sense != "extension" && sense != "compression")
          fail(s["sense"], field + ".sense", "expected extension or compression");
        sensor.compression = sense == "compression";
      } else if (sensor.type == Sensor::Type::AngularVelocity) {
        if (!s["body"]) fail(s, field + ".body", "missing");
        sensor.a.body = body_index(s["body"], text(s["body"], field + ".body"), field + ".body");
        sensor.frame = frame(s, field);
      } else if (sensor.type == Sensor::Type::Joint) {
        if (!s["joint"]) fail(s, field + ".joint", "missing");
        sensor.joint = joint_index(s["joint"], field + ".joint");
      } else {
        if (!s["point"]) fail(s, field + ".point", "missing");
        sensor.a = point(s["point"], field + ".point");
        sensor.frame = frame(s, field);
      }
      std::vector<std::string> names{"x", "y", "z"};
      if (sensor.type == Sensor::Type::Length) names = {"length", "rate"};
      if (sensor.type == Sensor::Type::Joint) names = {"q", "qd", "qdd"};
      if (s["components"]) {
        sensor.components = components(s["components"], field + ".components", names);
      } else {
        for (int c = 0; c < sensor.full_width(); ++c) sensor.components.push_back(c);
      }
      m_.sensors.push_back(sensor);
    }
  }

  // The point Jacobians written in extenso.
  void read_jacobians(const YAML::Node& js) {
    for (std::size_t i = 0; i < js.size(); ++i) {
      const YAML::Node j = js[i];
      const std::string field = "jacobians[" + std::to_string(i) + "]";
      check_keys(j, field, {"name", "point"});
      if (!j["name"] || !j["point"]) fail(j, field, "needs name and point");
      m_.jacobians.push_back({text(j["name"], field + ".name"), point(j["point"], field + ".point")});
    }
  }

  // The independent coordinates the model names.
  void read_independent(const YAML::Node& ind) {
    if (!ind.IsSequence()) fail(ind, "independent", "expected a list of joint names");
    for (std::size_t i = 0; i < ind.size(); ++i) {
      const int k = joint_index(ind[i], "independent");
      if (m_.joints[k].driven) fail(ind[i], "independent", "a driven joint cannot be independent");
      m_.independent.push_back(k);
    }
  }

  // The start of an entry of a list section: its keys checked, its name (`fallback` and its number
  // when it has none and a fallback is given; required otherwise), its field for messages
  // ("cuts.NAME") and its type ("" when it has none).
  struct Entry {
    std::string name, field, type;
  };
  Entry entry(const YAML::Node& node, const std::string& section, std::size_t i,
              std::initializer_list<const char*> keys, const char* fallback = nullptr) const {
    const std::string at = section + "[" + std::to_string(i) + "]";
    check_keys(node, at, keys);
    Entry e;
    if (node["name"]) e.name = text(node["name"], at + ".name");
    else if (fallback) e.name = fallback + std::to_string(i + 1);
    else fail(node, at, "missing name");
    e.field = section + "." + e.name;
    e.type = node["type"] ? text(node["type"], e.field + ".type") : "";
    return e;
  }

 private:
  Model& m_;
  std::string file_;
};

}  // namespace

int Model::constraint_count() const {
  int m = 0;
  for (const Cut& c : cuts) m += c.equations();
  return m;
}

std::vector<int> Model::driven_joints() const {
  std::vector<int> d;
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (joints[k].driven) d.push_back(static_cast<int>(k));
  return d;
}

int Model::load_input_count() const {
  int n = 0;
  for (const Load& l : loads) n += l.width();
  return n;
}

int Model::input_count() const { return load_input_count() + 3 * static_cast<int>(driven_joints().size()); }

std::vector<std::string> Model::input_names() const {
  std::vector<std::string> names;
  static const char* const xyz[] = {"x", "y", "z"};
  for (const Load& l : loads) {
    if (l.type == Load::Type::LinkForce) names.push_back(l.name);
    else
      for (int c : l.components) names.push_back(l.name + "." + xyz[c]);
  }
  for (int k : driven_joints())
    for (const char* c : {"q", "qd", "qdd"}) names.push_back(joints[k].name + "." + c);
  return names;
}

int Model::symbolic_parameter_count() const {
  int n = 0;
  for (const Parameter& p : parameters) n += p.symbolic;
  return n;
}

std::vector<std::string> Model::sensor_output_names() const {
  std::vector<std::string> names;
  for (const Sensor& s : sensors) {
    static const char* const xyz[] = {"x", "y", "z"};
    static const char* const length[] = {"length", "rate"};
    static const char* const joint[] = {"q", "qd", "qdd"};
    const char* const* parts = s.type == Sensor::Type::Length ? length : s.type == Sensor::Type::Joint ? joint : xyz;
    for (int c : s.components) names.push_back(s.name + "." + parts[c]);
  }
  return names;
}

Model parse_model(const std::string& text, const std::string& file) {
  Model model;
  model.file = file;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw symbolic::ParseError(file, e.mark.line + 1, "yaml: " + e.msg);
  }
  Loader(model, file).load(root);
  if (model.name.empty()) {
    std::string stem = file.substr(file.find_last_of('/') + 1);
    model.name = stem.substr(0, stem.find('.'));
  }
  return model;
}

Model load_model(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw symbolic::ParseError(path, 0, "file: cannot be read");
  std::stringstream s;
  s << in.rdbuf();
  return parse_model(s.str(), path);
}

}  // namespace dydp::mbs
