#include "solver/flight.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "solver/contact_detection.hpp"

namespace talus {
namespace {

// Rounding allowance on every clearance and on the box, m: the scheme's positions depart from the
// closed form below by at most a unit in the last place per half step (6e-11 m at 4e5 m map
// coordinates, 2e-9 m at 1e7 m), under 1e-5 m over the longest window.
constexpr double kMargin_m = 1e-4;
// The longest window, s and steps; the most DEM nodes a box may hold; the most boxes a look scans.
constexpr double kLongestWindow_s = 1.0;
constexpr int kMostSteps = 2000;
constexpr double kMostNodes = 4096;
constexpr int kLooks = 3;

// A rock in free flight seen against a reference plane z = z_0 + s_x (x - x_0) + s_y (y - y_0):
// heights are vertical heights above it, rates are along m = (-s_x, -s_y, 1).
struct Approach {
  double height_m;  // centre of mass at the start
  double rate_m_s;  // its rate at the start, m . v
  double sphere_m;  // depth of the bounding sphere's lowest point below the centre: |m| rho
  double spin_m_s;  // fastest rate of a vertex relative to the centre: |m| rho omega_max
};

struct Flight {
  double dt_s, gravity_m_s2, horizon_s;
  double drag_m;  // the highest drag layer (0 without one)
};

// Lowest height above the plane, over the first k steps, of a vertex at a step's midpoint or at
// its predicted end point, and of the centre of mass less the highest drag layer. The scheme's
// positions at step ends lie on the parabola through the start and its midpoints g dt^2/8 above
// it; the parabola is concave, so its least value over [0, k dt] is at an end. The predicted end
// points move at the last step's end velocity, the slowest, for the horizon.
double Lowest(const Approach& a, const Flight& f, int k) {
  const double t = k * f.dt_s;
  const double centre =
      std::min(a.height_m, a.height_m + t * (a.rate_m_s - 0.5 * f.gravity_m_s2 * t));
  const double slowest_rate = a.rate_m_s - f.gravity_m_s2 * t - a.spin_m_s;
  return std::min(centre - a.sphere_m + f.horizon_s * std::min(0.0, slowest_rate),
                  centre - f.drag_m);
}

// Largest k in 0 .. k_max whose Lowest is above bound_m (Lowest falls with k).
int LongestClear(const Approach& a, const Flight& f, double bound_m, int k_max) {
  int lo = 0, hi = k_max;
  while (lo < hi) {
    const int mid = lo + (hi - lo + 1) / 2;
    if (Lowest(a, f, mid) > bound_m + kMargin_m)
      lo = mid;
    else
      hi = mid - 1;
  }
  return lo;
}

// Bound of the angular speed under the free rotation, which keeps the kinetic energy
// omega . Theta omega / 2: |omega|^2 <= omega . Theta omega / Theta_min; 0.1 % above it for the
// tolerance of the rotation's Newton solve.
double MaxAngularSpeed(const RockShape& rock, const RockState& state) {
  const Eigen::Vector3d& w = state.angular_velocity_rad_s;
  return 1.001 *
         std::sqrt(w.dot(rock.inertia_kg_m2.cwiseProduct(w)) / rock.inertia_kg_m2.minCoeff());
}

// The highest drag layer of the ground categories and the forest's.
double HighestDragLayer(const Scene& scene) {
  const GroundTable& ground = scene.ground;
  double highest = scene.forest_drag.empty() ? 0.0 : scene.forest_drag.height_m();
  for (int g = 0; g < ground.size(); ++g)
    if (ground.params(g).HasDragLayer())
      highest = std::max(highest, ground.params(g).drag_height_m);
  return highest;
}

// Longest time, s, that the interval [p - reach, p + reach] moving at v stays within [lo, hi];
// negative when it starts outside.
double TimeWithin(double p, double v, double reach, double lo, double hi) {
  if (!(p - reach >= lo && p + reach <= hi)) return -1;
  if (v > 0) return (hi - reach - p) / v;
  if (v < 0) return (lo + reach - p) / v;
  return std::numeric_limits<double>::infinity();
}

// The box of horizontal positions that the centre of mass's path over time t reaches, widened by
// reach.
Terrain::Box BoxReached(const RockState& state, double reach, double t) {
  const Eigen::Vector3d& p = state.position_m;
  const Eigen::Vector3d end = p + t * state.velocity_m_s;
  return {std::min(p.x(), end.x()) - reach, std::max(p.x(), end.x()) + reach,
          std::min(p.y(), end.y()) - reach, std::max(p.y(), end.y()) + reach};
}

double NodesIn(const Terrain::Box& box, const GridGeometry& grid) {
  return ((box.x_hi_m - box.x_lo_m) / grid.dx_m + 2) * ((box.y_hi_m - box.y_lo_m) / grid.dy_m + 2);
}

}  // namespace

int ClearFlightSteps(const Scene& scene, const RockShape& rock, const RockState& state,
                     int max_steps) {
  const SolverOptions& opt = scene.options;
  const Terrain& terrain = scene.terrain;
  const GridGeometry& grid = terrain.heights().grid;
  const Eigen::Vector3d& p = state.position_m;
  const Eigen::Vector3d& v = state.velocity_m_s;
  TerrainSample under;
  if (max_steps <= 0 || !terrain.Sample(p.x(), p.y(), &under)) return 0;
  const Flight flight{opt.dt_s, opt.gravity_m_s2, PredictionHorizon(opt), HighestDragLayer(scene)};
  const double rho = rock.bounding_radius_m;
  const double spin = rho * MaxAngularSpeed(rock, state);
  // Vertices stay within rho of the centre, and predicted end points within reach of it.
  const double reach = rho + flight.horizon_s * spin + kMargin_m;

  // Steps for which the box stays inside the DEM.
  const double time_inside = std::min(TimeWithin(p.x(), v.x(), reach, grid.x0_m, grid.x_max_m()),
                                      TimeWithin(p.y(), v.y(), reach, grid.y0_m, grid.y_max_m())) -
                             flight.horizon_s;
  if (!(time_inside >= 0)) return 0;
  int k = time_inside >= max_steps * flight.dt_s ? max_steps
                                                 : static_cast<int>(time_inside / flight.dt_s);

  // Heights against the tangent plane under the centre of mass: the window if the terrain were
  // nowhere above that plane, then the terrain's height above it over the box that window reaches.
  const Eigen::Vector3d& n = under.normal;
  const Terrain::Plane tangent{p.x(), p.y(), under.height_m, -n.x() / n.z(), -n.y() / n.z()};
  const Eigen::Vector3d m(-tangent.slope_x, -tangent.slope_y, 1.0);
  const Approach approach{p.z() - under.height_m, m.dot(v), m.norm() * rho, m.norm() * spin};
  int guess = LongestClear(approach, flight, 0.0, k);
  auto box = [&](int steps) {
    return BoxReached(state, reach, steps * flight.dt_s + flight.horizon_s);
  };
  while (guess > 0 && NodesIn(box(guess), grid) > kMostNodes) guess /= 2;
  // A smaller box bounds the terrain closer (and may stay clear of nodata): when a box allows
  // less than half the steps it was drawn for, look again over the box of max(allowed + 1, a
  // quarter), at most kLooks times.
  int clear = 0;
  for (int look = 0; look < kLooks && guess > clear; ++look) {
    double above_m = 0;
    if (terrain.MaxAbovePlane(box(guess), tangent, &above_m))
      clear = std::max(clear, LongestClear(approach, flight, above_m, guess));
    if (2 * clear >= guess) break;
    guess = std::max(clear + 1, guess / 4);
  }
  return clear;
}

StepReport FlightStepper::Advance(const Scene& scene, const RockShape& rock, RockState& state,
                                  StepWorkspace& workspace, StageTimes* times) {
  if (windows_ && left_ == 0 && wait_ == 0) {
    StageClock clock(times);
    const int longest =
        std::clamp(static_cast<int>(kLongestWindow_s / scene.options.dt_s), 1, kMostSteps);
    left_ = ClearFlightSteps(scene, rock, state, longest);
    clock.Lap(&StageTimes::contacts_s);
    if (left_ > 0) {
      backoff_ = 1;
    } else {
      wait_ = backoff_;
      backoff_ = std::min(2 * backoff_, 64);
    }
  }
  if (left_ > 0) {
    --left_;
    ++flight_steps_;
    return FlightStep(scene, rock, state, workspace, times);
  }
  const StepReport report = Step(scene, rock, state, workspace, times);
  if (!report.clear) {
    wait_ = 1;  // look after the next step that clears the terrain
    backoff_ = 1;
  } else if (wait_ > 0) {
    --wait_;
  }
  return report;
}

}  // namespace talus
