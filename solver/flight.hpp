#pragma once
// Flight windows: runs of steps that a rock in free flight takes without contact detection
// (docs/model.md, "Flight steps"). Within a window each step is FlightStep, which gives the same
// state, bit for bit, as Step.

#include "solver/scene.hpp"
#include "solver/state.hpp"
#include "solver/step.hpp"

namespace talus {

// The number of coming steps, 0 .. max_steps, that the rock in `state` (at the beginning of a
// step) can take in free flight (gravity alone) with
// - no hull vertex at or below the terrain at a step's midpoint, and none predicted to be below it
//   at the end of the prediction horizon (so that DetectContacts would find no contact);
// - its bounding sphere, over the horizon, inside the DEM and clear of nodata cells (so that no
//   step would end the rock as left_domain);
// - its centre of mass above every drag layer (so that the drag layer would not act).
// From the bounding sphere, the body's kinetic energy of rotation (which the free rotation keeps),
// gravity, and an upper bound of the terrain's height above the tangent plane under the centre of
// mass over the box the sphere can reach (the largest at its DEM nodes). Conservative: 0 when
// unsure.
int ClearFlightSteps(const Scene& scene, const RockShape& rock, const RockState& state,
                     int max_steps);

// Advances a rock step by step: FlightStep for as long as a flight window lasts, Step otherwise.
// It looks for a window (ClearFlightSteps) at the rock's start, at the end of every window and
// after a full step whose bounding sphere cleared the terrain; after a look that found none it
// waits for 1, 2, 4, ... (at most 64) such steps before the next, so that a rock skimming the
// terrain does not pay for a look at every step. One per rock.
class FlightStepper {
 public:
  // windows = false: Step every time (the reference the windows are tested against).
  explicit FlightStepper(bool windows) : windows_(windows) {}

  StepReport Advance(const Scene& scene, const RockShape& rock, RockState& state,
                     StepWorkspace& workspace, StageTimes* times);

  long flight_steps() const { return flight_steps_; }  // steps taken as FlightStep
  // Something other than a step changed the rock's velocity (a barrier): the current window no
  // longer holds; look for a new one before the next step.
  void Restart() { left_ = wait_ = 0; }

 private:
  bool windows_;
  int left_ = 0;     // flight steps left in the current window
  int wait_ = 0;     // clear full steps to take before the next look
  int backoff_ = 1;  // the wait after the next look that finds no window
  long flight_steps_ = 0;
};

}  // namespace talus
