#include "io/summary.hpp"

#include <nlohmann/json.hpp>

namespace talus::io {

std::string SummaryJson(const SceneFile& scene, const ensemble::EnsembleReport& report,
                        const std::string& version, const std::vector<std::string>& outputs) {
  nlohmann::ordered_json j;
  j["talus_version"] = version;
  j["scene"] = scene.path;
  j["inputs"] = scene.inputs;
  j["inputs_hash_fnv1a64"] = scene.inputs_hash;
  j["terrain"] = scene.terrain_description;
  j["rock"] = {{"shape", scene.rock_description},
               {"mass_kg", scene.scene.rock.mass_kg},
               {"volume_m3", scene.scene.rock.volume_m3},
               {"hull_vertices", scene.scene.rock.vertices_m.size()}};
  j["seed"] = scene.release.seed;
  j["releases"] = scene.release.release_count();  // geometries, or runs of a run table
  if (!scene.release.runs.empty()) {
    j["runs"] = scene.release.runs.size();
    nlohmann::ordered_json blocks = nlohmann::ordered_json::array();
    for (const ensemble::Block& b : scene.release.blocks)
      blocks.push_back({{"id", b.id},
                        {"mass_kg", b.shape->mass_kg},
                        {"volume_m3", b.shape->volume_m3},
                        {"hull_vertices", b.shape->vertices_m.size()}});
    j["blocks"] = blocks;
  }
  j["shape_per_rock"] = static_cast<bool>(scene.release.shape_per_rock);
  j["rocks_per_release"] = scene.release.rocks_per_release;
  j["rocks"] = report.rocks;
  j["ends"] = {{"rest", report.count(EndReason::kRest)},
               {"left_domain", report.count(EndReason::kLeftDomain)},
               {"max_time", report.count(EndReason::kMaxTime)},
               {"failed", report.count(EndReason::kFailed)}};
  j["raised_at_release"] = report.raised;
  // Rocks that never moved further than their own length from the start (held by the ground).
  j["stayed_at_release"] = report.stayed_at_release;
  j["steps"] = report.steps;
  j["unconverged_steps"] = report.unconverged_steps;
  j["dt_s"] = scene.scene.options.dt_s;
  j["threads"] = report.threads;
  j["wall_time_s"] = report.wall_time_s;
  j["trajectories_per_s"] = report.trajectories_per_s();
  j["outputs"] = outputs;
  return j.dump(2) + "\n";
}

}  // namespace talus::io
