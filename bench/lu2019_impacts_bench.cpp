// The four single impacts of Lu et al. 2019 (Table 2) with their fitted soils (Table 3), on the
// scarring soil (GroundModel::kLu2019): the EOTA221 block (780 kg) meets a plane with the measured
// velocity, spinning at the measured rate about its major principal axis (the axis of its largest
// moment, set along n x d so that it rolls forward), at a uniformly random angle about that axis.
// Prints, per impact, eq. 11's d_max and the medians and quartiles over the rocks of the first
// contact episode's scar depth, scar extent, translational and rotational energy ratios and
// duration, beside the paper's simulated and observed values (lu2019_model.md restates them).
// The slope of the impact points is not published: it is an option (--slope-deg), and the
// plane's downslope direction is the horizontal direction of the incoming velocity.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/episodes.hpp"
#include "solver/random.hpp"
#include "solver/simulate.hpp"

namespace {

struct Impact {
  double vx, vy, vz, omega;         // Table 2: m/s, rad/s
  double observed_depth, observed_length;
  double soil_strength, compaction_drag;  // Table 3: MN/m^2, 1
  double paper_depth, paper_length;       // Table 3: simulated, m
};
constexpr Impact kImpacts[] = {
    {5.56, -14.62, -11.20, 23.85, 0.13, 1.40, 25, 4.0, 0.14, 1.80},
    {5.30, -12.70, -10.74, 26.30, 0.15, 1.80, 15, 1.5, 0.16, 1.64},
    {5.34, -12.31, -10.36, 29.33, 0.18, 1.55, 10, 0.1, 0.18, 1.26},
    {5.34, -14.19, -8.52, 28.69, 0.21, 1.52, 10, 0.5, 0.18, 1.77},
};

struct Quartiles {
  double q1 = NAN, median = NAN, q3 = NAN;
};
Quartiles Of(std::vector<double> v) {
  Quartiles q;
  if (v.empty()) return q;
  std::sort(v.begin(), v.end());
  auto at = [&](double p) {  // type 7
    const double h = p * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  q.q1 = at(0.25);
  q.median = at(0.5);
  q.q3 = at(0.75);
  return q;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lu et al. 2019, Table 2 impacts on the scarring soil"};
  int rocks = 50;
  double slope_deg = 25, dt_s = 0.002;
  std::string drag = "centre_of_mass";
  std::string model = "lu2019";
  app.add_option("--rocks", rocks, "Rocks (angles about the spin axis) per impact")
      ->check(CLI::PositiveNumber);
  app.add_option("--slope-deg", slope_deg, "Slope of the plane at the impact, degrees")
      ->check(CLI::Range(0.0, 34.0));
  app.add_option("--dt", dt_s, "Time step, s")->check(CLI::PositiveNumber);
  app.add_option("--soil-drag", drag, "centre_of_mass | submerged_centroid");
  app.add_option("--model", model, "lu2019 | hard (the seed's contact at the surface)");
  CLI11_PARSE(app, argc, argv);

  std::printf("Lu et al. 2019 Table 2 impacts: %d rocks each, slope %.1f deg, dt %.4f s, model %s, "
              "soil drag at %s\n",
              rocks, slope_deg, dt_s, model.c_str(), drag.c_str());
  std::printf("%-3s %6s | %-17s %5s %5s | %-17s %5s %5s | %-17s | %-17s | %-17s\n", "", "d_max",
              "scar depth (m)", "paper", "obs", "scar extent (m)", "paper", "obs",
              "E_trans out/in", "E_rot out/in", "duration (s)");
  for (int i = 0; i < 4; ++i) {
    const Impact& im = kImpacts[i];
    talus::GroundParams soil{0.55, 2.0, 185, 3.0, 0.0};  // the paper's rebound plane, no nu
    talus::GroundModel ground_model;
    if (!talus::ParseGroundModel(model, &ground_model)) return 2;
    soil.model = ground_model;
    soil.soil_strength_mn_m2 = im.soil_strength;
    soil.compaction_drag = im.compaction_drag;
    talus::Scene scene = talus::scenes::Incline(slope_deg, talus::scenes::Eota221(), soil, 60, 0.5);
    scene.options.dt_s = dt_s;
    scene.options.max_time_s = 1.0;
    if (!talus::ParseSoilDragPoint(drag, &scene.options.soil_drag)) return 2;
    const talus::RockShape& rock = scene.rock;
    const double theta = slope_deg * std::numbers::pi / 180;
    const Eigen::Vector3d n(std::sin(theta), 0, std::cos(theta));  // the plane falls along +x
    const Eigen::Vector3d d(std::cos(theta), 0, -std::sin(theta));
    const Eigen::Vector3d axis = n.cross(d);  // rolling forward
    const Eigen::Vector3d velocity(std::hypot(im.vx, im.vy), 0, im.vz);

    std::vector<double> depth, extent, trans, rot, duration;
    talus::SimulationWorkspace workspace;
    talus::EpisodeRecorder episodes(scene.terrain);
    for (int k = 0; k < rocks; ++k) {
      talus::RockRandom random(1, static_cast<std::uint64_t>(k));
      const double angle = 2 * std::numbers::pi * random.Uniform();
      talus::RockState s;
      s.orientation = Eigen::AngleAxisd(angle, axis) *
                      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis);
      s.velocity_m_s = velocity;
      s.angular_velocity_rad_s = s.orientation.conjugate() * (im.omega * axis);
      // The lowest vertex 1 mm above the plane at x = 20 m.
      talus::TerrainSample ground;
      scene.terrain.Sample(20, 0, &ground);
      double lowest = 1e9;
      for (const Eigen::Vector3d& b : rock.vertices_m) lowest = std::min(lowest, n.dot(s.orientation * b));
      s.position_m = Eigen::Vector3d(20, 0, ground.height_m) + (0.001 - lowest) * n;
      episodes.Begin(s);
      talus::SimulateRock(scene, s, workspace, &episodes);
      const std::vector<talus::ContactEpisode> list = episodes.Finish();
      if (list.empty()) continue;
      const talus::ContactEpisode& e = list.front();
      depth.push_back(e.max_scar_depth_m);
      extent.push_back(e.scar_extent_m);
      trans.push_back(e.velocity_out_m_s.squaredNorm() / e.velocity_in_m_s.squaredNorm());
      const double in = e.angular_velocity_in_rad_s.squaredNorm();
      rot.push_back(in > 0 ? e.angular_velocity_out_rad_s.squaredNorm() / in : NAN);
      duration.push_back(e.duration_s());
    }
    const double d_max = soil.PenetrationDepth(rock.mass_kg, im.vz);
    const Quartiles qd = Of(depth), qe = Of(extent), qt = Of(trans), qr = Of(rot), qu = Of(duration);
    std::printf(
        "%-3d %6.3f | %5.3f %5.3f %5.3f %5.2f %5.2f | %5.2f %5.2f %5.2f %5.2f %5.2f | %5.2f %5.2f "
        "%5.2f | %5.2f %5.2f %5.2f | %5.3f %5.3f %5.3f\n",
        i + 1, d_max, qd.q1, qd.median, qd.q3, im.paper_depth, im.observed_depth, qe.q1, qe.median,
        qe.q3, im.paper_length, im.observed_length, qt.q1, qt.median, qt.q3, qr.q1, qr.median,
        qr.q3, qu.q1, qu.median, qu.q3);
  }
  std::printf("(each: first quartile, median, third quartile over the rocks; E_rot out/in is "
              "|omega|^2 out / in)\n");
  return 0;
}
