// Single impacts: the table's errors, the release of an impact relative to a plane (in-velocity in
// closed form) and a plastic impact whose energy ratio is known in closed form.

#include "fieldobs/single_impacts.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "solver/polyhedron.hpp"
#include "solver/shapes.hpp"

namespace talus::fieldobs {
namespace {

constexpr double kPi = 3.14159265358979323846;

CsvTable Table(const std::string& text) { return CsvTable::Parse(text, "impacts.csv"); }

// The message of the InputError that reading `text` throws ("" when none).
std::string ErrorOf(const std::string& text, const SingleImpactColumns& columns = {}) {
  try {
    ReadIncomingImpacts(Table(text), columns);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SingleImpacts, ComponentsComeFromTheTotalSpeedAndAngleOrTheComponentColumns) {
  const auto from_angle =
      ReadIncomingImpacts(Table("impact_id,incoming_total_speed_mps,impact_angle_deg\na,10,30\n"
                                "b,4,90\n"),
                          {});
  ASSERT_EQ(from_angle.size(), 2u);
  EXPECT_NEAR(from_angle[0].normal_speed_m_s, 5, 1e-12);  // 10 sin 30
  EXPECT_NEAR(from_angle[0].tangent_speed_m_s, 10 * std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(from_angle[1].tangent_speed_m_s, 0, 1e-12);
  EXPECT_EQ(from_angle[1].where, "impacts.csv:3");
  // All four columns: the components, checked against the total and the angle.
  const auto both =
      ReadIncomingImpacts(Table("impact_id,incoming_normal_speed_mps,incoming_tangent_speed_mps,"
                                "incoming_total_speed_mps,impact_angle_deg\na,3,4,5,36.87\n"),
                          {});
  EXPECT_EQ(both[0].normal_speed_m_s, 3);
  EXPECT_EQ(both[0].tangent_speed_m_s, 4);
  EXPECT_EQ(both[0].angular_speed_rad_s, 0);  // no spin column: no spin
}

TEST(SingleImpacts, BadTablesAreErrorsNamingFileLineAndColumn) {
  const std::string header = "impact_id,incoming_total_speed_mps,impact_angle_deg\n";
  EXPECT_NE(ErrorOf("impact_id,mass_kg\na,780\n").find("no incoming velocity"), std::string::npos);
  EXPECT_NE(ErrorOf("impact_id,incoming_total_speed_mps\na,3\n").find("impact_angle_deg"),
            std::string::npos);
  EXPECT_NE(ErrorOf("id,incoming_total_speed_mps,impact_angle_deg\na,3,20\n").find("impact_id"),
            std::string::npos);
  EXPECT_NE(ErrorOf(header + "a,nan,20\n")
                .find("impacts.csv:2: column 'incoming_total_speed_mps': 'nan' is not a finite"),
            std::string::npos);
  EXPECT_NE(ErrorOf(header + "a,3,20\nb,3,inf\n").find("impacts.csv:3: column 'impact_angle_deg'"),
            std::string::npos);
  for (const char* angle : {"0", "-10", "95"})
    EXPECT_NE(ErrorOf(header + "a,3," + angle + "\n")
                  .find("impacts.csv:2: column 'impact_angle_deg': impact angle " +
                        std::string(angle) + " deg is outside (0, 90]"),
              std::string::npos)
        << angle;
  EXPECT_NE(ErrorOf(header + "a,-3,20\n").find("must be >= 0"), std::string::npos);
  EXPECT_NE(ErrorOf(header + "a,3,20\na,4,20\n")
                .find("impacts.csv:3: column 'impact_id': impact "
                      "'a' appears twice"),
            std::string::npos);
  EXPECT_NE(ErrorOf(header + ",3,20\n").find("empty impact id"), std::string::npos);
  EXPECT_NE(ErrorOf(header).find("no impact"), std::string::npos);
  const std::string components = "impact_id,incoming_normal_speed_mps,incoming_tangent_speed_mps";
  EXPECT_NE(ErrorOf(components + "\na,0,5\n").find("no normal component"), std::string::npos);
  EXPECT_NE(ErrorOf(components + ",incoming_total_speed_mps,impact_angle_deg\na,3,4,6,36.87\n")
                .find("impacts.csv:2: column 'incoming_total_speed_mps': 6 m/s disagrees"),
            std::string::npos);
  EXPECT_NE(ErrorOf(components + ",incoming_total_speed_mps,impact_angle_deg\na,3,4,5,40\n")
                .find("column 'impact_angle_deg': 40 deg disagrees"),
            std::string::npos);
  SingleImpactColumns spin;
  spin.angular_speed = "omega_radps";
  EXPECT_NE(ErrorOf(header + "a,3,20\n", spin).find("omega_radps"), std::string::npos);
}

TEST(SingleImpacts, OutcomesAndScarDepthsAreObservationsOfTheRun) {
  const CsvTable t =
      Table("impact_id,energy_ratio,outgoing_speed_mps,scar_depth_m\na,0.4,3,0.1\nb,,2,0.2\n");
  ObservationSet set;
  ReadSingleImpactOutcomes(t, {}, set);
  ASSERT_EQ(set.scalars.size(), 5u);  // b has no energy ratio
  EXPECT_EQ(set.scalars[0].quantity, Quantity::kImpactEnergyRatio);
  EXPECT_EQ(set.scalars[0].run, "a");
  EXPECT_EQ(set.scalars[0].value, 0.4);
  EXPECT_EQ(set.scalars[2].quantity, Quantity::kImpactSpeedOut);
  EXPECT_EQ(set.scalars[2].where, "impacts.csv:3");
  EXPECT_EQ(set.scalars[3].quantity, Quantity::kImpactScarDepth);
  EXPECT_EQ(set.scalars[3].run, "a");
  EXPECT_EQ(set.scalars[3].value, 0.1);
  EXPECT_EQ(set.scalars[4].run, "b");
  EXPECT_EQ(set.scalars[4].value, 0.2);
  ObservationSet none;
  EXPECT_THROW(ReadSingleImpactOutcomes(Table("impact_id,mass_kg\na,780\n"), {}, none), InputError);
  EXPECT_THROW(ReadSingleImpactOutcomes(Table("impact_id,energy_ratio\na,-0.1\n"), {}, none),
               InputError);
}

// A plane of `slope_deg` falling along +x (x in 0 .. 40 m, slope then 10 m of runout), a 0.4 m
// cube of 2700 kg/m^3 on `ground`.
Scene PlaneScene(double slope_deg, const GroundParams& ground) {
  Scene scene;
  scene.terrain = Terrain(MakePlaneHeightfield({slope_deg, 40, 10, 20, 1}), 0);
  scene.ground.mutable_params(0) = ground;
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.4), 2700);
  scene.options.max_time_s = 0.4;
  return scene;
}

// The first contact episode of every rock of `runs` (rocks per run), run with the scene's rock.
std::vector<ContactEpisode> FirstEpisodes(const Scene& scene,
                                          std::vector<ensemble::ReleaseRun> runs, long rocks) {
  ensemble::ReleaseSpec release;
  release.runs = std::move(runs);
  release.rocks_per_release = rocks;
  release.height_reference = ensemble::ReleaseSpec::HeightReference::kLowestPoint;
  struct Firsts : ensemble::RockSink {
    std::vector<ContactEpisode> episodes;
    void OnRock(const ensemble::RockOutcome& rock) override {
      EXPECT_EQ(rock.lift_m, 0);  // started above the plane: never raised
      if (!rock.episodes.empty()) episodes.push_back(rock.episodes.front());
    }
  } sink;
  ensemble::EnsembleOptions options;
  options.threads = 2;
  options.episodes = true;
  ensemble::RunEnsemble(scene, release, options, &sink);
  return sink.episodes;
}

TEST(SingleImpacts, ARandomlyOrientedBlockMeetsThePlaneWithTheGivenVelocity) {
  // On a 40 deg slope the release sets v = v_t d - v_n n with d downslope, n the normal; the lowest
  // vertex 1 mm above the plane meets it within the first steps, so the first episode's incoming
  // velocity is the given one plus gravity over those steps: within g dt per step (at most 1).
  const Scene scene = PlaneScene(40, GroundParams{});
  IncomingImpact impact{"a", 6.0, 15.0, 0.0, "t"};
  const double slope = 40 * kPi / 180;
  const Eigen::Vector3d n(std::sin(slope), 0, std::cos(slope));
  const Eigen::Vector3d d(std::cos(slope), 0, -std::sin(slope));
  const ensemble::ReleaseRun run = SingleImpactRun(impact, scene.terrain, {10, 0}, 0.001, -1);
  EXPECT_NEAR((run.velocity_m_s - (15.0 * d - 6.0 * n)).norm(), 0, 1e-12);
  EXPECT_NEAR((DownslopeDirection(n) - d).norm(), 0, 1e-12);
  const std::vector<ContactEpisode> episodes = FirstEpisodes(scene, {run}, 20);
  ASSERT_EQ(episodes.size(), 20u);
  const double g_dt = 9.81 * scene.options.dt_s;
  for (const ContactEpisode& e : episodes) {
    EXPECT_LE((e.velocity_in_m_s - run.velocity_m_s).norm(), g_dt + 1e-12);
    EXPECT_LE(e.start_time_s, scene.options.dt_s + 1e-12);  // contact at once
  }
}

TEST(SingleImpacts, AFrictionlessPlasticImpactLosesExactlyTheNormalComponent) {
  // epsilon_N = 0 (the model's default) removes the normal contact velocity (tests/solver/
  // step_test.cpp, Impact.PlasticDropDoesNotBounce: to the solve's stopping rule). A cube landing
  // flat on level, frictionless ground (mu = 0, nu = 0) then keeps its tangential velocity and
  // gains no rotation, as a point mass: energy ratio out / in = cos^2 of the impact angle. With
  // the solve stopped at tolerance_m_s = delta (set to 1e-7 m/s here, not the default 1e-3), a
  // residual normal velocity of about delta changes the ratio by (delta / v_in)^2, below 1e-14 at
  // v_in >= 1.4 m/s (tolerance 1e-9), and a residual corner velocity of delta spins the 0.4 m
  // cube by about delta / 0.2 m = 5e-7 rad/s (tolerance 1e-6 rad/s). Measured: exact to round-off
  // (1e-16, 1e-17 rad/s), at the default tolerance too: a flat, symmetric landing ends exact.
  GroundParams frictionless;
  frictionless.mu_min = frictionless.mu_max = 0;
  frictionless.nu_1_s = 0;
  Scene scene = PlaneScene(0, frictionless);
  scene.options.tolerance_m_s = 1e-7;
  std::vector<ensemble::ReleaseRun> runs;
  for (double angle_deg : {10.0, 30.0, 60.0}) {
    const double a = angle_deg * kPi / 180;
    IncomingImpact impact{std::to_string(angle_deg), 8 * std::sin(a), 8 * std::cos(a), 0, "t"};
    runs.push_back(SingleImpactRun(impact, scene.terrain, {10, 0}, 0.001, -1));
    runs.back().orientation = Eigen::Quaterniond::Identity();  // face down
  }
  const std::vector<ContactEpisode> episodes = FirstEpisodes(scene, runs, 1);
  ASSERT_EQ(episodes.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const double a = std::stod(runs[k].id) * kPi / 180;
    const double ratio =
        episodes[k].velocity_out_m_s.squaredNorm() / episodes[k].velocity_in_m_s.squaredNorm();
    std::printf("%s deg: energy ratio off by %.2e, spin after %.2e rad/s\n", runs[k].id.c_str(),
                ratio - std::cos(a) * std::cos(a), episodes[k].angular_velocity_out_rad_s.norm());
    EXPECT_NEAR(ratio, std::cos(a) * std::cos(a), 1e-9) << runs[k].id << " deg";
    EXPECT_LT(episodes[k].angular_velocity_out_rad_s.norm(), 1e-6);
  }
}

TEST(SingleImpacts, SpinIsAboutTheForwardRollingAxis) {
  // n x d: a positive angular speed turns the block as if it rolled down the slope (v = r w x n).
  const Scene scene = PlaneScene(30, GroundParams{});
  const ensemble::ReleaseRun run =
      SingleImpactRun({"a", 1, 2, 5, "t"}, scene.terrain, {10, 0}, 0.001, -1);
  const double slope = 30 * kPi / 180;
  const Eigen::Vector3d n(std::sin(slope), 0, std::cos(slope));
  const Eigen::Vector3d d(std::cos(slope), 0, -std::sin(slope));
  EXPECT_NEAR((run.angular_velocity_rad_s - 5 * n.cross(d)).norm(), 0, 1e-12);
  EXPECT_NEAR((run.angular_velocity_rad_s.cross(n) - 5 * d).norm(), 0, 1e-12);
  EXPECT_EQ(*run.height_m, 0.001);
  EXPECT_FALSE(run.orientation);  // random per rock
}

}  // namespace
}  // namespace talus::fieldobs
