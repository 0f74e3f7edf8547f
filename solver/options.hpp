#pragma once
// Solver options: every knob a user trades against accuracy, with defaults, units and a check.

#include <string>

namespace talus {

struct SolverOptions {
  double dt_s = 0.002;                  // time step
  double max_time_s = 300;              // a rock still moving then ends as max_time
  double gravity_m_s2 = 9.81;           // along -z
  double normal_restitution = 0.0;      // epsilon_N in [0, 1]; the model is fully plastic (0)
  double tangential_restitution = 0.0;  // epsilon_T in [-1, 1]; 0: no tangential rebound
  // Contact solve: Gauss-Seidel sweeps until the largest velocity change a sweep makes at any
  // contact point is below tolerance_m_s, or max_iterations sweeps.
  double tolerance_m_s = 1e-7;
  int max_iterations = 200;
  double prox_alpha = 1.0;  // step length r = alpha / diag(W' M^-1 W), in (0, 2)
  // Contact prediction (plastic normal law only): a vertex that would sink deeper than this
  // fraction of the rock's thickness by the next midpoint joins the contact set early and is
  // stopped at that depth. In (0, 0.5].
  double penetration_tolerance = 0.01;
  // Rest: speed and angular speed below these thresholds, in contact, for rest_hold_s.
  double rest_speed_m_s = 0.02;
  double rest_angular_speed_rad_s = 0.05;
  double rest_hold_s = 1.0;

  // False, with the field, value and violated bound in *why, when an option is out of range.
  bool IsValid(std::string* why) const;
};

}  // namespace talus
