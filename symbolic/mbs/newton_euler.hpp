// The symbolic multibody generator: forward kinematics and backward recursive Newton-Euler in
// body-frame components (ROBOTRAN's relative-coordinate formalism) written as recursive equation
// lists, the constraints of the cut joints and their derivatives by recursive differentiation,
// sensors and point Jacobians. Every list shares one Context whose arrays, in order, are
// q, qd, qdd, lam (cut forces), inp (loads and driven motions) and p (symbolic parameters).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"
#include "symbolic/mbs/model.hpp"

namespace dydp::mbs {

// M of a tree too deep for its entries to be written one by one (a long chain): the same
// composite-inertia recursion, with the carrying of each joint's unit-acceleration wrench to its
// ancestors written as loops. A lane holds one joint's wrench (F, N: six values); the lanes are
// in depth-first order, so that every subtree's lanes are contiguous.
struct MassLoops {
  std::vector<int> lane_joint;  // joint of each lane
  // Outputs: the lanes' starting values, lane-major (value a of lane t at a * n + t; F in the
  // joint's own frame, then N about its origin), M(j, j) of each lane's joint (n), then the
  // values of `reads`.
  std::unique_ptr<symbolic::EquationList> start;
  // Auxiliaries and sin/cos abbreviations the sweeps read (besides the function's arrays).
  std::vector<symbolic::NodeId> reads;
  // Placeholders: a lane's six values before a sweep (F1 F2 F3 N1 N2 N3), and after it.
  std::array<symbolic::NodeId, 6> lane{}, moved_lane{};
  struct Sweep {
    int joint;           // the lanes of this joint's subtree move to its parent's frame
    int parent;          // the entries' column: M(lane's joint, parent)
    int begin, end;      // those lanes
    // The moved values: F' of `lane`, N' of `lane` and F' (the first three of `moved_lane`).
    std::array<symbolic::NodeId, 6> moved{};
    symbolic::NodeId entry = 0;  // M(lane's joint, parent), of `moved_lane`
  };
  // Deepest first; entries: M(j, j) by lane, then each sweep's (end - begin) in order.
  std::vector<Sweep> sweeps;
};

struct ModelLists {
  std::unique_ptr<symbolic::Context> context;
  symbolic::ArrayId q = 0, qd = 0, qdd = 0, lam = 0, inp = 0, p = 0;
  // Outputs M qdd of the inertial pass (qd = 0, no gravity, no loads): seeded on qdd, its
  // tangent gives the columns of M.
  std::unique_ptr<symbolic::EquationList> inertial;
  // The entries of M by composite inertias: outputs named M[i,k] (k = i and every ancestor of
  // joint i), the structurally nonzero entries; null for trees too deep for it (see
  // kMassEntriesPerCoordinate in newton_euler_generator.hpp), which use the inertial pass's tangent.
  std::unique_ptr<symbolic::EquationList> mass_matrix;
  // The same entries as loops, for the trees that have no mass_matrix.
  std::unique_ptr<MassLoops> mass_loops;
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

// How M's composite-inertia entries are written: one assignment each (mass_matrix), or as
// loops (mass_loops); Automatic takes the loops for trees too deep for the entries one by one.
enum class MassForm { Automatic, Entries, Loops };

// Builds every list, eliminated. Arrays of size zero are given one unused element so that every
// emitted function has the same signature.
ModelLists build_model_lists(const Model& model, MassForm mass_form = MassForm::Automatic);

// The arrays tangent functions are seeded on: q, qd, qdd, inp, p.
std::vector<symbolic::ArrayId> tangent_arrays(const ModelLists& lists);

}  // namespace dydp::mbs
