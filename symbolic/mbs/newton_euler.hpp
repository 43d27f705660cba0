// The symbolic multibody generator: forward kinematics and backward recursive Newton-Euler in
// body-frame components (ROBOTRAN's relative-coordinate formalism) written as recursive equation
// lists, the constraints of the cut joints and their derivatives by recursive differentiation,
// sensors and point Jacobians. Every list shares one Context whose arrays, in order, are
// q, qd, qdd, lam (cut forces), inp (loads and driven motions) and p (symbolic parameters).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"
#include "symbolic/mbs/model.hpp"

namespace dydp::mbs {

struct ModelLists {
  std::unique_ptr<symbolic::Context> context;
  symbolic::ArrayId q = 0, qd = 0, qdd = 0, lam = 0, inp = 0, p = 0;
  // Outputs M qdd of the inertial pass (qd = 0, no gravity, no loads): seeded on qdd, its
  // tangent gives the columns of M.
  std::unique_ptr<symbolic::EquationList> inertial;
  // The entries of M by composite inertias: outputs named M[i,k] (k = i and every ancestor of
  // joint i), the structurally nonzero entries; null for trees too deep for it (see
  // newton_euler.cpp), which use the inertial pass's tangent.
  std::unique_ptr<symbolic::EquationList> mass_matrix;
  // r = M qdd + c - J^T lam (n outputs), then the constraint accelerations J qdd + Jdot qd (m),
  // the cut points' relative accelerations from the full pass (Jdot qd: the same at qdd = 0).
  std::unique_ptr<symbolic::EquationList> residual;
  // The same without the cut forces (lam not read): M qdd + c (n), then J qdd + Jdot qd (m). The
  // partitioning evaluates this one; the multipliers enter only through the residual's tangent.
  std::unique_ptr<symbolic::EquationList> applied;
  // h (m), J (m x n, row-major).
  std::unique_ptr<symbolic::EquationList> constraints;
  // h (m), J qd (m): its tangent gives the dependent coordinates' and velocities' derivatives.
  std::unique_ptr<symbolic::EquationList> velocity_constraints;
  // h (m), J (m x n), Jdot qd (m) in one list, Jdot qd from the loops' relative kinematics at
  // qdd = 0: what the constraints cost together (dydp-gen --stats); null when a cut needs the
  // absolute kinematics (a hinge, a ball in ground components).
  std::unique_ptr<symbolic::EquationList> constraint_kinematics;
  // h (m) alone: its tangent gives dh for the dependent coordinates' derivatives.
  std::unique_ptr<symbolic::EquationList> position_constraints;
  std::unique_ptr<symbolic::EquationList> sensors;
  struct Named {
    std::string name;
    std::unique_ptr<symbolic::EquationList> list;
  };
  std::vector<Named> jacobians;  // 3 x n row-major, ground components
  std::size_t assignments_built = 0;  // the whole recursive scheme before any elimination
};

// Builds every list, eliminated. Arrays of size zero are given one unused element so that every
// emitted function has the same signature.
ModelLists build_model_lists(const Model& model);

// The arrays tangent functions are seeded on: q, qd, qdd, inp, p.
std::vector<symbolic::ArrayId> tangent_arrays(const ModelLists& lists);

}  // namespace dydp::mbs
