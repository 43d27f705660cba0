// The sensors' outputs, read off the kinematics and the full pass's accelerations.
#include "symbolic/mbs/newton_euler_generator.hpp"

#include <string>
#include <vector>

namespace dydp::mbs::detail {

// Sensors in the components of their frame, each through the rotation relative to the frame
// when that frame carries the point (the chassis frame and a wheel centre: the corner's joints
// only); lengths in the frame of the two bodies' common ancestor, like the link forces.
std::vector<Expr> Generator::sensor_values() {
  std::vector<Expr> values;
  int index = 0;
  for (const Sensor& s : m_.sensors) {
    ++index;
    const std::string name = "SENS" + std::to_string(index) + "_";
    V3 v;
    const int frame = m_.bodies[s.frame].frame;
    switch (s.type) {
      case Sensor::Type::AngularVelocity: {
        const int f = m_.bodies[s.a.body].frame;
        v = f < 0 ? zero3() : change_frame(f, frame, omega_[f]);
        break;
      }
      case Sensor::Type::Position:
        if (carries(frame, m_.bodies[s.a.body].frame)) v = point_in(s.a, frame);
        else v = body_rotation(s.frame).apply_transpose(point_position(s.a) - body_origin(s.frame));
        break;
      case Sensor::Type::Velocity: v = velocity_in(s.a, frame); break;
      case Sensor::Type::Acceleration: v = acceleration_in(s.a, frame); break;
      case Sensor::Type::Joint:
        v = V3{{ctx_->element(out_.q, s.joint), ctx_->element(out_.qd, s.joint), ctx_->element(out_.qdd, s.joint)}};
        break;
      case Sensor::Type::Length: {
        const int c = common_frame(m_.bodies[s.a.body].frame, m_.bodies[s.b.body].frame);
        const V3 d = assign(name + "D", 0, point_in(s.b, c) - point_in(s.a, c));
        const Expr length = all_->assign(name + "L", symbolic::sqrt(dot(d, d)));
        const Expr rate = dot(d, velocity_in(s.b, c) - velocity_in(s.a, c)) / length;
        const Expr extension = length - val(s.reference);
        v = V3{{s.compression ? -extension : extension, s.compression ? -rate : rate, ctx_->zero()}};
        break;
      }
    }
    v = assign(name, 0, v);
    for (int c : s.components) values.push_back(v[c]);
  }
  return values;
}

}  // namespace dydp::mbs::detail
