// Rolling on a plane: how far a block that rolls keeps rolling. The EOTA111 block of cases/tirol
// (1 m^3, 2700 kg, the standard's bevelled 1.122 m cube) starts on a plane of each slope rolling
// about a face axis at --omega rad/s (its centre at the matching speed), on the seed's hard contact
// or on the scarring soil (Lu et al. 2019, the paper's M_E 15 MN/m^2 and C_s 1.5), with Coulomb
// friction --mu and the viscous term --nu under either reading (none by default). Prints per slope
// whether it came to rest (SimulateRock's rule: speed below 0.02 m/s and angular speed below
// 0.05 rad/s, in contact, for 1 s) and when, or how it ended, the distance travelled and the speeds
// at the end of --seconds. A polygonal prism rolling with plastic impacts is McGeer's rimless wheel
// (tests/solver/rolling_test.cpp checks the solver against its closed form); this shows where that
// wheel stops for the block real runs use.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"

int main(int argc, char** argv) {
  using namespace talus;
  CLI::App app{"How far a rolling EOTA111 block keeps rolling on a plane"};
  std::vector<double> slopes{2, 3, 4, 6, 9, 12, 15};
  double mu = 0.6, omega = 3.0, seconds = 120, dt_s = 0.002;
  double nu = 0;
  std::string model = "hard", viscous = "contact_friction";
  app.add_option("--slopes", slopes, "Slopes of the plane, degrees")->check(CLI::Range(0.0, 45.0));
  app.add_option("--mu", mu, "Coulomb friction coefficient")->check(CLI::Range(0.0, 5.0));
  app.add_option("--omega", omega, "Start angular speed, rad/s")->check(CLI::Range(0.0, 50.0));
  app.add_option("--seconds", seconds, "Simulated time, s")->check(CLI::PositiveNumber);
  app.add_option("--dt", dt_s, "Time step, s")->check(CLI::PositiveNumber);
  app.add_option("--model", model, "hard | lu2019")->check(CLI::IsMember({"hard", "lu2019"}));
  app.add_option("--nu", nu, "Viscous ground term, 1/s")->check(CLI::Range(0.0, 100.0));
  app.add_option("--viscous", viscous, "contact_friction | centre_of_mass");
  CLI11_PARSE(app, argc, argv);
  ViscousReading reading;
  if (!ParseViscousReading(viscous, &reading)) {
    std::fprintf(stderr, "--viscous: '%s': expected contact_friction or centre_of_mass\n",
                 viscous.c_str());
    return 2;
  }

  const double a = 1.122;
  const RockShape rock =
      MakeRockShape(MakeBevelledBox(a, a, a, BevelForVolume(a, a, a, 1.0)), 2700);
  std::printf(
      "EOTA111 %.0f kg, mu %.2f, nu %.2f 1/s (%s), %s ground, start %.2f rad/s, dt %.4f s, "
      "%.0f s\n",
      rock.mass_kg, mu, nu, viscous.c_str(), model.c_str(), omega, dt_s, seconds);
  std::printf("slope_deg  rest_at_s  distance_m  end_speed_m_s  end_omega_rad_s\n");
  for (double slope : slopes) {
    GroundParams ground{mu, mu, 150, 2.0, nu};
    if (model == "lu2019") ground.model = GroundModel::kLu2019;
    Scene scene = scenes::Incline(slope, rock, ground, 4000, 5);
    scene.options.dt_s = dt_s;
    scene.options.viscous = reading;
    RockState s;
    s.orientation = rock.PrincipalOrientation(Eigen::Quaterniond::Identity());
    TerrainSample plane;
    scene.terrain.Sample(50, 0, &plane);
    s.position_m = {50, 0, plane.height_m + a / 2 + 1e-3};
    s.angular_velocity_rad_s = s.orientation.inverse() * Eigen::Vector3d(0, omega, 0);
    s.velocity_m_s = {omega * a / 2, 0, 0};
    scene.options.max_time_s = seconds;
    SimulationWorkspace workspace;
    const RockResult result = SimulateRock(scene, rock, s, workspace);
    const RockState& last = result.final_state;
    const bool rest = result.end == EndReason::kRest;
    std::printf(
        "%9.1f  %9s  %10.1f  %13.2f  %15.2f\n", slope,
        rest ? std::to_string(result.travel_time_s).substr(0, 6).c_str() : ToString(result.end),
        (last.position_m - s.position_m).norm(), last.velocity_m_s.norm(),
        last.angular_velocity_rad_s.norm());
  }
  return 0;
}
