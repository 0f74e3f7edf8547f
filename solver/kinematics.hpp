#pragma once
// Kinematic stages of the midpoint step: half-step drift and the free rotation.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

#include "solver/state.hpp"

namespace talus {

// The turn of Drift's last call: a step's end drift and the next step's midpoint drift turn by the
// same body rate over the same time, so the second reuses the first's sine and cosine. Keyed on the
// rate and time themselves, so a reused turn is the same bits as a computed one.
struct DriftTurn {
  Eigen::Vector3d rate_rad_s = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double h_s = std::numeric_limits<double>::quiet_NaN();
  bool turns = false;  // |rate| > 0
  Eigen::Quaterniond turn = Eigen::Quaterniond::Identity();
};

// Advances position by h v and orientation by the body angular velocity over h (exact
// quaternion exponential of a constant body rate), then renormalises the quaternion. With `last`,
// reuses and keeps the turn.
void Drift(RockState& state, double h_s, DriftTurn* last = nullptr);

// Implicit midpoint rule for the torque-free Euler equations:
// Theta (W_f - W_b) + dt W_m x (Theta W_m) = 0, W_m = (W_b + W_f)/2, solved by Newton's method
// (a step it cannot take, turning the rock by several radians, as two halves).
// It conserves kinetic energy and |angular momentum| exactly (both are quadratic invariants),
// which keeps rotation about the major axis stable (Leine et al. 2021).
Eigen::Vector3d FreeRotation(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b,
                             double dt_s);

}  // namespace talus
