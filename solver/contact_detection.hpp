#pragma once
// Contact detection stage: which hull vertices touch the terrain at the midpoint, or will touch it
// before the next midpoint.

#include <Eigen/Core>

#include "solver/contact.hpp"
#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus {

// kClear: the bounding sphere cleared the terrain over the horizon, no vertex was tested (no
// contacts); kOk: the vertices that may touch were tested.
enum class DetectResult { kClear, kOk, kOutsideDomain };

// How far ahead contacts are predicted, s: one step (with restitution too: a predicted contact
// that the vertex reaches within the step takes Newton's law, SolveContacts).
inline double PredictionHorizon(const SolverOptions& options) { return options.dt_s; }

// Fills workspace.contacts with the vertices in contact, with their contact frame, ground index and
// friction mu(scar_m):
// - closed: gap (height above the terrain times the terrain normal's z) <= 0 at the midpoint
//   `mid`; gap_m = 0, frame of the terrain under the vertex;
// - predicted (only when horizon_s > 0): open at the midpoint, but deeper than allowed_depth_m
//   below the terrain after moving for horizon_s with its predicted velocity (from the centre of
//   mass's world velocity and the body angular velocity given); frame of the terrain at that end
//   point, gap_m = the midpoint vertex's distance to the terrain's tangent plane there plus
//   allowed_depth_m (>= 0), so that the solver's law gap_m + horizon gamma_N,E >= 0 lets the
//   vertex sink no deeper than allowed_depth_m by the next midpoint;
// - held (SolverOptions::contact_hold, plastic law, outside soil): open at the midpoint, a contact
//   of the step before (workspace.last_closed), below the terrain after the horizon but not
//   deeper than allowed_depth_m; frame as predicted, gap_m its own distance to that plane
//   (>= 0): the vertex reaches the terrain by the next midpoint and goes no deeper.
// Under ContactHold::kHeld closed and held contacts also get lift_m, the turn's lift over the
// next drift where gravity presses the vertex harder than the turn lifts it (Contact::lift_m).
// A rock whose bounding sphere clears the terrain's local plane, over the horizon, by more than
// the terrain departs from that plane (Terrain::PlaneAround, over the box that the sphere reaches
// within the horizon) costs one test (kClear); otherwise only the vertices within that departure
// of the plane are tested against the terrain itself. On hulls of many vertices, walks over the
// hull's edges to its lowest vertices find those without looking at every vertex when few or none
// are within that departure (the same contacts, in the same order). Returns kOutsideDomain when a
// vertex that may touch lies outside the DEM or over nodata.
DetectResult DetectContacts(const Scene& scene, const RockShape& rock, const RockState& mid,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& velocity_m_s,
                            const Eigen::Vector3d& omega_rad_s, double horizon_s,
                            double allowed_depth_m, StepWorkspace& workspace);

}  // namespace talus
