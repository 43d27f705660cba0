// What a generated multibody model exposes at run time: sizes, names, and pointers to its
// generated functions. dydp-gen writes one constant of this type per model; generated_models/
// collects them in a registry. Plain data: no dependency on the generator or the engine.
#pragma once

namespace dydp::mbs {

// Every generated function reads the arrays q, qd, qdd (n), lam (m), inp (inputs), p (symbolic
// parameters), in this order; arrays of size zero are passed as one unused element.
using GeneratedFunction = void (*)(const double* q, const double* qd, const double* qdd, const double* lam,
                                   const double* inp, const double* p, double* out);
// Tangent seeded on q, qd, qdd, inp and p: seed (i, d) of array x (size s) at seed_x[d*s + i],
// derivative (j, d) of output j (k outputs) at dout[d*k + j].
using GeneratedTangent = void (*)(const double* q, const double* qd, const double* qdd, const double* lam,
                                  const double* inp, const double* p, int nd, const double* seed_q,
                                  const double* seed_qd, const double* seed_qdd, const double* seed_inp,
                                  const double* seed_p, double* out, double* dout);
// Tangent seeded on qd, qdd, inp and p, not on q: the derivatives for seeds with dq = 0 (a
// direction that moves no coordinate), arrays laid out as in GeneratedTangent.
using GeneratedVelocityTangent = void (*)(const double* q, const double* qd, const double* qdd, const double* lam,
                                          const double* inp, const double* p, int nd, const double* seed_qd,
                                          const double* seed_qdd, const double* seed_inp, const double* seed_p,
                                          double* out, double* dout);
// The residual's tangent in blocks, after one primal (symbolic/grouped_tangent.hpp): nd[b]
// directions for block b, the blocks' directions consecutive in the seeds and in dout, laid out
// as in GeneratedTangent. Block 0 is seeded on every array (as GeneratedTangent), block 1 on
// qd, qdd, inp and p (as GeneratedVelocityTangent); for each coordinate group g, block 2 + 2g
// on q, qd and qdd in the group only, block 3 + 2g on qd and qdd in the group only.
using GeneratedGroupedTangent = void (*)(const double* q, const double* qd, const double* qdd, const double* lam,
                                         const double* inp, const double* p, const int* nd, const double* seed_q,
                                         const double* seed_qd, const double* seed_qdd, const double* seed_inp,
                                         const double* seed_p, double* out, double* dout);
// Tangent seeded on qdd only (the inertial pass: columns of M); it writes no primal outputs
// (`out` is not touched).
using GeneratedMassTangent = void (*)(const double* q, const double* qd, const double* qdd, const double* lam,
                                      const double* inp, const double* p, int nd, const double* seed_qdd,
                                      double* out, double* dout);

struct GeneratedModel {
  const char* name;
  int n;           // coordinates
  int m;           // constraints
  int inputs;      // the loads' components, then q, qd, qdd of each driven joint
  int loads;       // number of loads (their inputs: load_inputs, load_widths below)
  int parameters;  // symbolic parameters
  int sensor_outputs;
  const char* const* coordinate_names;
  const char* const* input_names;
  const char* const* parameter_names;
  const double* parameter_values;  // as written in the model
  const char* const* sensor_names;  // one per sensor output (`tip.x`)
  int sensor_count;                 // sensors (each sensor_widths[i] outputs, in order)
  const char* const* sensor_ports;  // sensor names
  const int* sensor_widths;
  const int* sensor_reads_acceleration;  // 1: depends on qdd (acceleration and joint sensors)
  const double* initial_q;
  int driven_count;
  const int* driven;       // coordinates imposed by inputs
  int independent_count;
  const int* independent;  // coordinates u; the others (not driven) are dependent
  GeneratedMassTangent mass;                       // seeded on qdd: columns of M
  GeneratedFunction residual;                      // M qdd + c (n), J qdd + Jdot qd (m); lam not read
  // Seeded like every tangent, of M qdd + c - J^T lam (n) and J qdd + Jdot qd (m): the cut
  // forces enter here only (the partitioning's tangent differentiates J^T lam at frozen lam).
  GeneratedTangent residual_tangent;
  GeneratedFunction constraints;                   // h (m), J (m x n row-major)
  GeneratedTangent velocity_constraints_tangent;   // h (m), J qd (m)
  GeneratedFunction sensors;
  GeneratedTangent sensors_tangent;
  // Load ports: the first `load_inputs` inputs, load_widths[i] of them for load i (3 for a force
  // or torque, fewer with components, 1 for a link force).
  int load_inputs;
  const char* const* load_names;
  const int* load_widths;
  const char* const* sensor_units;  // SI unit of each sensor port ("m", "m/s", "rad", ...)
  // m x n row-major: 0 where J is zero whatever the state (a joint that does not move the cut).
  const int* jacobian_nonzero;
  GeneratedTangent constraints_tangent;  // h (m) and its tangent: dh for dq (cheaper than h, J qd)
  // M by composite inertias: mass_matrix writes mass_entries values, M(mass_rows[k],
  // mass_cols[k]) = M(mass_cols[k], mass_rows[k]) = out[k]; the other entries are zero (joints
  // neither of which carries the other). Null (mass_entries 0) for a tree too deep for it
  // (chain200): M comes from `mass` then.
  int mass_entries;
  const int* mass_rows;
  const int* mass_cols;
  GeneratedFunction mass_matrix;
  const char* const* parameter_units;  // SI unit of each symbolic parameter ("" if the model gives none)
  // The sensors in two groups, each writing its ports' outputs in port order as `sensors` does:
  // the ports that do not read qdd (sensor_reads_acceleration 0; their tangent's qdd seeds are
  // not read) and those that do. A block asked for positions before the loads are known, and
  // for accelerations after, computes each group once.
  GeneratedFunction sensors_kinematic;
  GeneratedTangent sensors_kinematic_tangent;
  GeneratedFunction sensors_acceleration;
  GeneratedTangent sensors_acceleration_tangent;
  // residual_tangent for directions with dq = 0: it computes only what the velocities, loads,
  // accelerations and parameters reach, none of the rotations' and positions' derivatives.
  GeneratedVelocityTangent residual_velocity_tangent;
  // Groups of coordinates that move together (those a constraint row couples; the others alone)
  // whose directions cost at most half a full one in residual_tangent_groups: tangent_group[i]
  // is coordinate i's group or -1. Zero groups (and a null function) when none pays.
  int tangent_groups;
  const int* tangent_group;
  GeneratedGroupedTangent residual_tangent_groups;
};

}  // namespace dydp::mbs
