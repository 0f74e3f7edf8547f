#pragma once
// Running one rock from release to its end, with the statistics a hazard engineer reads.

#include <string>
#include <vector>

#include "solver/barriers.hpp"
#include "solver/contact.hpp"
#include "solver/scene.hpp"
#include "solver/state.hpp"
#include "solver/step.hpp"

namespace talus {

// kBarrier: stopped by a barrier (RockResult::barrier_events' last event says which), at rest at
// the crossing point.
enum class EndReason { kRest, kLeftDomain, kMaxTime, kFailed, kBarrier };
inline constexpr int kEndReasons = 5;
// "rest", "left_domain", "max_time", "failed", "barrier"
const char* ToString(EndReason reason);

// What happened to one rock: its ending, final state and the extremes along its path.
struct RockResult {
  EndReason end = EndReason::kMaxTime;
  std::string message;  // why it failed, for kFailed
  RockState final_state;
  double travel_time_s = 0;
  double runout_m = 0;       // horizontal distance of the centre of mass from start to end
  double path_length_m = 0;  // horizontal path of the centre of mass
  // Largest distance (3-D) of the centre of mass from its start along the path: a rock that never
  // got further than its own length (RockShape::length_m) stayed where it was released.
  double max_displacement_m = 0;
  double max_speed_m_s = 0;
  double max_kinetic_energy_j = 0;  // translational + rotational
  double max_jump_height_m = 0;     // centre of mass above ground, along the terrain normal
  double max_angular_speed_rad_s = 0;
  double max_scar_m = 0;
  long steps = 0;
  long contact_steps = 0;      // steps with at least one closed contact
  long solver_iterations = 0;  // Gauss-Seidel sweeps, summed over steps
  long unconverged_steps = 0;  // steps whose contact solve hit max_iterations
  long flight_steps = 0;       // steps taken in flight windows, without contact detection
  // The scene's barriers the rock met, in the order it met them (empty without barriers). A rock
  // that ends as kBarrier was stopped by the barrier of the last event.
  std::vector<BarrierEvent> barrier_events;
  // The scene's stems the rock touched, in the order it first hit them (empty without a forest).
  std::vector<StemHit> stem_hits;

  // True when the centre of mass never got further from its start than the rock's length.
  bool StayedAtRelease(const RockShape& rock) const { return max_displacement_m <= rock.length_m; }

  // One line: ending, time, speeds, energy.
  std::string BriefReport() const;
};

// Called after every step with the new state; recorders (trajectories, rasters) implement it.
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  // ground: what the terrain says under the centre of mass.
  virtual void OnStep(const RockState& state, const StepReport& step,
                      const TerrainSample& ground) = 0;
};

// Per-thread scratch space for SimulateRock.
struct SimulationWorkspace {
  StepWorkspace step;
  StageTimes* stage_times = nullptr;  // set to profile the step's stages
  // Lean flight steps while the rock cannot touch the terrain (solver/flight.hpp); false: contact
  // detection in every step, the reference that gives the same results bit for bit.
  bool flight_windows = true;
};

// Runs the rock of shape `rock` from `start` until rest, leaving the domain, max_time or a
// non-finite state. Requires scene.IsValid() and rock.IsValid(). Never throws for numerical
// trouble: that is reported as kFailed. The overload without a shape runs scene.rock.
RockResult SimulateRock(const Scene& scene, const RockShape& rock, const RockState& start,
                        SimulationWorkspace& workspace, StepObserver* observer = nullptr);
inline RockResult SimulateRock(const Scene& scene, const RockState& start,
                               SimulationWorkspace& workspace, StepObserver* observer = nullptr) {
  return SimulateRock(scene, scene.rock, start, workspace, observer);
}

// Kinetic energy (translational + rotational), J.
double KineticEnergy(const RockShape& rock, const RockState& state);

// Raises the rock along z until no hull vertex is below the terrain; returns the lift (m, >= 0).
// Vertices outside the DEM are ignored.
double RaiseAboveTerrain(const Scene& scene, const RockShape& rock, RockState& state);
inline double RaiseAboveTerrain(const Scene& scene, RockState& state) {
  return RaiseAboveTerrain(scene, scene.rock, state);
}

}  // namespace talus
