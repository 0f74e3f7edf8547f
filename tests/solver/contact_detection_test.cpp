// Contact detection: rocks that move further than their own size in a step must still be stopped
// near the surface, not found once they are deep. Each test states the deepest vertex's
// penetration (model gap: height below the terrain times n_z) at rest and along the way against
// a tolerance, with the values measured before contact prediction (predicted contacts stop a
// vertex at penetration_tolerance = 1 % of the rock's thickness) and after. Every run also checks
// that no step raises the mechanical energy by more than the midpoint scheme's derived per-step
// bound, m g^2 dt^2 / 8 plus the work a solve stopped at tolerance_m_s may leave
// (tests/solver/energy_bound.hpp), to round-off.

#include "solver/contact_detection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/random.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"
#include "tests/solver/energy_bound.hpp"

namespace talus {
namespace {

constexpr double kDeg = std::numbers::pi / 180;
const GroundParams kHard{0.55, 2.0, 185, 3.0, 0.4};

// Depth of the deepest hull vertex below the terrain, m (0 when none is below).
double Penetration(const Scene& scene, const RockState& s) {
  double depth = 0;
  for (const Eigen::Vector3d& b : scene.rock.vertices_m) {
    const Eigen::Vector3d x = s.position_m + s.orientation * b;
    TerrainSample at;
    if (!scene.terrain.Sample(x.x(), x.y(), &at)) continue;
    depth = std::max(depth, (at.height_m - x.z()) * at.normal.z());
  }
  return depth;
}

// What a run left: its ending, the deepest penetration at the end and along the way, and the
// largest energy change of a step beyond its bound (relative to the release energy above the
// lowest terrain point, z = 0 here).
struct RunResult {
  EndReason end = EndReason::kMaxTime;
  double final_depth_m = 0;
  double max_depth_m = 0;
  double step_excess = 0;
};

// The largest energy change of a step beyond its plastic bound (testing::StepEnergyBound).
class Probe : public StepObserver {
 public:
  Probe(const Scene& scene, const RockState& start, const StepWorkspace& ws)
      : scene_(scene), ws_(ws) {
    e0_ = previous_ = Energy(start);
  }
  void OnStep(const RockState& state, const StepReport& step, const TerrainSample&) override {
    max_depth_m = std::max(max_depth_m, Penetration(scene_, state));
    const double e = Energy(state);
    step_excess =
        std::max(step_excess, (e - previous_ - testing::StepEnergyBound(scene_, ws_, step)) / e0_);
    previous_ = e;
  }
  double max_depth_m = 0, step_excess = -1;

 private:
  double Energy(const RockState& s) const {
    return KineticEnergy(scene_.rock, s) +
           scene_.rock.mass_kg * scene_.options.gravity_m_s2 * s.position_m.z();
  }
  const Scene& scene_;
  const StepWorkspace& ws_;
  double e0_ = 0, previous_ = 0;
};

RunResult RunRock(const Scene& scene, const RockState& start) {
  SimulationWorkspace ws;
  Probe probe(scene, start, ws.step);
  const RockResult r = SimulateRock(scene, start, ws, &probe);
  return {r.end, Penetration(scene, r.final_state), probe.max_depth_m, probe.step_excess};
}

// Flat ground 200 x 200 m, 5 m cells, hard ground, time step dt.
Scene Flat(const RockShape& rock, double dt_s) {
  Scene scene = scenes::Incline(0, rock, kHard);
  scene.options.dt_s = dt_s;
  scene.options.max_time_s = 60;
  return scene;
}

TEST(Burial, SmallCubeDroppedFrom104mRestsOnTheSurface) {
  // A 0.1 m cube falls 104 m (45 m/s at impact, 9 cm per 2 ms step) onto flat ground in six
  // random orientations, at dt = 2 ms, 10 ms and 0.1 s (the largest dt the options accept).
  // Before contact prediction, at rest: 4 of 6 at 7.4-9.0 cm (2 ms), 6 of 6 at 6.7-9.5 cm
  // (10 ms), all 2.1 m deep (0.1 s). Measured now (impact sub-steps, the default), deepest at
  // rest / along the way: 0.75 / 0.99 mm (2 ms), 0.98 / 0.99 mm (10 ms), 0.99 / 1.00 mm (0.1 s);
  // with whole steps 0.67 / 1.00, 0.98 / 0.98, 1.26 / 1.27 mm.
  // Tolerance: 2 % of the cube's size (2 mm) at rest, 5 % (5 mm) along the way.
  const double size = 0.1;
  for (double dt : {0.002, 0.01, 0.1}) {
    const Scene scene = Flat(MakeRockShape(MakeBox(size, size, size), 2700), dt);
    double worst_excess = -1;
    for (int k = 0; k < 6; ++k) {
      RockState s;
      s.orientation = RockRandom(104, k).Orientation();
      s.position_m = {100, 0, 104};
      const RunResult run = RunRock(scene, s);
      worst_excess = std::max(worst_excess, run.step_excess);
      EXPECT_EQ(run.end, EndReason::kRest) << "dt " << dt << " rock " << k;
      EXPECT_LT(run.final_depth_m, 0.02 * size) << "dt " << dt << " rock " << k;
      EXPECT_LT(run.max_depth_m, 0.05 * size) << "dt " << dt << " rock " << k;
      EXPECT_LT(run.step_excess, testing::kEnergyRoundOff) << "dt " << dt << " rock " << k;
    }
    std::printf(
        "dt %.3f s: worst energy change of a step beyond its bound %.2e (bound about %.2e)\n", dt,
        worst_excess, 9.81 * dt * dt / 8 / 104);
  }
}

// A plane of slope_deg whose face is 2 m long horizontally, above a flat runout of 20 m, 20 m
// wide, 0.5 m cells: at 88.9 degrees the face is 104 m high.
Scene Face(double slope_deg, const RockShape& rock, double dt_s) {
  PlaneSpec plane;
  plane.slope_deg = slope_deg;
  plane.slope_length_m = 2;
  plane.runout_m = 20;
  plane.width_m = 20;
  plane.cell_m = 0.5;
  Scene scene;
  const int hard = scene.ground.Set({"test", 100, kHard});
  scene.terrain = Terrain(MakePlaneHeightfield(plane), hard);
  scene.rock = rock;
  scene.options.dt_s = dt_s;
  scene.options.max_time_s = 60;
  return scene;
}

TEST(Burial, BlockDownAnAlmostVerticalFaceRestsOnTheSurface) {
  // A 0.3 x 0.25 x 0.2 m block released against an 88.9 degree face 104 m high slides and
  // tumbles down it and lands on the runout in the concave corner at about 45 m/s. Before
  // contact prediction: at 2 ms those at rest were 0.05-1.5 mm deep but vertices reached 8.2 cm
  // along the way; at 10 ms 5 of 6 rested 0.13-0.39 m deep; at 0.1 s 0.38-4.05 m. Measured now
  // (impact sub-steps), deepest at rest / along the way: 1.94 / 2.03 mm (2 ms), 1.59 / 1.96 mm
  // (10 ms; 5 of 6 at rest), 2.96 / 2.96 mm (0.1 s); with whole steps 1.51 / 1.97 mm (2 ms; 3
  // of 6 left the domain), 2.01 / 2.01 mm, 2.37 / 2.43 mm. Tolerance: 2 % of the smallest
  // dimension (4 mm) at rest, 5 % (1 cm) along the way; a block may also leave the domain.
  const double smallest = 0.2;
  for (double dt : {0.002, 0.01, 0.1}) {
    const Scene scene = Face(88.9, MakeRockShape(MakeBox(0.3, 0.25, smallest), 2700), dt);
    for (int k = 0; k < 6; ++k) {
      RockState s;
      s.orientation = RockRandom(889, k).Orientation();
      TerrainSample at;
      scene.terrain.Sample(0.3, 0, &at);
      s.position_m = {0.3, 0, at.height_m + 0.5};
      RaiseAboveTerrain(scene, s);
      const RunResult run = RunRock(scene, s);
      EXPECT_NE(run.end, EndReason::kFailed);
      if (run.end == EndReason::kRest) {
        EXPECT_LT(run.final_depth_m, 0.02 * smallest) << "dt " << dt << " rock " << k;
      }
      EXPECT_LT(run.max_depth_m, 0.05 * smallest) << "dt " << dt << " rock " << k;
      EXPECT_LT(run.step_excess, testing::kEnergyRoundOff) << "dt " << dt << " rock " << k;
    }
  }
}

TEST(Burial, FastPebbleStopsAtTheSurface) {
  // A 1 cm cube (2.7 g) hits flat ground at 50 m/s (40 down, 30 along), 10 cm per 2 ms step:
  // ten times its size. Before contact prediction 4 of 6 rested 2.7-3.1 cm deep, three times
  // its size. Measured now (impact sub-steps): at rest 0.03-0.10 mm, along the way 0.14 mm at
  // most (whole steps: 0.087-0.113 mm and 0.117 mm).
  // Tolerance 2 % of its size (0.2 mm) at rest, 5 % along the way.
  const double size = 0.01;
  const Scene scene = Flat(MakeRockShape(MakeBox(size, size, size), 2700), 0.002);
  for (int k = 0; k < 6; ++k) {
    RockState s;
    s.orientation = RockRandom(50, k).Orientation();
    s.position_m = {60, 0, 0.5};
    s.velocity_m_s = {30, 0, -40};
    const RunResult run = RunRock(scene, s);
    EXPECT_EQ(run.end, EndReason::kRest) << "rock " << k;
    EXPECT_LT(run.final_depth_m, 0.02 * size) << "rock " << k;
    EXPECT_LT(run.max_depth_m, 0.05 * size) << "rock " << k;
    EXPECT_LT(run.step_excess, testing::kEnergyRoundOff) << "rock " << k;
  }
}

TEST(Burial, ThinSlabLandingFlatStopsAtTheSurface) {
  // A 2 x 2 x 0.1 m slab (20:1) dropped 3 m flat and tilted by 0.5 and 3 degrees: 7.7 m/s at
  // impact, 1.5 cm per 2 ms step. Before contact prediction it rested 11.3-16.2 mm deep;
  // measured now: 1.00 mm (1 %) at rest and along the way, with impact sub-steps as with whole
  // steps (sub-steps without their late-arrival rule, solver/step.cpp: 4.9 mm at rest).
  // Tolerance 2 % of its thickness (2 mm) at rest, 5 % along the way.
  const double thickness = 0.1;
  const Scene scene = Flat(MakeRockShape(MakeBox(2, 2, thickness), 2700), 0.002);
  for (double tilt_deg : {0.0, 0.5, 3.0}) {
    RockState s;
    s.orientation = scene.rock.PrincipalOrientation(Eigen::Quaterniond(
        Eigen::AngleAxisd(tilt_deg * kDeg, Eigen::Vector3d(1, 2, 0).normalized())));
    s.position_m = {100, 0, 3.0};
    const RunResult run = RunRock(scene, s);
    EXPECT_EQ(run.end, EndReason::kRest) << "tilt " << tilt_deg;
    EXPECT_LT(run.final_depth_m, 0.02 * thickness) << "tilt " << tilt_deg;
    EXPECT_LT(run.max_depth_m, 0.05 * thickness) << "tilt " << tilt_deg;
    EXPECT_LT(run.step_excess, testing::kEnergyRoundOff) << "tilt " << tilt_deg;
  }
}

// The vertices the contract of DetectContacts names, found by testing every vertex against the
// terrain: closed (at or below it at the midpoint) or predicted (its end point after the horizon
// deeper than allowed_depth_m along the terrain's normal there), and with `held` (every vertex a
// contact of the step before, ContactHold::kHeld) held (its end point below the terrain, not that
// deep). In hull order.
std::vector<int> VerticesThatTouch(const Scene& scene, const RockState& mid,
                                   const Eigen::Matrix3d& rotation, const Eigen::Vector3d& v,
                                   const Eigen::Vector3d& omega, double horizon_s,
                                   double allowed_depth_m, bool held) {
  std::vector<int> touching;
  for (int k = 0; k < static_cast<int>(scene.rock.vertices_m.size()); ++k) {
    const Eigen::Vector3d& b = scene.rock.vertices_m[k];
    const Eigen::Vector3d x = mid.position_m + rotation * b;
    double h = 0;
    EXPECT_TRUE(scene.terrain.Height(x.x(), x.y(), &h));
    const Eigen::Vector3d move = horizon_s * (v + rotation * omega.cross(b));
    const Eigen::Vector3d x_end = x + move;
    TerrainSample end;
    if (x.z() <= h) {
      touching.push_back(k);
      // A second contact with the face ahead of a closed vertex (AddCornerContact).
      TerrainSample own;
      EXPECT_TRUE(scene.terrain.Sample(x.x(), x.y(), &own));
      const Eigen::Vector3d slide = x + move - std::min(0.0, own.normal.dot(move)) * own.normal;
      if (scene.terrain.Sample(slide.x(), slide.y(), &end) &&
          end.normal.dot(own.normal) < 1 - 1e-12 &&
          (slide.z() - end.height_m) * end.normal.z() < -allowed_depth_m)
        touching.push_back(k);
    } else if (scene.terrain.Sample(x_end.x(), x_end.y(), &end) &&
               (x_end.z() - end.height_m) * end.normal.z() < (held ? 0.0 : -allowed_depth_m)) {
      touching.push_back(k);
    }
  }
  return touching;
}

// A 1 x 0.8 x 0.6 m box.
RockShape TestBox() { return MakeRockShape(MakeBox(1.0, 0.8, 0.6), 2700); }

// A scene of `hf` and `rock` for the detection oracles, with held contacts if asked.
Scene DetectionScene(const Heightfield& hf, const RockShape& rock, bool held) {
  Scene scene;
  scene.terrain = Terrain(hf, 0);
  scene.rock = rock;
  if (held) scene.options.contact_hold = ContactHold::kHeld;
  return scene;
}

// A random velocity (up to speed_m_s / 2 per component) and angular velocity (up to 15 rad/s).
std::pair<Eigen::Vector3d, Eigen::Vector3d> RandomMotion(RockRandom& random, double speed_m_s) {
  const Eigen::Vector3d v =
      speed_m_s *
      Eigen::Vector3d(random.Uniform() - 0.5, random.Uniform() - 0.5, random.Uniform() - 0.5);
  const Eigen::Vector3d omega =
      30 * Eigen::Vector3d(random.Uniform() - 0.5, random.Uniform() - 0.5, random.Uniform() - 0.5);
  return {v, omega};
}

// DetectContacts on one state, checked against testing every vertex; the contacts it found.
long ExpectTheContactsOfTestingEvery(const Scene& scene, const RockState& mid,
                                     const Eigen::Vector3d& v, const Eigen::Vector3d& omega,
                                     double horizon_s, double allowed_depth_m, bool held,
                                     StepWorkspace& ws, const std::string& where) {
  const Eigen::Matrix3d rotation = mid.orientation.toRotationMatrix();
  EXPECT_NE(
      DetectContacts(scene, scene.rock, mid, rotation, v, omega, horizon_s, allowed_depth_m, ws),
      DetectResult::kOutsideDomain)
      << where;
  std::vector<int> found;
  for (const Contact& c : ws.contacts) found.push_back(c.vertex);
  EXPECT_EQ(found,
            VerticesThatTouch(scene, mid, rotation, v, omega, horizon_s, allowed_depth_m, held))
      << where;
  return static_cast<long>(found.size());
}

// Runs DetectContacts for 4000 random states of `rock` (by default a 1 x 0.8 x 0.6 m box) near the
// terrain of `hf` (centres in [lo, hi]^2 horizontally, up to `spread_m` above the terrain), fast
// (up to `speed_m_s` / 2 per component) and spinning, with a 20 ms horizon, and checks that it
// finds exactly the vertices that testing every one finds; with `held`, under ContactHold::kHeld
// with every vertex a contact of the step before. Returns the contacts found and the states without
// one.
std::pair<long, long> CheckDetection(const Heightfield& hf, double lo, double hi, bool held = false,
                                     double spread_m = 1.5, double speed_m_s = 60,
                                     const RockShape& rock = TestBox()) {
  const Scene scene = DetectionScene(hf, rock, held);
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  if (held) ws.last_closed.assign(scene.rock.vertices_m.size(), 1);
  long contacts = 0, untouched = 0;
  for (int k = 0; k < 4000; ++k) {
    RockRandom random(11, k);
    RockState mid;
    mid.orientation = random.Orientation();
    const double x = lo + (hi - lo) * random.Uniform(), y = lo + (hi - lo) * random.Uniform();
    double h = 0;
    EXPECT_TRUE(scene.terrain.Height(x, y, &h));
    mid.position_m = {x, y, h + spread_m * random.Uniform()};
    const auto [v, omega] = RandomMotion(random, speed_m_s);
    const long found = ExpectTheContactsOfTestingEvery(scene, mid, v, omega, 0.02, 0.006, held, ws,
                                                       "state " + std::to_string(k));
    contacts += found;
    untouched += found == 0;
  }
  std::printf("%ld contacts; %ld of 4000 states without one\n", contacts, untouched);
  return {contacts, untouched};
}

// Rough terrain: 5 m cells, heights varying by metres from node to node.
Heightfield RoughDem() {
  Heightfield hf;
  hf.grid = {60, 60, 0.0, 0.0, 5.0, 5.0};
  for (int j = 0; j < 60; ++j)
    for (int i = 0; i < 60; ++i)
      hf.z_m.push_back(-2.0 * i + 4 * std::sin(1.3 * i) * std::cos(0.7 * j) +
                       0.8 * ((i * 7 + j * 13) % 5));
  return hf;
}

// A plane: a 40 degree slope across 2 m cells, as the benchmark ramp.
Heightfield PlaneDem() {
  Heightfield hf;
  hf.grid = {100, 40, 0.0, 0.0, 2.0, 2.0};
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 100; ++i)
      hf.z_m.push_back(-std::tan(40 * std::numbers::pi / 180) * 2.0 * i);
  return hf;
}

TEST(Detection, SkipsOnlyVerticesThatCannotTouch) {
  // DetectContacts tests only the vertices within the terrain's departure from its local plane
  // (Terrain::PlaneAround over the box the rock reaches within the horizon). On rough terrain
  // (5 m cells, heights varying by metres from node to node), for rocks near the ground, fast (up
  // to 52 m/s) and spinning, with a 20 ms horizon (the prediction of a 20 ms step), so that
  // predicted end points leave the bounding sphere's box by up to a metre, it must find exactly
  // the vertices that testing every one finds. (With the box of the bounding sphere alone, 19 of
  // these 4000 states missed a predicted contact.)
  const auto [contacts, untouched] = CheckDetection(RoughDem(), 20, 270);
  EXPECT_GT(contacts, 1000);  // measured: 6975
  EXPECT_GT(untouched, 400);  // measured: 1575
}

TEST(Detection, SkipsOnlyVerticesThatCannotTouchOnAFineDem) {
  // The same on a fine DEM (0.1 m cells, a 30 m square: a slope with waves of metres and roughness
  // of decimetres from node to node), where the box a rock reaches spans tens of cells and
  // Terrain::PlaneAround bounds it by the blocks of its plane pyramid instead of cell by cell: the
  // same vertices as testing every one.
  Heightfield hf;
  hf.grid = {300, 300, 0.0, 0.0, 0.1, 0.1};
  for (int j = 0; j < 300; ++j)
    for (int i = 0; i < 300; ++i) {
      const double x = 0.1 * i, y = 0.1 * j;
      hf.z_m.push_back(-0.5 * x + 2 * std::sin(0.5 * x) * std::cos(0.3 * y) +
                       0.1 * ((i * 7 + j * 13) % 5));
    }
  const auto [contacts, untouched] = CheckDetection(hf, 3, 27);
  EXPECT_GT(contacts, 1000);
  EXPECT_GT(untouched, 400);
}

TEST(Detection, SkipsOnlyVerticesThatCannotTouchOnAPlane) {
  // On a plane (a 40 degree slope across 2 m cells, as the benchmark ramp) the terrain departs
  // from its local plane by rounding alone, so the plane's bound decides alone which vertices are
  // tested, and the margin between a vertex it skips and a predicted or held contact is the
  // allowed depth or nothing. States near the plane and slower (up to 26 m/s per component), so
  // that many end points fall within centimetres of it: the same vertices as testing every one,
  // with and without held contacts. (Measured on mutants of the bound: one that also skips the end
  // points down to three times the allowed depth below the plane misses 71 of the 7494 contacts
  // found here, down to 1.5 times 9 states' contacts, and one that skips the held vertices ending
  // within the allowed depth 38 of the 7540 found with held contacts; the oracles of the rough
  // DEMs above miss none of these.)
  for (const bool held : {false, true}) {
    SCOPED_TRACE(held ? "held contacts" : "midpoint");
    const auto [contacts, untouched] = CheckDetection(PlaneDem(), 10, 70, held, 1.2, 26);
    EXPECT_GT(contacts, 1000);  // measured: 7494 and 7540
    EXPECT_GT(untouched, 400);  // measured: 1088 and 1080
  }
}

TEST(Detection, SearchesHullsOfManyVerticesFromTheirLowest) {
  // On a hull of many vertices (48 or more) walks over its edges find the lowest vertices along the
  // plane's normal and along that of the end points; when none is in reach, no vertex is tested,
  // and when those in reach lie in a thin cap they are searched from there instead of looped
  // over. Ellipsoids of the box's size, of 162 and 642 vertices (the finer one with faces within a
  // few degrees of each other, where round-off decides which of two vertices is lower), on the
  // rough DEM and the plane above, with and without held contacts: the same vertices as testing
  // every one. (Measured on mutants: a search that keeps only the lowest vertices misses 104
  // contacts on the plane, and walks and a search along the plane's normal alone miss predicted
  // contacts in every case.)
  for (const int subdivisions : {2, 3}) {
    const RockShape rock = MakeRockShape(MakeEllipsoid(0.5, 0.4, 0.3, subdivisions), 2700);
    SCOPED_TRACE(std::to_string(rock.vertices_m.size()) + " vertices");
    const auto [contacts, untouched] = CheckDetection(RoughDem(), 20, 270, false, 1.5, 60, rock);
    EXPECT_GT(contacts, 1000);
    EXPECT_GT(untouched, 400);
    for (const bool held : {false, true}) {
      SCOPED_TRACE(held ? "held contacts" : "midpoint");
      const auto [on_plane, none] = CheckDetection(PlaneDem(), 10, 70, held, 1.2, 26, rock);
      EXPECT_GT(on_plane, 1000);
      EXPECT_GT(none, 400);
    }
  }
}

// Runs DetectContacts along 200 paths of 25 steps of 2 ms each (the horizon too), each a rock of
// `rock`'s shape moving at a constant velocity (up to `speed_m_s` / 2 per component) and spin, its
// centre a random height up to `spread_m` above the terrain under it, on `hf` from a start in
// [lo, hi]^2; one workspace throughout, as a thread's. Checks every step against testing every
// vertex, and returns the contacts found and the steps whose local plane was one kept from an
// earlier step (sampled elsewhere).
std::pair<long, long> CheckDetectionAlongPaths(const Heightfield& hf, double lo, double hi,
                                               bool held, double spread_m, double speed_m_s,
                                               const RockShape& rock = TestBox()) {
  const Scene scene = DetectionScene(hf, rock, held);
  const double dt_s = 0.002;
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  long contacts = 0, kept = 0;
  for (int path = 0; path < 200; ++path) {
    RockRandom random(12, path);
    RockState mid;
    mid.orientation = random.Orientation();
    double x = lo + (hi - lo) * random.Uniform(), y = lo + (hi - lo) * random.Uniform();
    const double above = spread_m * random.Uniform();
    const auto [v, omega] = RandomMotion(random, speed_m_s);
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(dt_s * omega.norm(), omega.normalized()));
    for (int step = 0; step < 25; ++step, x += dt_s * v.x(), y += dt_s * v.y()) {
      double h = 0;
      EXPECT_TRUE(scene.terrain.Height(x, y, &h));
      mid.position_m = {x, y, h + above};
      mid.orientation = (mid.orientation * turn).normalized();
      if (held) ws.last_closed.assign(scene.rock.vertices_m.size(), 1);
      contacts += ExpectTheContactsOfTestingEvery(
          scene, mid, v, omega, dt_s, 0.006, held, ws,
          "path " + std::to_string(path) + ", step " + std::to_string(step));
      kept +=
          ws.kept_plane.heights != nullptr && (ws.kept_plane.x_m != x || ws.kept_plane.y_m != y);
    }
  }
  std::printf("%ld contacts; %ld of 5000 steps on a kept plane\n", contacts, kept);
  return {contacts, kept};
}

TEST(Detection, AKeptLocalPlaneFindsTheSameContacts) {
  // A hull of few vertices keeps its local plane, taken over a box wider than the detection's by
  // four times the horizon's travel, for the next steps whose boxes lie inside it. Along paths of
  // 2 ms steps, on the rough DEM and the plane above, with and without held contacts, and towards
  // a ridge (a row of nodes 0.3 m above flat ground, 1 m cells), which a kept plane taken short of
  // it does not see: the same vertices as testing every one, with most steps on a kept plane.
  // (Measured on mutants: a kept plane taken for a box whose centre, not all of it, lies inside the
  // kept box misses contacts at the ridge; one whose height at the centre is that of the point
  // where it was sampled, with no slope, misses them on the plane.)
  const auto [contacts, kept] = CheckDetectionAlongPaths(RoughDem(), 20, 250, false, 1.0, 30);
  EXPECT_GT(contacts, 1000);
  EXPECT_GT(kept, 2500);
  Heightfield ridge;
  ridge.grid = {100, 100, 0.0, 0.0, 1.0, 1.0};
  for (int j = 0; j < 100; ++j)
    for (int i = 0; i < 100; ++i) ridge.z_m.push_back(i == 50 ? 0.3 : 0.0);
  const auto [at_ridge, kept_at_ridge] = CheckDetectionAlongPaths(ridge, 47, 53, false, 0.8, 60);
  EXPECT_GT(at_ridge, 1000);
  EXPECT_GT(kept_at_ridge, 2500);
  for (const bool held : {false, true}) {
    SCOPED_TRACE(held ? "held contacts" : "midpoint");
    const auto [on_plane, kept_on_plane] =
        CheckDetectionAlongPaths(PlaneDem(), 10, 70, held, 0.8, 26);
    EXPECT_GT(on_plane, 1000);
    EXPECT_GT(kept_on_plane, 2500);
  }
}

TEST(Detection, APlaneKeptOnOneTerrainIsNotUsedOnAnother) {
  // One workspace, two terrains, the same place: the plane kept on the first is not taken for the
  // second (its heights are another DEM's), and the second finds what testing every vertex finds.
  // (Measured on a mutant that takes it: the plane's bound on the rough DEM misses contacts.)
  const Scene on_plane = DetectionScene(PlaneDem(), TestBox(), false);
  const Scene on_rough = DetectionScene(RoughDem(), TestBox(), false);
  StepWorkspace ws;
  ws.Reset(on_rough.rock.vertices_m.size());
  const Eigen::Vector3d v(3, 1, -2), omega(2, -1, 3);
  RockState mid;
  mid.orientation = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized());
  long contacts = 0;
  for (int k = 0; k < 40; ++k) {
    const double x = 40 + 0.3 * k, y = 30;
    for (const Scene* scene : {&on_plane, &on_rough}) {
      double h = 0;
      ASSERT_TRUE(scene->terrain.Height(x, y, &h));
      mid.position_m = {x, y, h + 0.1};
      contacts += ExpectTheContactsOfTestingEvery(
          *scene, mid, v, omega, 0.002, 0.006, false, ws,
          std::string(scene == &on_rough ? "rough" : "plane") + ", point " + std::to_string(k));
      EXPECT_EQ(ws.kept_plane.heights.get(), &scene->terrain.heights());
    }
  }
  EXPECT_GT(contacts, 40);
}

TEST(Prediction, PredictedContactsNeverPushOutAndDoNoPositiveWork) {
  // A predicted contact's normal law is gap_m + dt gamma_N,E >= 0 with gap_m >= 0: its percussion
  // may slow the vertex's approach down to gap_m / dt but never makes it move away, so its work
  // on the end velocity, P_N gamma_N,E = -P_N gap_m / dt, is <= 0 (a closed contact's is 0).
  // Checked at every loaded predicted contact of the small cube's 104 m drops at dt = 10 ms, to
  // the solve's stopping rule: set here to 1e-7 m/s per sweep (not the default 1e-3 m/s, which
  // would allow 1e-3 m/s); allowance 1e-6 m/s, as a few sweeps' changes may add up.
  Scene scene = Flat(MakeRockShape(MakeBox(0.1, 0.1, 0.1), 2700), 0.01);
  scene.options.tolerance_m_s = 1e-7;
  StepWorkspace ws;
  long loaded_predicted = 0;
  for (int k = 0; k < 6; ++k) {
    RockState s;
    s.orientation = RockRandom(104, k).Orientation();
    s.position_m = {100, 0, 104};
    ws.Reset(scene.rock.vertices_m.size());
    for (int step = 0; step < 1000; ++step) {
      Step(scene, s, ws);
      for (const Contact& c : ws.contacts) {
        if (c.gap_m == 0 || c.percussion.x() <= 0) continue;
        ++loaded_predicted;
        const double gamma_end =
            c.directions.col(0).dot(s.velocity_m_s) + c.arms.col(0).dot(s.angular_velocity_rad_s);
        EXPECT_LE(gamma_end, 1e-6) << "rock " << k << " step " << step;
      }
    }
  }
  EXPECT_GT(loaded_predicted, 6);  // measured: 75
}

// The energy a rod keeps from a plastic impact on one end, in closed form: a 2 x 0.2 x 0.2 m rod,
// tilted 30 degrees with its +x end down, falling at 4 m/s and spinning at 15 rad/s about y (its
// low end sweeping down at about 15 m/s), lands on that end on flat ground with mu = 2 (sticking).
// Both end vertices touch at once; the planar impact keeps the angular momentum about the touch
// point P: omega+ = L_P / (I_y + m |S - P|^2), T+ = L_P^2 / (2 I_P). After it the rod pivots on
// its end, sticking, which does no work, so its mechanical energy stays E0 - T- + T+ until the
// other end lands (about 0.3 s later).
struct RodLanding {
  double expected_j = 0;  // mechanical energy after the impact, closed form
  double scheme_j = 0;    // the scheme's, 20 ms after the touch
  double release_j = 0;   // mechanical energy at release (z = 0 on the ground)
};

RodLanding LandRod(double dt_s, PredictedLever lever, double phase) {
  const GroundParams stick{2.0, 2.0, 185, 0.0, 0.0};
  Scene scene = Flat(MakeRockShape(MakeBox(2, 0.2, 0.2), 2700), dt_s);
  scene = scenes::Incline(0, scene.rock, stick);
  scene.options.dt_s = dt_s;
  scene.options.predicted_lever = lever;
  const RockShape& rock = scene.rock;
  const double m = rock.mass_kg, g = scene.options.gravity_m_s2;
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  const Eigen::Quaterniond q0 =
      rock.PrincipalOrientation(Eigen::Quaterniond(Eigen::AngleAxisd(30 * kDeg, y)));
  const double omega = 15;
  const double i_y = (q0.toRotationMatrix().transpose() * y).cwiseAbs().dot(rock.inertia_kg_m2);
  const Eigen::Vector3d v0(0, 0, -4);
  TerrainSample ground;
  scene.terrain.Sample(100, 0, &ground);
  // Exact flight: parabola and steady rotation about the principal axis y (so is the scheme's).
  auto centre = [&](double t) -> Eigen::Vector3d {
    return Eigen::Vector3d(100, 0, 2) + t * v0 - 0.5 * g * t * t * Eigen::Vector3d::UnitZ();
  };
  auto rotation = [&](double t) { return Eigen::Matrix3d(Eigen::AngleAxisd(omega * t, y) * q0); };
  // Height of the lowest vertices above the ground and their mean position (the two end vertices
  // are at the same height).
  auto lowest = [&](double t, Eigen::Vector3d* point) {
    double low = 1e9;
    for (const Eigen::Vector3d& b : rock.vertices_m) low = std::min(low, (rotation(t) * b).z());
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (const Eigen::Vector3d& b : rock.vertices_m) {
      const Eigen::Vector3d arm = rotation(t) * b;
      if (arm.z() > low + 1e-9) continue;
      sum += centre(t) + arm;
      ++count;
    }
    *point = sum / count;
    return point->z() - ground.height_m;
  };
  // Touch time by bisection, then the start shifted so that it falls at `phase` within a step.
  double lo = 0, hi = 2;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < 100; ++k) (lowest(0.5 * (lo + hi), &p) > 0 ? lo : hi) = 0.5 * (lo + hi);
  const double touch = hi;
  lowest(touch, &p);
  const double start = touch - (std::floor(touch / dt_s) + phase) * dt_s + dt_s;
  RockState s;
  s.position_m = centre(start);
  s.orientation = Eigen::Quaterniond(rotation(start));
  s.velocity_m_s = v0 - g * start * Eigen::Vector3d::UnitZ();
  s.angular_velocity_rad_s = s.orientation.conjugate() * (omega * y);
  auto energy = [&](const RockState& r) {
    return KineticEnergy(rock, r) + m * g * (r.position_m.z() - ground.height_m);
  };
  RodLanding out;
  out.release_j = energy(s);
  // Closed form at the touch.
  const Eigen::Vector3d arm = centre(touch) - p;
  const Eigen::Vector3d v_in = v0 - g * touch * Eigen::Vector3d::UnitZ();
  const double l_p = i_y * omega + m * arm.cross(v_in).y();
  const double i_p = i_y + m * (arm.x() * arm.x() + arm.z() * arm.z());
  const double t_in = 0.5 * m * v_in.squaredNorm() + 0.5 * i_y * omega * omega;
  out.expected_j = out.release_j - t_in + 0.5 * l_p * l_p / i_p;
  // Sticking: the impact's percussion lies in the friction cone.
  const Eigen::Vector3d v_out = (l_p / i_p) * y.cross(arm);
  const Eigen::Vector3d percussion = m * (v_out - v_in);
  EXPECT_LT(std::abs(percussion.x()), stick.mu_min * percussion.z());
  StepWorkspace ws;
  ws.Reset(rock.vertices_m.size());
  while (s.time_s < touch - start + 0.02) Step(scene, s, ws);
  out.scheme_j = energy(s);
  return out;
}

TEST(Prediction, TouchLeverIsWhereTheVertexTouches) {
  // A 1 m cube spinning at 60 rad/s about a tilted axis falls at 10 m/s onto flat ground; a step
  // of 4 ms turns it by 0.24 rad. For each predicted contact of its first contact step, the
  // vertex's arm when it touches (exact flight: parabola and, for a cube, steady rotation;
  // touch time by bisection) is compared with the lever the contact uses. With the midpoint
  // lever the arm is off by up to omega s |b| (s: time to touch, up to one step); with the touch
  // lever only by the error of s taken from the vertex's linear path (its arc turns by up to
  // 0.24 rad). Measured: largest distance 0.157 m (midpoint) and 0.026 m (touch). Tolerance:
  // touch below a quarter of midpoint's.
  const double dt = 0.004;
  Scene scene = Flat(MakeRockShape(MakeBox(1, 1, 1), 2700), dt);
  scene.options.impact_substeps = 1;  // the lever of a whole step's predicted contact
  const RockShape& rock = scene.rock;
  const double g = scene.options.gravity_m_s2;
  const Eigen::Vector3d omega_world = 60 * Eigen::Vector3d(0.3, 1, 0.2).normalized();
  const Eigen::Vector3d v0(3, 0, -10);
  RockState s;
  s.orientation = RockRandom(60, 1).Orientation();
  s.position_m = {100, 0, 1.6};
  s.velocity_m_s = v0;
  s.angular_velocity_rad_s = s.orientation.conjugate() * omega_world;
  TerrainSample ground;
  scene.terrain.Sample(100, 0, &ground);
  double farthest[2] = {0, 0};
  for (PredictedLever lever : {PredictedLever::kMidpoint, PredictedLever::kTouch}) {
    scene.options.predicted_lever = lever;
    RockState state = s;
    StepWorkspace ws;
    ws.Reset(rock.vertices_m.size());
    while (ws.contacts.empty()) Step(scene, state, ws);
    // Midpoint of that step on the exact flight from s.
    const double t_mid = state.time_s - 0.5 * dt;
    const Eigen::Quaterniond q_mid = Eigen::Quaterniond(Eigen::AngleAxisd(
                                         omega_world.norm() * t_mid, omega_world.normalized())) *
                                     s.orientation;
    for (const Contact& c : ws.contacts) {
      if (c.gap_m == 0) continue;
      const Eigen::Vector3d& b = rock.vertices_m[c.vertex];
      auto arm_at = [&](double t) -> Eigen::Vector3d {
        return Eigen::AngleAxisd(omega_world.norm() * t, omega_world.normalized()) *
               (s.orientation * b);
      };
      auto height = [&](double t) {
        return s.position_m.z() + v0.z() * t - 0.5 * g * t * t + arm_at(t).z() - ground.height_m;
      };
      double lo = t_mid, hi = t_mid + dt;
      if (height(hi) > 0) continue;  // does not touch within the horizon on the exact flight
      for (int k = 0; k < 60; ++k) (height(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
      const Eigen::Vector3d lever_world = q_mid * c.lever_m;
      farthest[lever == PredictedLever::kTouch] =
          std::max(farthest[lever == PredictedLever::kTouch], (lever_world - arm_at(hi)).norm());
    }
  }
  EXPECT_GT(farthest[0], 0.1);
  EXPECT_LT(farthest[1], 0.25 * farthest[0]);
}

TEST(Prediction, RodLandingOnOneEndKeepsTheClosedFormEnergy) {
  // The touch falls at five phases of a step, so that the end vertices are closed at a midpoint
  // (found late) or predicted 0.2-0.8 steps before they touch. Measured, largest error of the
  // energy after the impact relative to the energy the impact takes (12.3 kJ of 14.1 kJ), with
  // either lever: 3e-4 at 0.5 ms, 1.2e-3 at 2 ms, 2.3e-3 at 4 ms. Tolerance: 1e-3 per ms of dt.
  for (PredictedLever lever : {PredictedLever::kMidpoint, PredictedLever::kTouch}) {
    for (double dt : {0.0005, 0.002, 0.004}) {
      for (double phase : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const RodLanding r = LandRod(dt, lever, phase);
        EXPECT_NEAR(r.scheme_j, r.expected_j, 1.0 * dt * (r.release_j - r.expected_j))
            << ToString(lever) << " dt " << dt << " phase " << phase;
      }
    }
  }
}

}  // namespace
}  // namespace talus
