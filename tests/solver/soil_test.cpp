// The scarring soil of Lu et al. 2019 (solver/soil.hpp, GroundModel::kLu2019): the submerged part's
// geometry, eq. 11, and the motion through the layer against closed-form solutions.

#include "solver/soil.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/episodes.hpp"
#include "solver/kinematics.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"
#include "solver/step.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81;

// The paper's whole-trajectory soil (Lu et al. 2019: M_E 15 MN/m^2, C_s 1.5, C_f 1, rho 1700) under
// the friction of its rebound plane (mu_min 0.55, mu_max 2, beta 185, kappa 3), no nu.
GroundParams PaperSoil() {
  GroundParams p{0.55, 2.0, 185, 3.0, 0.0};
  p.model = GroundModel::kLu2019;
  return p;
}

TEST(ClipBelowPlane, HalfACubeHasTheClosedFormVolumeCentroidAndFrontalAreas) {
  // A 1 x 1 x 1 m cube, the plane through its centre: the part below is a 1 x 1 x 0.5 box with
  // centroid 0.25 m below the centre; its projections are 0.5 m^2 along x and y, 1 m^2 along z,
  // and (0.5 |u_x| + 1 |u_z|) m^2 along a unit u in the x-z plane. Exact geometry: 1e-12.
  const RockShape cube = MakeRockShape(MakeBox(1, 1, 1), 2700);
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  SubmergedPart part;
  ClipBelowPlane(cube, identity, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), &part);
  EXPECT_NEAR(part.volume_m3, 0.5, 1e-12);
  EXPECT_NEAR((part.centroid_m - Eigen::Vector3d(0, 0, -0.25)).norm(), 0, 1e-12);
  EXPECT_NEAR(part.depth_m, 0.5, 1e-12);
  EXPECT_NEAR(part.FrontalArea(Eigen::Vector3d::UnitX()), 0.5, 1e-12);
  EXPECT_NEAR(part.FrontalArea(-Eigen::Vector3d::UnitY()), 0.5, 1e-12);
  EXPECT_NEAR(part.FrontalArea(-Eigen::Vector3d::UnitZ()), 1.0, 1e-12);
  const Eigen::Vector3d u = Eigen::Vector3d(0.6, 0, -0.8);
  EXPECT_NEAR(part.FrontalArea(u), 0.5 * 0.6 + 0.8, 1e-12);

  // Turned 45 deg about z, the plane 0.3 m below the centre: a 0.2 m slab of the cube, volume 0.2,
  // centroid 0.4 m below; seen along x, the slab's diagonal (sqrt 2 m) times 0.2 m.
  const Eigen::Matrix3d turned =
      Eigen::AngleAxisd(std::numbers::pi / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  ClipBelowPlane(cube, turned, Eigen::Vector3d(0, 0, -0.3), Eigen::Vector3d::UnitZ(), &part);
  EXPECT_NEAR(part.volume_m3, 0.2, 1e-12);
  EXPECT_NEAR((part.centroid_m - Eigen::Vector3d(0, 0, -0.4)).norm(), 0, 1e-12);
  EXPECT_NEAR(part.depth_m, 0.2, 1e-12);
  EXPECT_NEAR(part.FrontalArea(Eigen::Vector3d::UnitX()), std::sqrt(2.0) * 0.2, 1e-12);

  // A tilted plane: x + y + z = -1.5 + t cuts the corner (-0.5, -0.5, -0.5) off as a right
  // tetrahedron of legs t, volume t^3 / 6, centroid at the corner plus t/4 on each axis.
  const double t = 0.3;
  const Eigen::Vector3d n = Eigen::Vector3d::Ones().normalized();
  const Eigen::Vector3d on_plane(-0.5 + t, -0.5, -0.5);
  ClipBelowPlane(cube, identity, on_plane, n, &part);
  EXPECT_NEAR(part.volume_m3, t * t * t / 6, 1e-12);
  EXPECT_NEAR((part.centroid_m - Eigen::Vector3d::Constant(-0.5 + t / 4)).norm(), 0, 1e-12);
  // Seen along x: the tetrahedron's face in the x = -0.5 plane, a right triangle of legs t.
  EXPECT_NEAR(part.FrontalArea(Eigen::Vector3d::UnitX()), t * t / 2, 1e-12);

  // Nothing below: empty; everything below: the whole cube.
  ClipBelowPlane(cube, identity, Eigen::Vector3d(0, 0, -0.6), Eigen::Vector3d::UnitZ(), &part);
  EXPECT_TRUE(part.empty());
  EXPECT_EQ(part.FrontalArea(Eigen::Vector3d::UnitX()), 0);
  ClipBelowPlane(cube, identity, Eigen::Vector3d(0, 0, 0.6), Eigen::Vector3d::UnitZ(), &part);
  EXPECT_NEAR(part.volume_m3, 1.0, 1e-12);
  EXPECT_NEAR(part.FrontalArea(Eigen::Vector3d::UnitY()), 1.0, 1e-12);
}

TEST(PenetrationDepth, Eq11OfLu2019) {
  // d_max = 0.1 M^(1/3) M_E^(-0.4) |V_perp|^0.8 with M_E in kN/m^2 (Lu et al. 2019, eq. 11). The
  // paper's check: 780 kg, 15 MN/m^2, 11 m/s give about 0.13 m; to rounding, 0.133878 m
  // (0.1 * 780^(1/3) * 15000^(-0.4) * 11^0.8, evaluated independently to six digits).
  GroundParams soil = PaperSoil();
  EXPECT_NEAR(soil.PenetrationDepth(780, 11), 0.13, 0.005);
  EXPECT_NEAR(soil.PenetrationDepth(780, -11), 0.133878, 5e-7);
  // Scaling: M^(1/3), M_E^(-0.4), V^0.8, exactly.
  EXPECT_NEAR(soil.PenetrationDepth(8 * 780, 11) / soil.PenetrationDepth(780, 11), 2, 1e-12);
  soil.soil_strength_mn_m2 = 15 * 32;
  EXPECT_NEAR(soil.PenetrationDepth(780, 11), 0.133878 / 4, 5e-7);
  EXPECT_EQ(soil.PenetrationDepth(780, 0), 0);
}

// A 1 x 1 x 0.5 m box lying flat just above flat soil, falling at v0 (m/s) straight down.
struct Drop {
  Scene scene;
  RockState state;
};
Drop FlatDrop(double v0, double dt_s) {
  Drop d;
  d.scene = scenes::Incline(0, MakeRockShape(MakeBox(1, 1, 0.5), 2700), PaperSoil());
  d.scene.options.dt_s = dt_s;
  d.scene.options.tolerance_m_s = 1e-12;
  d.state.orientation = d.scene.rock.PrincipalOrientation(Eigen::Quaterniond::Identity());
  d.state.position_m = {100, 0, 0.25 + 1e-9};
  d.state.velocity_m_s = {0, 0, -v0};
  return d;
}

TEST(SoilDrop, SpeedInTheLayerFollowsTheQuadraticDragAndStopsOnTheReboundPlane) {
  // A flat-lying box moving straight down has frontal area A = 1 m^2 as soon as it is in the layer,
  // so m dv/dt = m g - k v^2 with k = (C_f + C_s) rho A / 2 = 2125 kg/m, and with z the depth of
  // its lower face (eq. 9 integrated; eq. 8 is its g = 0 limit):
  //   v(z)^2 = v_t^2 + (v0^2 - v_t^2) exp(-2 k z / m),  v_t^2 = m g / k.
  // On the rebound plane, at the d_max that eq. 11 gives for the speed it entered with, the plastic
  // contact stops it: it rests there, the plane never passed by more than the contact prediction's
  // allowance (1 % of the thickness, 5 mm). The drag is implicit in v with |v| from the step's
  // beginning: measured relative error of v(z) 2.1e-5 at dt 2 ms and 5.3e-8 at dt 0.1 ms;
  // tolerances 1e-4 and 1e-6.
  for (const double dt : {0.002, 0.0001}) {
    const double v0 = 10;
    Drop drop = FlatDrop(v0, dt);
    const Scene& scene = drop.scene;
    const double m = scene.rock.mass_kg, k = 0.5 * 2.5 * 1700 * 1.0;
    StepWorkspace ws;
    ws.Reset(scene.rock.vertices_m.size());
    RockState s = drop.state;
    double depth_max = 0, worst = 0, d_max = 0;
    int checked = 0;
    for (int step = 0; step < static_cast<int>(1.0 / dt); ++step) {
      const double v_begin = -s.velocity_m_s.z();
      const StepReport r = Step(scene, s, ws);
      if (step == 0) {
        ASSERT_GE(s.soil_ground, 0);
        d_max = s.soil_depth_m;
        // eq. 11 with the predicted vertical speed at entry, v0 + g dt.
        EXPECT_NEAR(d_max, scene.ground.params(s.soil_ground).PenetrationDepth(m, v0 + kG * dt),
                    1e-15);
      }
      const double depth = 0.25 - s.position_m.z();
      depth_max = std::max(depth_max, depth);
      if (r.contacts == 0 && depth > 0 && v_begin > 0) {
        const double vt2 = m * kG / k;
        const double expected = std::sqrt(vt2 + (v0 * v0 - vt2) * std::exp(-2 * k * depth / m));
        worst = std::max(worst, std::abs(-s.velocity_m_s.z() - expected) / expected);
        ++checked;
      }
    }
    std::printf("dt %.4f s: d_max %.4f m, deepest %.4f m, worst relative speed error %.2e over %d "
                "steps\n",
                dt, d_max, depth_max, worst, checked);
    EXPECT_NEAR(d_max, 0.1 * std::cbrt(m) * std::pow(15000.0, -0.4) * std::pow(v0, 0.8), 0.01);
    EXPECT_GE(checked, dt < 0.001 ? 100 : 5);
    EXPECT_LT(worst, dt < 0.001 ? 1e-6 : 1e-4);
    EXPECT_LE(depth_max, d_max + 0.01 * 0.5 + 1e-9);
    EXPECT_GE(depth_max, d_max - 1e-9);
    EXPECT_LT(s.velocity_m_s.norm(), 1e-6);
    EXPECT_GE(s.soil_ground, 0);  // still in the layer, resting on its plane
  }
}

TEST(SoilDrop, HardGroundStopsAtTheSurface) {
  // The same drop on the seed's hard ground: the plastic contact stops the box at the surface, no
  // soil state. The prediction lets a vertex sink 5 mm (1 % of the thickness) by the midpoint after
  // the step it closes in; the end point lies another half step further: measured 10 mm at
  // 10 m/s (a step is 20 mm); bound 10 mm.
  Drop drop = FlatDrop(10, 0.002);
  drop.scene.ground.mutable_params(drop.scene.terrain.default_ground()).model = GroundModel::kHard;
  StepWorkspace ws;
  ws.Reset(drop.scene.rock.vertices_m.size());
  RockState s = drop.state;
  double depth_max = 0;
  for (int step = 0; step < 200; ++step) {
    Step(drop.scene, s, ws);
    depth_max = std::max(depth_max, 0.25 - s.position_m.z());
    EXPECT_EQ(s.soil_ground, -1);
  }
  EXPECT_LE(depth_max, 0.01 + 1e-9);
  EXPECT_LT(s.velocity_m_s.norm(), 1e-6);
}

TEST(SoilDrag, AtTheSubmergedCentroidItTurnsTheRockAtTheCentreOfMassItDoesNot) {
  // No gravity; the flat box with its lower face 0.1 m deep in the layer (rebound plane at 0.2 m),
  // moving at v = (5, 0, -2) m/s. The drag (eq. 9) is k A zeta'^2 against v, zeta' = 2 m/s the
  // rate of penetration, A the projection of the 1 x 1 m slab below the surface (depth z at the
  // midpoint, 0.102 m) normal to v: (5 z + 2) / sqrt(29) m^2. At the centre of mass it exerts no
  // torque, and the implicit step gives v_E = v_B / (1 + dt k A zeta'^2 / (m |v|)) exactly. At the
  // centroid of the slab (below the centre of mass) it pitches the front down: a positive angular
  // velocity about y. Both only slow the box. Without penetration rate (v = (5, 0, 0)) there is no
  // drag: the rock slides through the layer as on the rebound plane.
  for (const SoilDragPoint point : {SoilDragPoint::kCentreOfMass, SoilDragPoint::kSubmergedCentroid}) {
    for (const double rate : {2.0, 0.0}) {
      Drop drop = FlatDrop(0, 0.002);
      Scene& scene = drop.scene;
      scene.options.gravity_m_s2 = 0;
      scene.options.soil_drag = point;
      RockState s = drop.state;
      s.position_m.z() = 0.25 - 0.1;
      s.soil_ground = scene.terrain.default_ground();
      s.soil_depth_m = 0.2;
      s.velocity_m_s = {5, 0, -rate};
      StepWorkspace ws;
      ws.Reset(scene.rock.vertices_m.size());
      const double energy = KineticEnergy(scene.rock, s);
      const StepReport r = Step(scene, s, ws);
      EXPECT_TRUE(r.in_soil);
      const double depth = 0.1 + 0.001 * rate;  // at the midpoint
      EXPECT_NEAR(r.soil_penetration_m, depth, 1e-12);
      const Eigen::Vector3d omega_world = s.orientation * s.angular_velocity_rad_s;
      if (rate == 0) {
        EXPECT_EQ(s.velocity_m_s, Eigen::Vector3d(5, 0, 0));
        EXPECT_EQ(omega_world.norm(), 0);
        continue;
      }
      EXPECT_LT(KineticEnergy(scene.rock, s), energy);
      if (point == SoilDragPoint::kCentreOfMass) {
        EXPECT_EQ(omega_world.norm(), 0);
        const double speed = std::sqrt(29.0), m = scene.rock.mass_kg;
        const double area = (5 * depth + 2) / speed;
        const double k = 0.5 * 2.5 * 1700 * area;
        const Eigen::Vector3d expected =
            Eigen::Vector3d(5, 0, -2) / (1 + 0.002 * k * rate * rate / (m * speed));
        EXPECT_NEAR((s.velocity_m_s - expected).norm(), 0, 1e-12);
      } else {
        EXPECT_GT(omega_world.y(), 0);
        EXPECT_NEAR(omega_world.x(), 0, 1e-12);
        EXPECT_NEAR(omega_world.z(), 0, 1e-12);
      }
    }
  }
}

// Mechanical energy of `rocks` EOTA221 blocks released on the 40 deg ramp (seed `seed`), `steps`
// steps each: its largest climb above its running minimum, relative to the release energy. Counts
// the steps with part of a hull in a soil layer.
double WorstEnergyRise(const Scene& scene, int rocks, int steps, std::uint64_t seed,
                       long* soil_steps) {
  const double m = scene.rock.mass_kg, g = scene.options.gravity_m_s2;
  StepWorkspace ws;
  double worst = 0;
  for (int rock = 0; rock < rocks; ++rock) {
    RockState s = scenes::Ramp40Release(scene, seed, rock);
    ws.Reset(scene.rock.vertices_m.size());
    const double e0 = KineticEnergy(scene.rock, s) + m * g * s.position_m.z();
    double running_min = e0;
    for (int k = 0; k < steps; ++k) {
      const StepReport r = Step(scene, s, ws);
      if (r.outside_domain) break;
      *soil_steps += r.in_soil;
      const double e = KineticEnergy(scene.rock, s) + m * g * s.position_m.z();
      EXPECT_TRUE(std::isfinite(e));
      running_min = std::min(running_min, e);
      worst = std::max(worst, (e - running_min) / e0);
    }
  }
  return worst;
}

TEST(SoilEnergy, TheLayerNeverAddsEnergyBeyondTheSchemesOwnDrift) {
  // The scar drag only takes energy (implicit, P . v_E <= 0), and the rebound plane moving between
  // episodes only lets a rock sink further (potential energy into kinetic, no gain). Bound as for
  // the hard contact with contact friction (step_test.cpp, Energy.*): 1e-5 of the release energy,
  // the midpoint scheme's own order-dt^2 drift.
  for (const SoilDragPoint point : {SoilDragPoint::kCentreOfMass, SoilDragPoint::kSubmergedCentroid}) {
    Scene scene = scenes::Ramp40();
    for (int i = 0; i < scene.ground.size(); ++i) {
      GroundParams& p = scene.ground.mutable_params(i);
      p.model = GroundModel::kLu2019;
    }
    scene.options.soil_drag = point;
    long soil_steps = 0;
    const double worst = WorstEnergyRise(scene, 10, 5000, 11, &soil_steps);
    std::printf("%s: worst energy rise %.2e of the release energy, %ld steps in the soil\n",
                ToString(point), worst, soil_steps);
    EXPECT_GT(soil_steps, 5000);
    EXPECT_LT(worst, 1e-5);
  }
}

}  // namespace
}  // namespace talus

namespace talus {
namespace {

TEST(Lu2019Table2, ImpactsScarToTheReboundPlaneAndLastTensOfMilliseconds) {
  // The four single impacts of Lu et al. 2019 (Table 2) with their Table 3 soils, on a 25 deg plane
  // (the impact points' slope is not published), eight angles about the spin axis each. The scar
  // depth is the deepest penetration normal to the surface: on the rebound plane, d_max (eq. 11,
  // vertical) times cos 25 deg, to 2 mm above and twice the contact prediction's allowance (1 % of
  // the 0.47 m thickness, met at the next midpoint, not at every vertex's deepest) below (measured
  // medians 0.105, 0.124, 0.140, 0.121 m: up to 4.9 mm below the plane). The paper's simulated
  // depths are 0.14-0.18 m: eq. 11 with the centre of mass's vertical speed gives 0.111-0.150 m,
  // and the paper does not say how it measured depth; ours are within 35 % of its. Its simulated
  // scar lengths are 1.26-1.80 m: our scar extents' medians 1.30-1.75 m, asserted within a factor
  // 1.8. The seed's hard contact ends such an impact in 5-8 ms (measured with
  // talus_bench_lu2019_impacts --model hard); on the soil it lasts 90-121 ms (measured medians),
  // asserted above 40 ms (the field: about 0.2 s).
  const double slope_deg = 25;
  for (int i = 0; i < 4; ++i) {
    Scene scene = scenes::Lu2019ImpactScene(i, slope_deg);
    const scenes::Lu2019Impact& impact = scenes::Lu2019Impacts()[i];
    const double d_max =
        scene.ground.params(scene.terrain.default_ground()).PenetrationDepth(780, impact.vz);
    std::vector<double> depth, extent, duration;
    SimulationWorkspace workspace;
    EpisodeRecorder episodes(scene.terrain);
    for (int k = 0; k < 8; ++k) {
      const RockState start =
          scenes::Lu2019ImpactStart(scene, i, slope_deg, 2 * std::numbers::pi * k / 8);
      episodes.Begin(start);
      SimulateRock(scene, start, workspace, &episodes);
      const std::vector<ContactEpisode> list = episodes.Finish();
      ASSERT_FALSE(list.empty());
      depth.push_back(list.front().max_scar_depth_m);
      extent.push_back(list.front().scar_extent_m);
      duration.push_back(list.front().duration_s());
    }
    for (auto* v : {&depth, &extent, &duration}) std::sort(v->begin(), v->end());
    const double median_depth = 0.5 * (depth[3] + depth[4]);
    const double median_extent = 0.5 * (extent[3] + extent[4]);
    const double median_duration = 0.5 * (duration[3] + duration[4]);
    std::printf("impact %d: d_max %.3f m, scar depth %.3f m (paper %.2f), extent %.2f m (paper "
                "%.2f), duration %.3f s\n",
                i + 1, d_max, median_depth, impact.paper_depth_m, median_extent,
                impact.paper_length_m, median_duration);
    const double normal = d_max * std::cos(slope_deg * std::numbers::pi / 180);
    EXPECT_GT(median_depth, normal - 0.002);
    EXPECT_LT(median_depth, normal + 2 * 0.01 * 0.47);
    EXPECT_NEAR(median_depth, impact.paper_depth_m, 0.35 * impact.paper_depth_m);
    EXPECT_GT(median_extent, impact.paper_length_m / 1.8);
    EXPECT_LT(median_extent, impact.paper_length_m * 1.8);
    EXPECT_GT(median_duration, 0.04);
  }
}

}  // namespace
}  // namespace talus

namespace talus {
namespace {

TEST(SoilEnergy, NoAcceptedGroundParametersAddEnergy) {
  // Every combination of ground parameters the scene accepts at the ends of their bounds (mu 0 and
  // 10, nu 0 and 1e4 1/s, kappa 0 and 1e4 1/m, beta 0 and 1e5 1/s, M_E 0.1 and 1000 MN/m^2, C_s 0
  // and 100), hard and soil, both readings of nu: three EOTA221 blocks tumbling 2 s down the 40 deg
  // ramp never rise above their running minimum of mechanical energy by more than the scheme's own
  // drift (1e-5 of the release energy, as Energy.* in step_test.cpp); nu = 1e160, accepted before
  // the bounds, launched rocks at 2943 m/s.
  double worst = 0;
  long runs = 0;
  for (const double mu : {0.0, 10.0})
    for (const double nu : {0.0, 1e4})
      for (const double kappa : {0.0, 1e4})
        for (const double beta : {0.0, 1e5})
          for (const GroundModel model : {GroundModel::kHard, GroundModel::kLu2019})
            for (const ViscousReading reading :
                 {ViscousReading::kContactFriction, ViscousReading::kCentreOfMass}) {
              Scene scene = scenes::Ramp40();
              GroundParams& p = scene.ground.mutable_params(scene.terrain.default_ground());
              p = GroundParams{mu, mu, beta, kappa, nu};
              p.model = model;
              p.soil_strength_mn_m2 = mu == 0 ? 0.1 : 1000;
              p.compaction_drag = kappa == 0 ? 0 : 100;
              std::string why;
              ASSERT_TRUE(p.IsValid(&why)) << why;
              scene.options.viscous = reading;
              long soil_steps = 0;
              worst = std::max(worst, WorstEnergyRise(scene, 3, 1000, 5, &soil_steps));
              runs += 3;
            }
  std::printf("%ld runs: worst energy rise %.2e of the release energy\n", runs, worst);
  EXPECT_LT(worst, 1e-5);
}

}  // namespace
}  // namespace talus
