#pragma once
// One time step of the Moreau-type midpoint scheme (docs/model.md; Leine et al. 2014, 2021).

#include <chrono>

#include "solver/contact.hpp"
#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus {

struct StepReport {
  int contacts = 0;             // contacts closed at the midpoint or carrying load
  int iterations = 0;           // Gauss-Seidel sweeps
  bool converged = true;        // contact solve met its tolerance
  bool loaded = false;          // a contact carried load: the scar grew
  bool outside_domain = false;  // a vertex near the ground is outside the DEM or over nodata
  bool clear = false;           // no vertex needed a test (bounding sphere clear, or FlightStep)
  bool in_soil = false;         // part of the hull is in a soil layer at the midpoint (Lu 2019)
  // The step was taken as this many sub-steps (SolverOptions::impact_substeps), 1: as one.
  int substeps = 1;
  // Internal to Step: the step stopped after contact detection to be redone as sub-steps.
  bool split = false;
  double soil_penetration_m = 0;  // deepest vertex below the surface's tangent plane, soil only
  // Soil only: the rear and front (world, m) of the hull's part below the surface along the
  // horizontal velocity, at the midpoint: the scar's extent in this step.
  Eigen::Vector3d soil_rear_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d soil_front_m = Eigen::Vector3d::Zero();
};

// Wall-clock time spent in each stage, accumulated when a StageTimes is passed to Step.
struct StageTimes {
  double midpoint_s = 0, free_rotation_s = 0, contacts_s = 0, solve_s = 0, end_s = 0;
  long steps = 0;
};

// Accumulates the time since the last lap into a stage's counter; free when not profiling.
class StageClock {
 public:
  explicit StageClock(StageTimes* times) : times_(times) {
    if (times_) last_ = std::chrono::steady_clock::now();
  }
  void Lap(double StageTimes::*stage) {
    if (!times_) return;
    const auto now = std::chrono::steady_clock::now();
    times_->*stage += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  StageTimes* times_;
  std::chrono::steady_clock::time_point last_;
};

// Advances state by one step of scene.options.dt_s. When outside_domain is reported the state is
// left at the step's beginning. A step whose contact detection finds a predicted contact (a vertex
// open at the midpoint and closing before the step ends) is taken as
// SolverOptions::impact_substeps sub-steps of dt / impact_substeps instead (docs/model.md,
// "Impact sub-steps"); the report covers the whole step.
// `rock` is the shape of this rock (a scene may carry many); the overload without it uses
// scene.rock.
StepReport Step(const Scene& scene, const RockShape& rock, RockState& state,
                StepWorkspace& workspace, StageTimes* times = nullptr);
inline StepReport Step(const Scene& scene, RockState& state, StepWorkspace& workspace,
                       StageTimes* times = nullptr) {
  return Step(scene, scene.rock, state, workspace, times);
}

// The lean flight step: what Step does when no vertex touches or is predicted to touch the terrain
// and the centre of mass is above every drag layer (drift, free rotation, gravity, scar decay),
// without contact detection, bit for bit. The caller guarantees those conditions
// (ClearFlightSteps, solver/flight.hpp); reports no contacts and clear.
StepReport FlightStep(const Scene& scene, const RockShape& rock, RockState& state,
                      StepWorkspace& workspace, StageTimes* times = nullptr);

}  // namespace talus
