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
    const talus::scenes::Lu2019Impact& im = talus::scenes::Lu2019Impacts()[i];
    talus::Scene scene = talus::scenes::Lu2019ImpactScene(i, slope_deg);
    talus::GroundParams& soil = scene.ground.mutable_params(scene.terrain.default_ground());
    if (!talus::ParseGroundModel(model, &soil.model)) return 2;
    scene.options.dt_s = dt_s;
    if (!talus::ParseSoilDragPoint(drag, &scene.options.soil_drag)) return 2;
    const talus::RockShape& rock = scene.rock;

    std::vector<double> depth, extent, trans, rot, duration;
    talus::SimulationWorkspace workspace;
    talus::EpisodeRecorder episodes(scene.terrain);
    for (int k = 0; k < rocks; ++k) {
      talus::RockRandom random(1, static_cast<std::uint64_t>(k));
      const talus::RockState s = talus::scenes::Lu2019ImpactStart(
          scene, i, slope_deg, 2 * std::numbers::pi * random.Uniform());
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
        i + 1, d_max, qd.q1, qd.median, qd.q3, im.paper_depth_m, im.observed_depth_m, qe.q1, qe.median,
        qe.q3, im.paper_length_m, im.observed_length_m, qt.q1, qt.median, qt.q3, qr.q1, qr.median,
        qr.q3, qu.q1, qu.median, qu.q3);
  }
  std::printf("(each: first quartile, median, third quartile over the rocks; E_rot out/in is "
              "|omega|^2 out / in)\n");
  return 0;
}
