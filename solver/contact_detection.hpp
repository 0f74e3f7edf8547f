#pragma once
// Contact detection stage: which hull vertices touch the terrain at the midpoint.

#include <Eigen/Core>

#include "solver/contact.hpp"
#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus {

enum class DetectResult { kOk, kOutsideDomain };

// Fills workspace.contacts with the vertices whose gap (height above the terrain times the
// terrain normal's z) is <= 0, with their contact frame, ground index and friction mu(scar_m).
// A rock whose bounding sphere clears the terrain's local plane by more than the terrain departs
// from that plane costs one test; otherwise only the vertices within that departure of the plane
// are tested against the terrain itself.
// Returns kOutsideDomain when a vertex that may touch lies outside the DEM or over nodata.
DetectResult DetectContacts(const Scene& scene, const RockShape& rock, const RockState& mid,
                            const Eigen::Matrix3d& rotation, StepWorkspace& workspace);

}  // namespace talus
