#pragma once
// Contact solve stage: percussions from the set-valued contact laws by proximal-point
// Gauss-Seidel iterations (Leine et al. 2014).

#include <Eigen/Core>

#include "solver/contact.hpp"
#include "solver/scene.hpp"

namespace talus {

struct ContactSolveReport {
  int iterations = 0;
  bool converged = true;
  bool loaded = false;  // at least one contact carries a positive normal percussion
};

// How a percussion P changes the end velocities: dv = P / mass_kg, dOmega = Theta^-1 W P /
// inertia_scale. The rock's own mass and inertia (scale 1), or larger ones where the step folds a
// drag into the velocity update (centre-of-mass viscous term, drag layer; solver/step.cpp).
struct EffectiveInertia {
  double mass_kg = 0;
  double inertia_scale = 1;
};

// Solves for the percussions of workspace.contacts and updates the end velocities in place.
// On entry velocity_m_s and omega_rad_s hold the free (contact-less) end velocities, with the
// effective mass and inertia `inertia`; v_begin, omega_begin are the step's begin velocities
// (needed only for restitution). Contact laws are imposed on xi = gamma_E + eps gamma_B + (gap_m /
// dt, 0, 0): Signorini/Newton in the normal direction, Coulomb disk in the tangent plane; with
// ViscousReading::kContactFriction the tangential percussion of a loaded contact adds -nu dt m (P_N
// / sum P_N) gamma_T,E, which does negative work on the end velocity and none when the contact does
// not slip. For a predicted contact (gap_m > 0) the normal law reads gap_m + dt gamma_N,E >= 0: the
// vertex may approach by its gap until the next midpoint, not beyond; its percussion then does
// negative work on the end velocity (P_N gamma_N,E <= 0), as a closed contact's does none, so
// neither adds energy. The iteration stops when no contact changes the velocity of any body point
// by more than the tolerance. dt_s is the step's length: scene.options.dt_s, or a sub-step's
// (solver/step.hpp).
ContactSolveReport SolveContacts(const Scene& scene, const RockShape& rock, double dt_s,
                                 const Eigen::Matrix3d& rotation, const EffectiveInertia& inertia,
                                 const Eigen::Vector3d& v_begin, const Eigen::Vector3d& omega_begin,
                                 Eigen::Vector3d& velocity_m_s, Eigen::Vector3d& omega_rad_s,
                                 StepWorkspace& workspace);

}  // namespace talus
