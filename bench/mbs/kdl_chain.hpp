// The Orocos KDL chain equivalent to a serial dydp multibody model (the KDL test and benchmark).
//
// Conventions (those of symbolic/mbs/numeric_dynamics.cpp, the oracle), and how they map:
//   - joint k's frame = joint parent(k)'s frame, moved by `offset` (parent-frame components),
//     then rotated about (or translated along) `axis` (parent-frame components; for a rotation
//     they are also the joint frame's, the axis being fixed by it). At q = 0 the joint frame is
//     parallel to its parent's.
//     KDL: one segment per joint, whose root frame is the previous segment's tip. The joint is a
//     RotAxis / TransAxis joint with origin = offset and the same axis (root-frame components):
//     its pose is Frame(Rot(axis, q), offset) or Frame(offset + q axis). Segment's constructor
//     takes the tip relative to the root *at q = 0* and stores joint.pose(0)^-1 f_tip, so passing
//     Frame(offset) makes the tip frame the joint frame itself (stored f_tip = identity).
//   - a body's frame is the frame of the last joint of its `joints` list, its com is in that frame
//     and its inertia (Ixx, Iyy, Izz, Ixy, Ixz, Iyz: the entries of the tensor, not negated
//     products) is about the centre of mass, body-frame axes.
//     KDL: the segment's inertia is expressed in its tip frame; RigidBodyInertia(m, com, Ic) takes
//     the rotational inertia about the centre of gravity (it moves it to the tip origin itself),
//     and RotationalInertia takes the same six tensor entries in the same order.
//     Intermediate frames (joints ending no body) are segments with zero inertia.
//   - gravity is the acceleration of gravity in ground components: KDL's `grav` argument too.
//   - coordinate k is segment k's joint: KDL numbers joints in segment order.
// Parameters take their values as written in the model (the generated functions' defaults).
//
// KDL's solvers (ChainIdSolver_RNE, ChainDynParam, ChainFdSolver_RNE) keep a *reference* to the
// chain they are built from (in 1.5.1, despite "an internal copy will be made" in the FD
// solver's documentation): KdlDynamics owns the chain and the solvers together, and is
// neither copied nor moved.
#pragma once

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfdsolver_recursive_newton_euler.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>
#include <stdexcept>
#include <string>

#include "symbolic/mbs/model.hpp"

namespace dydp::bench {

// The KDL chain of `model`. Throws std::invalid_argument for what a KDL chain cannot hold or
// this mapping does not carry over: a joint whose parent is not the previous joint (a tree or
// a reordered chain), cut joints, force elements, loads, driven joints.
inline KDL::Chain kdl_chain(const mbs::Model& model) {
  const std::string where = "kdl_chain(" + model.name + "): ";
  if (!model.cuts.empty()) throw std::invalid_argument(where + "cut joints (closed loops) are not a chain");
  if (!model.forces.empty()) throw std::invalid_argument(where + "force elements are not carried over");
  if (!model.loads.empty()) throw std::invalid_argument(where + "loads are not carried over");
  auto vec = [&](const mbs::Vec3Value& v) { return KDL::Vector(model.value(v[0]), model.value(v[1]), model.value(v[2])); };
  KDL::Chain chain;
  for (int k = 0; k < model.coordinates(); ++k) {
    const mbs::Joint& joint = model.joints[k];
    if (joint.parent != k - 1)
      throw std::invalid_argument(where + "joint '" + joint.name + "' does not follow the previous joint (not a serial chain in coordinate order)");
    if (joint.driven) throw std::invalid_argument(where + "driven joint '" + joint.name + "'");
    const KDL::Vector offset = vec(joint.offset);
    const KDL::Vector axis(joint.axis[0], joint.axis[1], joint.axis[2]);
    const KDL::Joint kdl_joint(joint.name, offset, axis, mbs::is_revolute(joint.type) ? KDL::Joint::RotAxis : KDL::Joint::TransAxis);
    KDL::RigidBodyInertia inertia = KDL::RigidBodyInertia::Zero();
    if (joint.body >= 0) {
      const mbs::Body& b = model.bodies[joint.body];
      const auto I = [&](int i) { return model.value(b.inertia[i]); };
      inertia = KDL::RigidBodyInertia(model.value(b.mass), vec(b.com), KDL::RotationalInertia(I(0), I(1), I(2), I(3), I(4), I(5)));
    }
    chain.addSegment(KDL::Segment(joint.body >= 0 ? model.bodies[joint.body].name : joint.name, kdl_joint,
                                  KDL::Frame(offset), inertia));
  }
  return chain;
}

inline KDL::Vector kdl_gravity(const mbs::Model& model) {
  return KDL::Vector(model.gravity[0], model.gravity[1], model.gravity[2]);
}

// The chain of a model with KDL's three solvers, and their work arrays (sized once: the timed
// calls allocate nothing).
struct KdlDynamics {
  explicit KdlDynamics(const mbs::Model& model)
      : chain(kdl_chain(model)),
        n(chain.getNrOfJoints()),
        id(chain, kdl_gravity(model)),
        dyn(chain, kdl_gravity(model)),
        fd(chain, kdl_gravity(model)),
        f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero()),
        torques(n),
        qdd(n),
        H(n) {}
  KdlDynamics(const KdlDynamics&) = delete;
  KdlDynamics& operator=(const KdlDynamics&) = delete;

  // Each returns KDL's error code (0: KDL::SolverI::E_NOERROR).
  // Joint forces M qdd + c (gravity included, no external wrenches) into `torques`.
  int inverse(const KDL::JntArray& q, const KDL::JntArray& qd, const KDL::JntArray& qdd_in) {
    return id.CartToJnt(q, qd, qdd_in, f_ext, torques);
  }
  // M(q) into H.
  int mass(const KDL::JntArray& q) { return dyn.JntToMass(q, H); }
  // Accelerations under the joint forces `tau` into qdd.
  int forward(const KDL::JntArray& q, const KDL::JntArray& qd, const KDL::JntArray& tau) {
    return fd.CartToJnt(q, qd, tau, f_ext, qdd);
  }

  const KDL::Chain chain;  // first: the solvers below refer to it
  const unsigned int n;
  KDL::ChainIdSolver_RNE id;
  KDL::ChainDynParam dyn;
  KDL::ChainFdSolver_RNE fd;
  KDL::Wrenches f_ext;
  KDL::JntArray torques, qdd;
  KDL::JntSpaceInertiaMatrix H;
};

}  // namespace dydp::bench
