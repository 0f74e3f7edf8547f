#include "solver/simulate.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "solver/flight.hpp"

namespace talus {

const char* ToString(EndReason reason) {
  switch (reason) {
    case EndReason::kRest:
      return "rest";
    case EndReason::kLeftDomain:
      return "left_domain";
    case EndReason::kMaxTime:
      return "max_time";
    case EndReason::kFailed:
      return "failed";
    case EndReason::kBarrier:
      return "barrier";
  }
  return "unknown";
}

std::string RockResult::BriefReport() const {
  char line[320];
  std::snprintf(line, sizeof line,
                "end %s after %.2f s (%ld steps); path %.1f m; max speed %.2f m/s, energy %.1f kJ, "
                "jump %.2f m, spin %.2f rad/s, scar %.2f m; %.1f sweeps per contact step",
                ToString(end), travel_time_s, steps, path_length_m, max_speed_m_s,
                max_kinetic_energy_j / 1000, max_jump_height_m, max_angular_speed_rad_s, max_scar_m,
                contact_steps ? double(solver_iterations) / contact_steps : 0.0);
  return message.empty() ? std::string(line) : std::string(line) + " (" + message + ")";
}

double KineticEnergy(const RockShape& rock, const RockState& state) {
  const Eigen::Vector3d& w = state.angular_velocity_rad_s;
  return 0.5 * rock.mass_kg * state.velocity_m_s.squaredNorm() +
         0.5 * w.dot(rock.inertia_kg_m2.cwiseProduct(w));
}

namespace {
// 0 x is +-0 for a finite x and NaN for an infinite or NaN one, and a sum of +-0 is +-0: one sum
// without branches tests every component (GCC keeps the products: 0 x is not 0 for every x).
bool IsFinite(const RockState& s) {
  double zero = 0.0 * s.scar_m;
  for (int k = 0; k < 3; ++k)
    zero += 0.0 * s.position_m[k] + 0.0 * s.velocity_m_s[k] + 0.0 * s.angular_velocity_rad_s[k];
  for (int k = 0; k < 4; ++k) zero += 0.0 * s.orientation.coeffs()[k];
  return zero == 0;
}

// What every finite state after a step holds (debug builds check it): the drift renormalises the
// orientation, the scar only grows or decays towards 0, and time has moved on by one step.
[[maybe_unused]] bool IsConsistentAfterStep(const RockState& s, double previous_time_s,
                                            double dt_s) {
  return std::abs(s.orientation.squaredNorm() - 1) <= 1e-12 && s.scar_m >= 0 &&
         std::abs(s.time_s - previous_time_s - dt_s) <= 1e-9 * (1 + std::abs(s.time_s));
}
}  // namespace

RockResult SimulateRock(const Scene& scene, const RockShape& rock, const RockState& start,
                        SimulationWorkspace& workspace, StepObserver* observer) {
  const SolverOptions& opt = scene.options;
  RockResult result;
  RockState state = start;
  workspace.step.Reset(rock.vertices_m.size());
  workspace.step.scene_has_soil = scene.ground.AnySoil();
  workspace.step.scene_has_drag = scene.ground.AnyDragLayer() || !scene.forest_drag.empty();
  // The path's largest speed, angular speed and displacement are kept squared and their roots
  // taken once at the end: the square root is monotone and correctly rounded, so the root of the
  // largest square is the largest root, bit for bit.
  double max_speed2 = 0, max_angular_speed2 = 0, max_displacement2 = 0;
  auto finish = [&](EndReason end) {
    result.end = end;
    result.max_speed_m_s = std::sqrt(max_speed2);
    result.max_angular_speed_rad_s = std::sqrt(max_angular_speed2);
    result.max_displacement_m = std::sqrt(max_displacement2);
    result.final_state = state;
    result.travel_time_s = state.time_s - start.time_s;
    result.runout_m = (state.position_m - start.position_m).head<2>().norm();
    return result;
  };
  if (!IsFinite(state)) {
    result.message = "non-finite initial state";
    return finish(EndReason::kFailed);
  }
  TerrainSample ground;
  if (!scene.terrain.Sample(state.position_m.x(), state.position_m.y(), &ground))
    return finish(EndReason::kLeftDomain);

  // Statistics along the path, the release state included.
  auto record = [&](const TerrainSample& under) {
    max_speed2 = std::max(max_speed2, state.velocity_m_s.squaredNorm());
    result.max_kinetic_energy_j = std::max(result.max_kinetic_energy_j, KineticEnergy(rock, state));
    result.max_jump_height_m = std::max(result.max_jump_height_m,
                                        (state.position_m.z() - under.height_m) * under.normal.z());
    max_angular_speed2 = std::max(max_angular_speed2, state.angular_velocity_rad_s.squaredNorm());
    result.max_scar_m = std::max(result.max_scar_m, state.scar_m);
    max_displacement2 =
        std::max(max_displacement2, (state.position_m - start.position_m).squaredNorm());
  };
  record(ground);

  const double end_time = start.time_s + opt.max_time_s;
  FlightStepper stepper(workspace.flight_windows);
  // With barriers: the state and the terrain under it at the beginning of the step.
  const bool barriers = !scene.barriers.empty();
  const bool forest = !scene.forest.empty();
  RockState before;
  double before_ground_m = ground.height_m;
  while (true) {
    const Eigen::Vector3d previous = state.position_m;
    if (barriers) before = state;
    [[maybe_unused]] const double previous_time_s = state.time_s;  // for the assertion
    const StepReport step =
        stepper.Advance(scene, rock, state, workspace.step, workspace.stage_times);
    result.flight_steps = stepper.flight_steps();
    if (step.outside_domain) return finish(EndReason::kLeftDomain);
    ++result.steps;
    // A non-finite state is numerical trouble: the rock fails, the run goes on.
    if (!IsFinite(state)) {
      result.message = "state became non-finite at t = " + std::to_string(state.time_s) + " s";
      return finish(EndReason::kFailed);
    }
    assert(
        IsConsistentAfterStep(state, previous_time_s, opt.dt_s) &&
        "a step left a finite state with a non-unit quaternion, a negative scar or a wrong time");
    if (!scene.terrain.Sample(state.position_m.x(), state.position_m.y(), &ground))
      return finish(EndReason::kLeftDomain);
    // Barriers the step crossed: the rock overtops them, breaks through them with less energy or
    // is stopped by one, at the crossing point (solver/barriers.hpp).
    bool stopped = false;
    if (barriers) {
      const BarrierAction action =
          MeetBarriers(scene.barriers, scene.terrain, rock, before, before_ground_m, &state,
                       ground.height_m, &result.barrier_events);
      if (action.acted) stepper.Restart();
      stopped = action.stopped;
      if (stopped) {
        TerrainSample here;
        if (scene.terrain.Sample(state.position_m.x(), state.position_m.y(), &here)) ground = here;
      }
      before_ground_m = ground.height_m;
    }
    // Stems the rock's hull now overlaps and moves into: a plastic, frictional impact each, or
    // the stem breaks (solver/forest.hpp).
    if (forest && !stopped && MeetStems(scene.forest, rock, &state, &result.stem_hits))
      stepper.Restart();

    result.path_length_m += (state.position_m - previous).head<2>().norm();
    record(ground);
    if (step.contacts > 0) {
      ++result.contact_steps;
      result.solver_iterations += step.iterations;
      if (!step.converged) ++result.unconverged_steps;
    }
    if (observer) observer->OnStep(state, step, ground);
    if (stopped) return finish(EndReason::kBarrier);

    // Rest: slow and in contact for the hold time (speeds looked at in contact steps only).
    const bool slow = step.contacts > 0 && state.velocity_m_s.norm() <= opt.rest_speed_m_s &&
                      state.angular_velocity_rad_s.norm() <= opt.rest_angular_speed_rad_s;
    state.rest_timer_s = slow ? state.rest_timer_s + opt.dt_s : 0.0;
    if (state.rest_timer_s >= opt.rest_hold_s) return finish(EndReason::kRest);
    if (state.time_s >= end_time - 0.5 * opt.dt_s) return finish(EndReason::kMaxTime);
  }
}

double RaiseAboveTerrain(const Scene& scene, const RockShape& rock, RockState& state) {
  const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
  double lift = 0;
  for (const Eigen::Vector3d& b : rock.vertices_m) {
    const Eigen::Vector3d x = state.position_m + rotation * b;
    TerrainSample sample;
    if (!scene.terrain.Sample(x.x(), x.y(), &sample)) continue;
    lift = std::max(lift, sample.height_m - x.z());
  }
  state.position_m.z() += lift;
  return lift;
}

}  // namespace talus
