#include "ensemble/evaluation_lines.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "ensemble/runner.hpp"
#include "fixtures.hpp"

namespace talus::ensemble {
namespace {

class Collect : public RockSink {
 public:
  void OnRock(const RockOutcome& outcome) override { rocks.push_back(outcome); }
  std::vector<RockOutcome> rocks;
};

TEST(CrossPolyline, CountsEachSegmentCrossedAndFindsTheEarliest) {
  const std::vector<Eigen::Vector2d> zigzag = {{1, -1}, {1, 1}, {2, -1}, {3, 1}};
  // Along y = 0 from x = 0 to 4: x = 1, 1.5 and 2.5, i.e. fractions 0.25, 0.375, 0.625.
  const StepCrossing c = CrossPolyline({0, 0}, {4, 0}, zigzag);
  EXPECT_EQ(c.count, 3);
  EXPECT_DOUBLE_EQ(c.fraction, 0.25);
  // The same step backwards: the earliest crossing is now x = 2.5, at 1.5 / 4.
  EXPECT_DOUBLE_EQ(CrossPolyline({4, 0}, {0, 0}, zigzag).fraction, 0.375);
  // Through the shared vertex (1, 1) of two segments: one crossing, not two.
  EXPECT_EQ(CrossPolyline({0, 1}, {2, 1}, zigzag).count, 1);
  // Parallel to a segment, short of the line, or starting on it: none.
  EXPECT_EQ(CrossPolyline({1, -2}, {1, 2}, {{1, -1}, {1, 1}}).count, 0);
  EXPECT_EQ(CrossPolyline({0, 0}, {0.9, 0}, zigzag).count, 0);
  EXPECT_EQ(CrossPolyline({1, 0}, {0, 0}, {{1, -1}, {1, 1}}).count, 0);
  // Ending on it: crossed, at fraction 1.
  EXPECT_DOUBLE_EQ(CrossPolyline({0, 0}, {1, 0}, {{1, -1}, {1, 1}}).fraction, 1.0);
}

// A spinning cube in ballistic flight over a 30 deg plane crosses a straight line and a zigzag.
// Closed form (uniform gravity, no contact): x = x0 + vx t, y = y0 + vy t,
// z = z0 + vz t - g t^2 / 2, |v|^2 = vx^2 + vy^2 + (vz - g t)^2; the cube's inertia is
// m a^2 / 6 about every axis, so w stays (0, 0, w) and E_rot = m a^2 w^2 / 12; the plane's height
// is (L - x) tan(30 deg) (terrain.hpp PlaneSpec; bilinear interpolation of a plane is exact).
// The midpoint scheme (DESIGN.md section 3) puts every step's end exactly on the parabola, so time,
// x, y and the velocity (linear in t) interpolate to round-off; z departs from the parabola by at
// most its sagitta within a step, g dt^2 / 8 = 4.9e-6 m for dt = 2 ms.
TEST(EvaluationLineRecorders, BallisticCrossingFollowsTheParabola) {
  constexpr double kSlopeDeg = 30, kLength_m = 40, kSide_m = 0.4, kG = 9.81;
  Scene scene = testing::SmallPlane(kSlopeDeg, kLength_m, 20);
  scene.options.max_time_s = 1.2;  // still in flight
  const double tan_slope = std::tan(kSlopeDeg * std::numbers::pi / 180);
  const auto plane_m = [&](double x) { return (kLength_m - x) * tan_slope; };
  const Eigen::Vector2d start(2, 0);
  const Eigen::Vector3d v0(8, 1, 3);
  const double z0 = plane_m(start.x()) + 10, spin_rad_s = 5;
  ReleaseSpec release;
  ReleaseRun run;
  run.id = "throw";
  run.xy_m = start;
  run.z_m = z0;
  run.velocity_m_s = v0;
  run.angular_velocity_rad_s = {0, 0, spin_rad_s};
  run.orientation = Eigen::Quaterniond::Identity();  // faces along the axes
  release.runs = {run};
  release.rocks_per_release = 1;

  auto lines = std::make_shared<std::vector<EvaluationLine>>();
  lines->push_back({"straight", {{6, -9}, {6, 9}}});
  // Crossed three times at x = 5, 5.5 and 6 by the path's ground track (y < 1 there).
  lines->push_back({"zigzag", {{5, -4}, {5, 4}, {5.5, -4}, {6, 4}}});
  lines->push_back({"beside", {{0, -5}, {30, -5}}});  // never crossed
  EnsembleOptions options;
  options.threads = 1;
  options.evaluation_lines = lines;
  Collect sink;
  RunEnsemble(scene, release, options, &sink);
  ASSERT_EQ(sink.rocks.size(), 1u);
  const RockOutcome& rock = sink.rocks[0];
  ASSERT_LT(rock.result.max_jump_height_m, 20.0);
  ASSERT_EQ(rock.line_crossings.size(), 2u);  // the line beside the path is absent

  const double m = scene.rock.mass_kg;
  const auto expect_parabola = [&](const LineCrossing& c, double x) {
    const double t = (x - start.x()) / v0.x();
    const double z = z0 + v0.z() * t - 0.5 * kG * t * t;
    const Eigen::Vector3d v(v0.x(), v0.y(), v0.z() - kG * t);
    EXPECT_NEAR(c.t_s, t, 1e-9);
    EXPECT_NEAR(c.position_m.x(), x, 1e-9);
    EXPECT_NEAR(c.position_m.y(), start.y() + v0.y() * t, 1e-9);
    EXPECT_NEAR(c.position_m.z(), z, kG * 0.002 * 0.002 / 8 + 1e-9);
    EXPECT_NEAR(c.speed_m_s, v.norm(), 1e-9);
    EXPECT_NEAR(c.translational_energy_J, 0.5 * m * v.squaredNorm(), 1e-9 * m * v.squaredNorm());
    // Energy conservation: speed from the drop alone.
    EXPECT_NEAR(c.speed_m_s * c.speed_m_s, v0.squaredNorm() + 2 * kG * (z0 - z), 1e-6);
    EXPECT_NEAR(c.rotational_energy_J, m * kSide_m * kSide_m * spin_rad_s * spin_rad_s / 12, 1e-9);
    EXPECT_NEAR(c.com_height_m, z - plane_m(x), 1e-5);
    // Bounce height: the cube's bottom face is level and turned by phi = w t about z; its lowest
    // corner above the slope (falling along +x) is the one furthest downhill, at
    // dx = (a / 2)(|cos phi| + |sin phi|) from the centre.
    const double phi = spin_rad_s * t;
    const double reach = 0.5 * kSide_m * (std::abs(std::cos(phi)) + std::abs(std::sin(phi)));
    EXPECT_NEAR(c.bounce_height_m, z - plane_m(x) - 0.5 * kSide_m - reach * tan_slope, 1e-5);
  };
  const LineCrossing& straight = rock.line_crossings[0];
  EXPECT_EQ(straight.line, 0);
  EXPECT_EQ(straight.crossings, 1);
  expect_parabola(straight, 6.0);
  const LineCrossing& zigzag = rock.line_crossings[1];
  EXPECT_EQ(zigzag.line, 1);
  EXPECT_EQ(zigzag.crossings, 3);
  expect_parabola(zigzag, 5.0);  // the first of the three
}

// Without lines the recorder is not there: no crossings, and the same rock otherwise.
TEST(EvaluationLineRecorders, NoLinesNoWork) {
  Scene scene = testing::SmallPlane(35, 20, 10);
  scene.options.max_time_s = 2;
  const ReleaseSpec release = testing::PointRelease({{3, 0}}, 2);
  Collect without, with;
  EnsembleOptions options;
  RunEnsemble(scene, release, options, &without);
  options.evaluation_lines = std::make_shared<std::vector<EvaluationLine>>(
      std::vector<EvaluationLine>{{"across", {{3.2, -5}, {3.2, 5}}}});
  RunEnsemble(scene, release, options, &with);
  EXPECT_EQ(with.rocks[0].line_crossings.size(), 1u);  // it slides across x = 3.2
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_TRUE(without.rocks[k].line_crossings.empty());
    EXPECT_EQ(without.rocks[k].result.final_state.position_m,
              with.rocks[k].result.final_state.position_m);
  }
}

}  // namespace
}  // namespace talus::ensemble
