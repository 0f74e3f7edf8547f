#include "io/summary.hpp"

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>

#include "ensemble/run_warnings.hpp"

namespace talus::io {
namespace {

// The names of `kinds`, in their order.
std::vector<std::string> RasterNames(const std::vector<ensemble::RasterKind>& kinds) {
  std::vector<std::string> names;
  for (ensemble::RasterKind kind : kinds) names.emplace_back(ToString(kind));
  return names;
}

// Every solver option (kSolverOptions), by the names of the scene's [solver] table.
nlohmann::ordered_json SolverJson(const SolverOptions& o) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const SolverOptionInfo& f : kSolverOptions) {
    const double v = f.member.get(o);
    switch (f.type) {
      case SolverOptionInfo::Type::kNumber:
        j[f.key] = v;
        break;
      case SolverOptionInfo::Type::kInteger:
        j[f.key] = static_cast<int>(v);
        break;
      case SolverOptionInfo::Type::kChoice:
        j[f.key] = f.choices->Name(static_cast<int>(v));
        break;
    }
  }
  return j;
}

// The ground table the run used, by the keys of the scene's [ground.<name>] tables; the drag
// layer's keys only for a category that has one.
nlohmann::ordered_json GroundJson(const GroundTable& table) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (int i = 0; i < table.size(); ++i) {
    const GroundCategory& c = table.category(i);
    const GroundParams& p = c.params;
    nlohmann::ordered_json g = {{"code", c.code}};
    if (p.IsSoil()) g["model"] = ToString(p.model);
    for (const GroundFieldInfo& f : kGroundFields)
      if (GroundFieldApplies(f, p)) g[f.key] = p.*f.member;
    out[c.name] = g;
  }
  return out;
}

// One line's summary (evaluation_lines_summary.csv's numbers; NaN, no rock crossed, is null).
nlohmann::ordered_json EvaluationLineJson(const EvaluationLineSummary& s) {
  nlohmann::ordered_json j = {{"name", s.name},
                              {"length_m", s.length_m},
                              {"rocks", s.rocks},
                              {"crossed", s.crossed},
                              {"passing_probability", s.passing_probability}};
  for (const auto& [key, statistics] :
       {std::pair{"speed_m_s", &s.speed_m_s}, std::pair{"energy_J", &s.energy_J},
        std::pair{"com_height_m", &s.com_height_m},
        std::pair{"bounce_height_m", &s.bounce_height_m}}) {
    nlohmann::ordered_json q = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < CrossingStatistics::kNames.size(); ++k)
      q[CrossingStatistics::kNames[k]] = statistics->values[k];
    j[key] = q;
  }
  return j;
}

// One barrier's summary (barriers_summary.csv's numbers; NaN, no rock counted, is null).
nlohmann::ordered_json BarrierJson(const BarrierSummary& s) {
  nlohmann::ordered_json j = {{"name", s.name},
                              {"type", s.type},
                              {"length_m", s.length_m},
                              {"height_m", s.height_m},
                              {"capacity_J", s.capacity_J},
                              {"rocks", s.rocks},
                              {"reached", s.reached},
                              {"stopped", s.stopped},
                              {"overtopped", s.overtopped},
                              {"broke_through", s.broke_through},
                              {"reach_probability", s.reach_probability},
                              {"passing_probability", s.passing_probability}};
  for (const auto& [key, statistics] : {std::pair{"impact_energy_J", &s.impact_energy_J},
                                        std::pair{"passing_height_m", &s.passing_height_m},
                                        std::pair{"passing_energy_J", &s.passing_energy_J}}) {
    nlohmann::ordered_json q = nlohmann::ordered_json::object();
    for (std::size_t k = 0; k < CrossingStatistics::kNames.size(); ++k)
      q[CrossingStatistics::kNames[k]] = statistics->values[k];
    j[key] = q;
  }
  return j;
}

// The forest's breaking-energy laws: its own and, per species of [forest.species], the species'
// (the forest's filled in), each with E_max at a DBH of 30 cm.
void BreakingEnergyJson(const ForestModel& model, nlohmann::ordered_json& f) {
  f["breaking_energy"] = {{"coefficient_J", model.energy_coefficient_J},
                          {"exponent", model.energy_exponent},
                          {"law", "E_max = coefficient * DBH[cm]^exponent"}};
  nlohmann::ordered_json species = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < model.species.size(); ++k) {
    const BreakingLaw law = model.Law(static_cast<int>(k));
    species.push_back({{"name", model.species[k].name},
                       {"coefficient_J", law.coefficient_J},
                       {"exponent", law.exponent},
                       {"factor", law.factor},
                       {"e_max_30cm_J", law.Energy_J(0.30)}});
  }
  f["species"] = species;
}

}  // namespace

std::string GroundTableJson(const GroundTable& table) { return GroundJson(table).dump(); }

namespace {

// talus simulate --self-check: the subsample, both settings, the verdict and every statistic.
nlohmann::ordered_json SelfCheckJson(const ensemble::SelfCheckReport& r) {
  nlohmann::ordered_json statistics = nlohmann::ordered_json::array();
  for (const ensemble::SelfCheckStatistic& s : r.statistics)
    statistics.push_back({{"name", s.name},
                          {"unit", s.unit},
                          {"as_run", s.as_run},
                          {"refined", s.refined},
                          {"difference", s.difference},
                          {"standard_error", s.standard_error},
                          {"significant", s.significant}});
  return {{"rocks", r.rocks},
          {"dt_s", r.dt_s},
          {"refined_dt_s", r.refined_dt_s},
          {"tolerance_m_s", r.tolerance_m_s},
          {"refined_tolerance_m_s", r.refined_tolerance_m_s},
          {"threshold_standard_errors", r.threshold},
          {"converged", r.converged},
          {"verdict", r.Verdict()},
          {"statistics", statistics},
          {"wall_time_s", r.wall_time_s}};
}

}  // namespace

std::string SummaryJson(const SceneFile& scene, const ensemble::EnsembleReport& report,
                        const std::string& version, const std::vector<std::string>& outputs,
                        const std::vector<EvaluationLineSummary>& evaluation_lines,
                        const ensemble::SelfCheckReport* self_check,
                        const std::vector<BarrierSummary>& barriers, const TreeImpactSummary* trees,
                        const std::vector<ensemble::RasterLayer>& rasters) {
  nlohmann::ordered_json j;
  j["talus_version"] = version;
  j["scene"] = scene.path;
  j["inputs"] = scene.inputs;
  j["inputs_sha256"] = scene.inputs_hash;
  j["terrain"] = scene.terrain_description;
  // The coordinates of every position written (rocks.csv, evaluation lines, trajectories): the
  // DEM's CRS as WKT, null for the plane or a DEM without one.
  j["crs_wkt"] = scene.crs_wkt.empty() ? nlohmann::ordered_json(nullptr)
                                       : nlohmann::ordered_json(scene.crs_wkt);
  j["rock"] = {{"shape", scene.rock_description},
               {"mass_kg", scene.scene.rock.mass_kg},
               {"volume_m3", scene.scene.rock.volume_m3},
               {"hull_vertices", scene.scene.rock.vertices_m.size()}};
  j["seed"] = scene.release.seed;
  j["releases"] = scene.release.release_count();  // geometries, or runs of a run table
  if (!scene.release.runs.empty()) {
    j["runs"] = scene.release.runs.size();
    nlohmann::ordered_json blocks = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < scene.release.blocks.size(); ++k) {
      const ensemble::Block& b = scene.release.blocks[k];
      nlohmann::ordered_json block = {{"id", b.id},
                                      {"mass_kg", b.shape->mass_kg},
                                      {"volume_m3", b.shape->volume_m3},
                                      {"hull_vertices", b.shape->vertices_m.size()}};
      // What the shape was made from: the scan, or the built-in with its knobs.
      if (k < scene.block_specs.size()) {
        const pointclouds::RockSpec& spec = scene.block_specs[k];
        if (!spec.file.empty()) {
          block["file"] = spec.file;
        } else {
          block["shape"] = spec.builtin;
          block["size_m"] = {b.knobs.size_m.x(), b.knobs.size_m.y(), b.knobs.size_m.z()};
          if (spec.builtin == "rock") block["roughness"] = b.knobs.roughness;
        }
      }
      blocks.push_back(block);
    }
    j["blocks"] = blocks;
  }
  j["shape_per_rock"] = static_cast<bool>(scene.release.shape_per_rock);
  // Block sizes ([release] volume): the distribution each rock's volume is drawn from.
  const ensemble::VolumeDistribution& volume = scene.release.volume;
  nlohmann::ordered_json v = {{"distribution", ToString(volume.kind)}};
  using Kind = ensemble::VolumeDistribution::Kind;
  if (volume.kind == Kind::kLogNormal) {
    v["median_m3"] = volume.median_m3;
    v["sigma"] = volume.sigma;
  }
  if (volume.kind != Kind::kFixed) {
    v["min_m3"] = volume.min_m3;
    v["max_m3"] = std::isfinite(volume.max_m3) ? nlohmann::ordered_json(volume.max_m3)
                                               : nlohmann::ordered_json(nullptr);
  }
  if (volume.kind == Kind::kPowerLaw) v["exponent"] = volume.exponent;
  j["volume"] = v;
  if (scene.release.release_first_rock.empty()) {
    j["rocks_per_release"] = scene.release.rocks_per_release;
  } else {  // rocks_per_m2: each release its own number
    nlohmann::ordered_json counts = nlohmann::ordered_json::array();
    for (long r = 0; r < scene.release.release_count(); ++r)
      counts.push_back(scene.release.RocksOf(static_cast<int>(r)));
    j["rocks_per_release"] = counts;
  }
  j["rocks"] = report.rocks;
  j["ends"] = {{"rest", report.count(EndReason::kRest)},
               {"left_domain", report.count(EndReason::kLeftDomain)},
               {"max_time", report.count(EndReason::kMaxTime)},
               {"failed", report.count(EndReason::kFailed)}};
  if (!scene.scene.barriers.empty()) j["ends"]["barrier"] = report.count(EndReason::kBarrier);
  j["raised_at_release"] = report.raised;
  // Rocks that never moved further than their own length from the start (held by the ground).
  j["stayed_at_release"] = report.stayed_at_release;
  j["steps"] = report.steps;
  j["unconverged_steps"] = report.unconverged_steps;
  j["dt_s"] = scene.scene.options.dt_s;
  // What the run used, whatever the scene file left to the defaults: a run can be repeated from
  // summary.json alone (with the inputs of the same hash).
  j["solver"] = SolverJson(scene.scene.options);
  j["solver"]["preset"] = ToString(scene.solver_preset);
  j["solver"]["preset_from"] = scene.solver_preset_from_command_line ? "command line" : "scene";
  j["solver"]["preset_overrode"] = scene.solver_keys_overridden;
  j["ground"] = GroundJson(scene.scene.ground);
  // How the rasters were asked for (the statistics rasters' percentiles and the file layout).
  j["raster_output"] = {{"rasters", RasterNames(scene.output.rasters)},
                        {"percentiles", scene.output.percentiles},
                        {"format", ToString(scene.output.raster_format)}};
  // Per percentile raster, the bound on |value - exact nearest-rank percentile| / |exact|: 0, the
  // percentiles are taken exactly from every passing rock's value (ensemble/raster_spill.hpp).
  nlohmann::ordered_json bounds = nlohmann::ordered_json::object();
  for (const ensemble::RasterLayer& layer : rasters)
    if (layer.statistic.size() > 1 && layer.statistic[0] == 'p' &&
        std::isdigit(static_cast<unsigned char>(layer.statistic[1])))
      bounds[layer.name] = 0;
  j["raster_output"]["percentile_relative_error"] = bounds;
  if (!scene.evaluation_lines.empty()) {
    nlohmann::ordered_json lines = nlohmann::ordered_json::array();
    for (const EvaluationLineSummary& s : evaluation_lines) lines.push_back(EvaluationLineJson(s));
    j["evaluation_lines"] = lines;
  }
  if (!scene.scene.barriers.empty()) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const BarrierSummary& s : barriers) list.push_back(BarrierJson(s));
    j["barriers"] = list;
  }
  if (scene.has_forest) {
    const Forest& forest = scene.scene.forest;
    const ForestModel& model = forest.model();
    nlohmann::ordered_json f;
    f["model"] = "trees";
    f["trees"] = forest.stems().size();
    f["trees_file"] = scene.trees_file;
    f["trees_from_file"] = scene.trees_from_file;
    nlohmann::ordered_json stands = nlohmann::ordered_json::array();
    for (const SceneFile::ForestStand& s : scene.stands)
      stands.push_back({{"area_m2", s.area_m2},
                        {"stems_per_ha", s.stems_per_ha},
                        {"dbh_cm", s.dbh_cm},
                        {"dbh_sd_cm", s.dbh_sd_cm},
                        {"trees", s.trees},
                        {"species", s.species}});
    f["stands_file"] = scene.stands_file;
    f["stands"] = stands;
    f["seed"] = scene.forest_seed;
    f["stem_height_m"] = model.stem_height_m;
    f["friction"] = model.friction;
    BreakingEnergyJson(model, f);
    if (trees)
      f["impacts"] = {
          {"rock_stem_pairs", trees->rows},        {"impacts", trees->impacts},
          {"rocks_hitting", trees->rocks_hitting}, {"rocks_breaking", trees->rocks_breaking},
          {"breakages", trees->breakages},         {"stems_hit", trees->stems_hit},
          {"absorbed_J", trees->absorbed_J}};
    j["forest"] = f;
  }
  if (scene.forest_model == "drag") {
    const ForestModel& model = scene.forest_drag_model;
    nlohmann::ordered_json f;
    f["model"] = "drag";
    nlohmann::ordered_json stands = nlohmann::ordered_json::array();
    for (const SceneFile::ForestStand& s : scene.stands)
      stands.push_back({{"area_m2", s.area_m2},
                        {"stems_per_ha", s.stems_per_ha},
                        {"dbh_cm", s.dbh_cm},
                        {"species", s.species}});
    f["stands_file"] = scene.stands_file;
    f["stands"] = stands;
    f["stems_per_ha_raster"] = scene.forest_density_raster;
    f["dbh_raster"] = scene.forest_dbh_raster;
    f["raster_species"] = scene.forest_raster_species;
    f["dem_nodes_in_forest"] = scene.forest_drag_cells;
    f["stem_height_m"] = model.stem_height_m;
    BreakingEnergyJson(model, f);
    f["rate"] = "c = n (DBH + w) |v_h| min(E_max, 2/3 E) / (2 E) on v and Omega (docs/model.md)";
    j["forest"] = f;
  }
  if (self_check) j["self_check"] = SelfCheckJson(*self_check);
  j["threads"] = report.threads;
  j["wall_time_s"] = report.wall_time_s;
  j["trajectories_per_s"] = report.trajectories_per_s();
  j["outputs"] = outputs;
  // The scene's warnings, then what the run's endings censor (ensemble/run_warnings.hpp).
  std::vector<std::string> warnings = scene.warnings;
  for (std::string& w : ensemble::RunWarnings(report, scene.scene.options))
    warnings.push_back(std::move(w));
  j["warnings"] = warnings;
  return j.dump(2) + "\n";
}

}  // namespace talus::io
