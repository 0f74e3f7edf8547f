#pragma once
// Barriers: protection structures on the map (flexible rockfall nets, rigid walls, dams) that act
// on the rocks reaching them during the simulation (docs/model.md, "Barriers"). A rock whose centre
// of mass crosses a barrier's polyline (in plan view) within a step either overtops it (its lowest
// hull vertex is higher above the terrain than the barrier), is stopped by it (its kinetic energy
// is at most the barrier's capacity) or breaks through it with its kinetic energy reduced by the
// capacity. The plan-view crossing test and the crossing point are those of the evaluation lines
// (ensemble/evaluation_lines.hpp), which share them.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"
#include "solver/state.hpp"
#include "solver/terrain.hpp"

namespace talus {

// How the straight step a -> b (horizontal) crosses a polyline: the number of its segments the
// step crosses, and where along the step the first crossing lies.
struct StepCrossing {
  int count = 0;         // crossings within the step (0: none)
  double fraction = -1;  // of the earliest crossing along a -> b, in (0, 1]; -1 when none
};
// A step crosses a segment when the two intersect. The step is half-open at its start (a rock
// that ends a step on the line crossed it in that step, not again in the next; a start on the
// line is no crossing); segments are half-open at their end vertex (the last one closed), so a
// step through a vertex between two segments crosses once. A step parallel to a segment does not
// cross it (a grazing path).
StepCrossing CrossPolyline(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           const std::vector<Eigen::Vector2d>& polyline);

// A rock at fraction f in (0, 1] of the step s0 -> s1: time, centre of mass and velocity
// interpolated linearly, the rotational energy linearly between the step's ends, the orientation
// by slerp. Heights are vertical, above the terrain.
struct PointOnStep {
  double t_s = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // centre of mass, world
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // principal frame -> world
  double rotational_energy_J = 0;  // 1/2 w . Theta w, between the step's ends
  double ground_m = 0;             // the terrain's height under the centre of mass
  double com_height_m = 0;         // centre of mass above the terrain
  // The lowest hull vertex above the terrain under it (under the centre of mass for a vertex off
  // the DEM), >= 0: the rock's passing height (0 when touching).
  double clearance_m = 0;
};
// ground0_m, ground1_m: the terrain under the centre of mass of s0 and s1 (NaN for s0 when
// unknown); where the terrain has no height under the point (a nodata cell between the two ends)
// it is interpolated between them.
PointOnStep PointAlongStep(const Terrain& terrain, const RockShape& rock, const RockState& s0,
                           double ground0_m, const RockState& s1, double ground1_m, double f);

// The three kinds of barrier. One model acts for all three (docs/model.md, "Barriers"): the kind
// is recorded with every result.
enum class BarrierType { kFlexibleNet, kRigidWall, kDam };
const char* ToString(BarrierType type);  // "flexible_net", "rigid_wall", "dam"
// Reads a name ToString gives; false for any other.
bool ParseBarrierType(const std::string& name, BarrierType* type);

// One barrier: a polyline on the map, a height above the terrain and an energy capacity.
struct Barrier {
  std::string name;
  BarrierType type = BarrierType::kFlexibleNet;
  std::vector<Eigen::Vector2d> vertices_m;  // >= 2, map coordinates (m), non-zero length
  double height_m = 0;                      // above the terrain, vertical (m), >= 0
  double capacity_J = 0;                    // energy the barrier absorbs (J), > 0

  double length_m() const;  // horizontal length of the polyline
  // Checks the fields above; *why names the field, the value and the bound.
  bool IsValid(std::string* why) const;
};

// What a barrier did to a rock.
enum class BarrierOutcome { kOvertopped, kStopped, kBrokeThrough };
const char* ToString(BarrierOutcome outcome);  // "overtopped", "stopped", "broke_through"

// A rock at a barrier: its first crossing of the barrier's polyline (a barrier acts on a rock
// once), interpolated within the step as PointAlongStep.
struct BarrierEvent {
  int barrier = 0;  // index into Scene::barriers
  BarrierOutcome outcome = BarrierOutcome::kOvertopped;
  double t_s = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        // centre of mass at the crossing
  double speed_m_s = 0;                                        // of the centre of mass, before
  double translational_energy_J = 0, rotational_energy_J = 0;  // before the barrier acted
  double passing_height_m = 0;                                 // PointOnStep::clearance_m
  double com_height_m = 0;                                     // centre of mass above the terrain
  // Kinetic energy after the barrier acted: unchanged when overtopped, 0 when stopped,
  // energy_J() - capacity when it broke through.
  double energy_after_J = 0;
  double energy_J() const { return translational_energy_J + rotational_energy_J; }
};

// What the barriers did to a rock in one step.
struct BarrierAction {
  bool acted = false;    // a barrier changed the rock's velocity (stopped or broke through)
  bool stopped = false;  // a barrier stopped it: *state is its rest state at the crossing
};

// The barriers of `barriers` the step s0 -> *state crosses and has not met before (in `events`),
// in the order the step reaches them, each met as docs/model.md "Barriers" says. With E the
// kinetic energy at the crossing (translational + rotational, less the capacities of barriers
// broken earlier in the step) and C the capacity: overtopped when the rock's lowest point passes
// higher than the barrier; else stopped when E <= C (*state becomes the crossing point at rest:
// position, orientation and time of the crossing, no velocity); else it breaks through with
// E - C. *state, at the step's end, then keeps its position and the directions of its velocity
// and angular velocity, both scaled by sqrt((E_end - C) / E_end), E_end its kinetic energy there
// (0 when E_end <= C): the energy it would have had at the step's end had the barrier taken C at
// the crossing, exactly so when the forces in between do work independent of the speed (gravity,
// Coulomb friction). Appends one event per barrier met. ground0_m, ground1_m as PointAlongStep.
BarrierAction MeetBarriers(const std::vector<Barrier>& barriers, const Terrain& terrain,
                           const RockShape& rock, const RockState& s0, double ground0_m,
                           RockState* state, double ground1_m, std::vector<BarrierEvent>* events);

}  // namespace talus
