// A multibody model description (`*.mbs.yaml`, documented in docs/models.md): a tree of bodies on
// 1-DOF joints, cut joints closing loops, force elements, external loads (inputs), sensors and
// Jacobians. Every numeric value is either a constant or a named parameter.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace dydp::mbs {

// A number of the model: a constant, or `scale` times parameter `param` (index into
// Model::parameters; written `$name` or `-$name`).
struct Value {
  double value = 0.0;
  int param = -1;
  double scale = 1.0;
};
using Vec3Value = std::array<Value, 3>;

struct Parameter {
  std::string name;
  double value = 0.0;
  bool symbolic = true;  // kept as a symbol (a sensitivity direction) or folded as a constant
  std::string unit;      // SI unit as written (`kg`, `m`), empty if none was given
};

// R and T: about / along an arbitrary unit axis (Joint::axis) of the frame the joint starts from.
enum class JointType { Rx, Ry, Rz, Tx, Ty, Tz, R, T };
inline bool is_revolute(JointType t) {
  return t == JointType::Rx || t == JointType::Ry || t == JointType::Rz || t == JointType::R;
}
// 0, 1, 2 for the frame's own axes, -1 for an arbitrary axis.
inline int axis_of(JointType t) { return t == JointType::R || t == JointType::T ? -1 : static_cast<int>(t) % 3; }

// One 1-DOF joint: a rotation about, or a translation along, an axis of the frame it starts from.
// Joint k's frame = frame of `parent` (a joint index, -1 for ground) moved by `offset` (parent
// frame), then by the joint motion. Coordinate q[k] belongs to joint k. A rotation about an
// arbitrary axis a is R = cos q I + sin q [a]x + (1 - cos q) a a^T, so at q = 0 the joint frame
// is parallel to its parent's (hardpoints of a whole suspension can be written in one frame).
struct Joint {
  std::string name;
  JointType type = JointType::Rz;
  std::array<double, 3> axis{0.0, 0.0, 1.0};  // unit, parent-frame components (set for every type)
  int parent = -1;
  Vec3Value offset{};
  bool driven = false;   // q, qd, qdd come from inputs
  double initial = 0.0;  // q(0), used by the automatic partitioning and as the block's default
  int body = -1;         // the body whose frame this joint ends, -1 for intermediate frames
};

struct Anchor {
  std::string name;
  Vec3Value position{};  // in the body frame
};

struct Body {
  std::string name;
  int frame = -1;  // the joint whose frame is the body frame; -1 for ground
  Value mass;
  Vec3Value com{};
  std::array<Value, 6> inertia{};  // Ixx, Iyy, Izz, Ixy, Ixz, Iyz about the centre of mass, body frame
  std::vector<Anchor> anchors;
};

// A point of a body: body index (0 = ground), anchor index.
struct PointRef {
  int body = 0;
  int anchor = 0;
};

// Cut joints. Ball: the two points coincide (components x, y, z in the ground frame, optionally
// a subset for planar models). Distance: |b - a| = length. Hinge: the two points coincide (x, y,
// z) and the axis fixed in b's body stays along the axis fixed in a's body: its components along
// two unit normals n1, n2 of a's axis vanish, (R_a n1) . (R_b axis_b) = (R_a n2) . (R_b axis_b) = 0
// (5 equations).
struct Cut {
  std::string name;
  enum class Type { Ball, Distance, Hinge } type = Type::Ball;
  PointRef a, b;
  std::vector<int> components;  // ball: which of x, y, z
  Value length;                 // distance
  // hinge: unit axes in the frames of a's and b's bodies, and the normals of axis_a (a's frame):
  // n1 = the frame axis least along axis_a, made orthogonal to it and normalised; n2 = axis_a x n1.
  std::array<double, 3> axis_a{0.0, 0.0, 1.0}, axis_b{0.0, 0.0, 1.0};
  std::array<std::array<double, 3>, 2> normals_a{};
  int equations() const {
    return type == Type::Ball ? static_cast<int>(components.size()) : type == Type::Hinge ? 5 : 1;
  }
};

// Internal force elements. Spring: linear spring-damper between two points, force
// k (L - l0) + c dL/dt along the line. JointForce: a constant generalised force on a joint.
struct ForceElement {
  std::string name;
  enum class Type { Spring, JointForce } type = Type::Spring;
  PointRef a, b;
  Value stiffness, rest_length, damping;
  int joint = -1;
  Value value;
};

// External loads, inputs of the model: a force at a point, or a torque on a body, components in
// the frame of body `frame` (0 = ground), all three or the subset `components` (one input each);
// or a link force: one input, the magnitude of equal and opposite forces at points a and b along
// the line between them, positive pulling them together (`tension`) or pushing them apart
// (`compression`, the convention of the spring blocks). A torque may react on a second body
// (`reaction`): a drive or brake torque between a wheel and its upright.
struct Load {
  std::string name;
  enum class Type { Force, Torque, LinkForce } type = Type::Force;
  PointRef point;  // force: the point; torque: point.body is the body; link force: point a
  PointRef b;      // link force: point b
  int frame = 0;
  std::vector<int> components{0, 1, 2};
  bool compression = false;  // link force: positive pushes apart
  int reaction = -1;         // torque: the body the opposite torque acts on (-1: none)
  int width() const { return type == Type::LinkForce ? 1 : static_cast<int>(components.size()); }
};

// Sensors. Position, velocity, acceleration of a point and angular velocity of a body (x, y, z in
// the frame of body `frame`); length of the line a-b and its rate (or, with `compression`,
// reference - length and its rate); joint q, qd, qdd. `components` keeps a subset of the
// outputs, in the order given (x y z; length rate; q qd qdd).
struct Sensor {
  std::string name;
  enum class Type { Position, Velocity, Acceleration, AngularVelocity, Length, Joint } type = Type::Position;
  PointRef a, b;  // b: for Length; AngularVelocity: a.body is the body
  int frame = 0;  // components in this body's frame (0 = ground)
  int joint = -1;
  Value reference;           // length: subtracted from (compression) or subtracted (extension)
  bool compression = false;  // length: reference - length, -rate
  std::vector<int> components;  // indices of the kept outputs
  int full_width() const { return type == Type::Length ? 2 : 3; }
  int width() const { return static_cast<int>(components.size()); }
};

// The Jacobian d(position of point)/dq, components in the ground frame, 3 x n row-major.
struct JacobianRequest {
  std::string name;
  PointRef point;
};

struct Model {
  std::string name;
  std::string file;
  std::array<double, 3> gravity{0.0, 0.0, -9.81};
  std::vector<Parameter> parameters;
  std::vector<Joint> joints;
  std::vector<Body> bodies;  // bodies[0] is ground
  std::vector<Cut> cuts;
  std::vector<ForceElement> forces;
  std::vector<Load> loads;
  std::vector<Sensor> sensors;
  std::vector<JacobianRequest> jacobians;
  std::vector<int> independent;  // chosen by the model; empty: automatic (pivoted QR)
  std::vector<int> order;        // joints with every parent before its children

  int coordinates() const { return static_cast<int>(joints.size()); }
  int constraint_count() const;
  // Inputs: the loads' components (Load::width each), then q, qd, qdd of every driven joint.
  int input_count() const;
  int load_input_count() const;
  std::vector<std::string> input_names() const;
  std::vector<int> driven_joints() const;
  int symbolic_parameter_count() const;
  std::vector<std::string> sensor_output_names() const;
  double value(const Value& v) const { return v.param < 0 ? v.value : v.scale * parameters[v.param].value; }
};

// Reads a model; errors are symbolic::ParseError with `file:line: field: message`.
Model load_model(const std::string& path);
Model parse_model(const std::string& text, const std::string& file);

}  // namespace dydp::mbs
