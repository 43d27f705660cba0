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
};

enum class JointType { Rx, Ry, Rz, Tx, Ty, Tz };
inline bool is_revolute(JointType t) { return t == JointType::Rx || t == JointType::Ry || t == JointType::Rz; }
inline int axis_of(JointType t) { return static_cast<int>(t) % 3; }

// One 1-DOF joint: a rotation about, or a translation along, an axis of the frame it starts from.
// Joint k's frame = frame of `parent` (a joint index, -1 for ground) moved by `offset` (parent
// frame), then by the joint motion. Coordinate q[k] belongs to joint k.
struct Joint {
  std::string name;
  JointType type = JointType::Rz;
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
// a subset for planar models). Distance: |b - a| = length.
struct Cut {
  std::string name;
  enum class Type { Ball, Distance } type = Type::Ball;
  PointRef a, b;
  std::vector<int> components;  // ball: which of x, y, z
  Value length;                 // distance
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

// External loads, inputs of the model: a force (3 components) at a point, or a torque (3) on a
// body, components in the frame of body `frame` (0 = ground).
struct Load {
  std::string name;
  enum class Type { Force, Torque } type = Type::Force;
  PointRef point;  // force: the point; torque: point.body is the body
  int frame = 0;
};

struct Sensor {
  std::string name;
  enum class Type { Position, Velocity, Acceleration, Length, Joint } type = Type::Position;
  PointRef a, b;  // b: for Length
  int frame = 0;  // components in this body's frame (0 = ground)
  int joint = -1;
  int width() const { return type == Type::Length ? 2 : 3; }
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
  // Inputs: 3 per load, then q, qd, qdd of every driven joint.
  int input_count() const;
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
