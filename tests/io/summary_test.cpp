#include "io/summary.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/sha256.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

TEST(SummaryJson, CarriesHashVersionCountsAndRate) {
  const auto dir = testing::FreshDir("summary");
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] "
                     "}\n[release]\npoints = [[10, 0]]\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  ensemble::EnsembleReport report;
  report.rocks = 10;
  report.by_end = {7, 2, 1, 0};
  report.raised = 3;
  report.stayed_at_release = 4;
  report.wall_time_s = 2.0;
  const auto j = nlohmann::json::parse(SummaryJson(scene, report, "9.9.9", {"rocks.csv"}));
  EXPECT_EQ(j["talus_version"], "9.9.9");
  EXPECT_EQ(j["inputs_sha256"], scene.inputs_hash);
  EXPECT_EQ(j["ends"]["rest"], 7);
  EXPECT_EQ(j["ends"]["left_domain"], 2);
  EXPECT_EQ(j["ends"]["max_time"], 1);
  EXPECT_EQ(j["raised_at_release"], 3);
  EXPECT_EQ(j["stayed_at_release"], 4);
  // The options and ground table actually used, defaults included.
  EXPECT_EQ(j["solver"]["viscous"], "contact_friction");
  EXPECT_DOUBLE_EQ(j["solver"]["dt_s"].get<double>(), 0.002);
  EXPECT_DOUBLE_EQ(j["solver"]["tolerance_m_s"].get<double>(), 1e-3);
  EXPECT_EQ(j["solver"]["preset"], "default");
  EXPECT_EQ(j["raster_output"]["percentiles"], nlohmann::json::array({95}));
  EXPECT_EQ(j["raster_output"]["format"], "gtiff");
  // No rasters given: no bounds. Each percentile layer by name with its bound, 0: exact; the
  // other layers have none.
  EXPECT_TRUE(j["raster_output"]["percentile_relative_error"].empty());
  const ensemble::RasterLayer p95{"energy_p95", "J", {}, "energy", "p95"};
  const ensemble::RasterLayer max{"energy_max", "J", {}, "energy", "max"};
  const ensemble::RasterLayer passages{"passages", "count", {}, "passages", "count"};
  const auto with = nlohmann::json::parse(SummaryJson(scene, report, "9.9.9", {"rocks.csv"}, {},
                                                      nullptr, {}, nullptr, {max, p95, passages}));
  EXPECT_EQ(with["raster_output"]["percentile_relative_error"],
            nlohmann::json::parse(R"({"energy_p95": 0})"));
  EXPECT_EQ(j["raster_output"]["rasters"], nlohmann::json::array());
  EXPECT_EQ(j["ground"].size(), 8u);  // Table 1
  EXPECT_EQ(j["ground"]["medium"]["code"], 4);
  EXPECT_DOUBLE_EQ(j["ground"]["medium"]["mu_min"].get<double>(), 0.35);
  EXPECT_DOUBLE_EQ(j["ground"]["snow"]["mu_max"].get<double>(), 0.35);
  EXPECT_FALSE(j["ground"]["medium"].contains("drag_height_m"));  // no layer
  EXPECT_DOUBLE_EQ(j["trajectories_per_s"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 2.0);
  EXPECT_TRUE(j["crs_wkt"].is_null());  // the plane has no CRS
}

// "forest": the species of [forest.species] with their laws (the forest's coefficient and exponent
// filled in) and E_max at 30 cm; each stand's species ("" without).
TEST(SummaryJson, ForestListsTheSpeciesLawsAndEachStandsSpecies) {
  const auto dir = testing::FreshDir("summary_forest");
  testing::WriteText(
      dir / "scene.toml",
      "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\npoints = [[10, "
      "0]]\n[forest]\nstands = [{ polygon = [[20, -5], [30, -5], [30, 5]], stems_per_ha = 400, "
      "dbh_cm = 30, species = \"beech\" }, { polygon = [[20, -5], [30, 5], [20, 5]], "
      "stems_per_ha = 400, dbh_cm = 30 }]\n[forest.species.beech]\nenergy_factor = 1.6\n"
      "[forest.species.larch]\nenergy_coefficient_j = 60\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  const auto j =
      nlohmann::json::parse(SummaryJson(scene, ensemble::EnsembleReport{}, "9.9.9", {}));
  const auto& f = j.at("forest");
  ASSERT_EQ(f.at("species").size(), 2u);
  const auto& beech = f["species"][0];
  EXPECT_EQ(beech["name"], "beech");
  EXPECT_EQ(beech["factor"], 1.6);
  EXPECT_EQ(beech["coefficient_J"], 38.7);
  EXPECT_EQ(beech["exponent"], 2.31);
  EXPECT_EQ(beech["e_max_30cm_J"], 1.6 * (38.7 * std::pow(30.0, 2.31)));
  const auto& larch = f["species"][1];
  EXPECT_EQ(larch["factor"], 1);
  EXPECT_EQ(larch["coefficient_J"], 60);
  EXPECT_EQ(larch["exponent"], 2.31);
  EXPECT_EQ(f["stands"][0]["species"], "beech");
  EXPECT_EQ(f["stands"][1]["species"], "");
  // The unused larch is a warning.
  ASSERT_EQ(j["warnings"].size(), 1u);
}

// The DEM's CRS, as WKT, for the positions every output holds.
TEST(SummaryJson, CarriesTheDemsCrs) {
  const auto dir = testing::FreshDir("summary_crs");
  const std::vector<std::vector<double>> flat(20, std::vector<double>(20, 1000.0));
  testing::WriteGdalRaster(dir / "dem.tif", flat, {2600000, 10, 0, 1200200, 0, -10}, 2056,
                           std::nullopt);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\ndem = \"dem.tif\"\n[rock]\nshape = { box = [1, 1, 1] "
                     "}\n[release]\npoints = [[2600100, 1200100]]\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  const auto j =
      nlohmann::json::parse(SummaryJson(scene, ensemble::EnsembleReport{}, "9.9.9", {}));
  ASSERT_TRUE(j["crs_wkt"].is_string());
  EXPECT_EQ(j["crs_wkt"], scene.crs_wkt);
  EXPECT_NE(j["crs_wkt"].get<std::string>().find("2056"), std::string::npos);
}

// "solver": every option of kSolverOptions in the table's order, then the preset, where it came
// from and what it overrode (talus simulate --preset).
TEST(SummaryJson, SolverIsTheOptionsTableInItsOrderThenThePreset) {
  const auto dir = testing::FreshDir("summary_solver");
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] "
                     "}\n[release]\npoints = [[10, 0]]\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  const auto j = nlohmann::ordered_json::parse(
      SummaryJson(scene, ensemble::EnsembleReport{}, "9.9.9", {"rocks.csv"}));
  std::vector<std::string> keys, expected;
  for (const auto& [key, value] : j["solver"].items()) keys.push_back(key);
  for (const SolverOptionInfo& f : kSolverOptions) expected.emplace_back(f.key);
  for (const char* key : {"preset", "preset_from", "preset_overrode"}) expected.emplace_back(key);
  EXPECT_EQ(keys, expected);
  EXPECT_TRUE(j["solver"]["max_iterations"].is_number_integer());
  EXPECT_EQ(j["solver"]["penetration_tolerance"], 0.01);
}

// The inputs' hash is the SHA-256 of the inputs' bytes in order: of a scene that reads no other
// file, what `sha256sum scene.toml` prints.
TEST(SummaryJson, HashFollowsTheInputs) {
  const auto dir = testing::FreshDir("hash");
  const std::string text =
      "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\npoints = [[10, 0]]\n";
  testing::WriteText(dir / "scene.toml", text);
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(scene.inputs.size(), 1u);
  const std::string a = scene.inputs_hash;
  EXPECT_EQ(a, Sha256Hex(text));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).inputs_hash, a);
  testing::WriteText(dir / "scene.toml", text + "# comment\n");
  EXPECT_NE(LoadScene((dir / "scene.toml").string()).inputs_hash, a);
}

// The evaluation lines' summary under "evaluation_lines", a line without crossings as nulls; no
// such key for a scene without lines.
TEST(SummaryJson, CarriesTheEvaluationLinesSummary) {
  const auto dir = testing::FreshDir("lines");
  const std::string text =
      "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\npoints = [[10, "
      "0]]\n";
  testing::WriteText(dir / "scene.toml", text);
  ensemble::EnsembleReport report;
  EXPECT_FALSE(nlohmann::json::parse(
                   SummaryJson(LoadScene((dir / "scene.toml").string()), report, "9.9.9", {}))
                   .contains("evaluation_lines"));
  testing::WriteText(dir / "scene.toml",
                     text +
                         "[evaluation_lines]\nlines = [[[50, -5], [50, 5]], [[60, -5], [60, "
                         "5]]]\nnames = [\"a\", \"b\"]\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  std::vector<EvaluationLineSummary> lines(2);
  lines[0].name = "a";
  lines[0].length_m = 10;
  lines[0].rocks = 4;
  lines[0].crossed = 2;
  lines[0].passing_probability = 0.5;
  lines[0].energy_J = StatisticsOf({1000, 3000});
  lines[1].name = "b";
  lines[1].rocks = 4;
  lines[1].speed_m_s = StatisticsOf({});
  const auto j = nlohmann::json::parse(SummaryJson(scene, report, "9.9.9", {}, lines));
  ASSERT_EQ(j["evaluation_lines"].size(), 2u);
  const auto& a = j["evaluation_lines"][0];
  EXPECT_EQ(a["name"], "a");
  EXPECT_EQ(a["crossed"], 2);
  EXPECT_DOUBLE_EQ(a["passing_probability"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(a["energy_J"]["mean"].get<double>(), 2000);
  EXPECT_DOUBLE_EQ(a["energy_J"]["p50"].get<double>(), 1000);  // nearest rank: the first of two
  EXPECT_DOUBLE_EQ(a["energy_J"]["max"].get<double>(), 3000);
  EXPECT_TRUE(j["evaluation_lines"][1]["speed_m_s"]["p95"].is_null());
}

}  // namespace
}  // namespace talus::io
