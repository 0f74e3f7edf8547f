#pragma once
// One time step of the Moreau-type midpoint scheme (docs/model.md; Leine et al. 2014, 2021).

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
};

// Wall-clock time spent in each stage, accumulated when a StageTimes is passed to Step.
struct StageTimes {
  double midpoint_s = 0, free_rotation_s = 0, contacts_s = 0, solve_s = 0, end_s = 0;
  long steps = 0;
};

// Advances state by one step of scene.options.dt_s. When outside_domain is reported the state is
// left at the step's beginning.
// `rock` is the shape of this rock (a scene may carry many); the overload without it uses
// scene.rock.
StepReport Step(const Scene& scene, const RockShape& rock, RockState& state,
                StepWorkspace& workspace, StageTimes* times = nullptr);
inline StepReport Step(const Scene& scene, RockState& state, StepWorkspace& workspace,
                       StageTimes* times = nullptr) {
  return Step(scene, scene.rock, state, workspace, times);
}

}  // namespace talus
