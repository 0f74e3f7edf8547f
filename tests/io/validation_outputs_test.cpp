// What talus validate writes (io/validation_outputs.hpp), from reports built by hand: scores.json's
// stable keys with NaN as null, observations.csv's header and rows (empty fields for missing
// values, quoted text), the observed-vs-simulated and PIT plots' panels and bars, and
// WriteTextFile's all-or-nothing write.

#include "io/validation_outputs.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "io/svg_plot.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

fieldobs::ObservationScore Scalar(const std::string& run, double observed, double median) {
  fieldobs::ObservationScore s;
  s.kind = "runout";
  s.unit = "m";
  s.run = run;
  s.where = "runs.csv:" + run;
  s.observed = observed;
  s.scored = true;
  s.members = 20;
  s.score = std::abs(median - observed) / 2;
  s.pit = 0.5;
  s.mean = s.median = median;
  s.sd = 3;
  s.q05 = median - 5;
  s.q95 = median + 5;
  s.inside_90 = std::abs(median - observed) <= 5;
  s.bias = median - observed;
  return s;
}

// Two runout observations (one with a comma in its run id), one unscored, one deposit.
fieldobs::ValidationReport Report() {
  fieldobs::ValidationReport r;
  r.observations = {Scalar("r1", 100, 104), Scalar("a, b", 120, 110)};
  fieldobs::ObservationScore missing;
  missing.kind = "runout";
  missing.unit = "m";
  missing.run = "r3";
  missing.not_scored = "1 simulated value (at least 2 needed)";
  missing.observed = 90;
  r.observations.push_back(missing);
  fieldobs::ObservationScore deposit;
  deposit.kind = "deposit";
  deposit.unit = "m";
  deposit.observed_xy_m = {10, 20};
  deposit.scored = true;
  deposit.score = 4;
  r.observations.push_back(deposit);
  fieldobs::KindSummary runout;
  runout.kind = "runout";
  runout.unit = "m";
  runout.observations = 3;
  runout.scored = 2;
  runout.mean_score = 3.5;
  runout.pit.counts = {0, 2, 0};
  runout.pit.degrees_of_freedom = 2;
  runout.pit.chi_square = 4;
  runout.pit.p_value = 0.135;
  fieldobs::KindSummary deposits;
  deposits.kind = "deposit";
  deposits.unit = "m";
  deposits.observations = 1;
  deposits.scored = 1;
  deposits.mean_score = 4;
  r.kinds = {runout, deposits};
  r.observations_scored = 3;
  r.skill_vs_climatology = 0.25;
  return r;
}

TEST(ScoresJson, StableKeysWithNaNAsNullAndTheReferenceNote) {
  EventFile event;
  event.path = "event.toml";
  event.scene.path = "scene.toml";
  event.not_scored = {"scars.csv: depth_m: no simulated counterpart"};
  ValidationRun run;
  run.version = "9.9";
  run.rocks_per_run = 50;
  run.seed = 3;
  run.ensemble.by_end[static_cast<std::size_t>(EndReason::kRest)] = 7;
  run.ensemble.by_end[static_cast<std::size_t>(EndReason::kFailed)] = 1;
  const nlohmann::json j = nlohmann::json::parse(ScoresJson(event, Report(), run));
  EXPECT_EQ(j["talus_version"], "9.9");
  EXPECT_EQ(j["rocks_per_run"], 50);
  EXPECT_EQ(j["seed"], 3);
  EXPECT_EQ(j["ends"]["rest"], 7);
  EXPECT_EQ(j["ends"]["failed"], 1);
  EXPECT_EQ(j["observations"], 4);
  EXPECT_EQ(j["observations_scored"], 3);
  EXPECT_TRUE(j["overall"]["skill_vs_reference"].is_null());
  EXPECT_EQ(j["overall"]["skill_vs_climatology"], 0.25);
  EXPECT_EQ(j["reference"]["parameters"], "table1");
  EXPECT_EQ(j["reference"]["note"], "the scene's ground table is the reference: skill 0");
  EXPECT_EQ(j["not_scored"].size(), 1u);
  EXPECT_EQ(j["kinds"]["runout"]["score"], "crps");
  EXPECT_EQ(j["kinds"]["deposit"]["score"], "energy_score");
  EXPECT_EQ(j["kinds"]["runout"]["pit"]["counts"], nlohmann::json({0, 2, 0}));
  EXPECT_FALSE(j["kinds"]["deposit"].contains("pit"));
  EXPECT_TRUE(j["kinds"]["runout"]["mean_bias"].is_null());
  // A simulated reference run, or none at all: no note.
  run.reference_run = true;
  EXPECT_EQ(nlohmann::json::parse(ScoresJson(event, Report(), run))["reference"]["note"], "");
}

TEST(ObservationsCsv, OneRowPerObservationWithEmptyFieldsForMissingValues) {
  const std::string csv = ObservationsCsv(Report());
  std::istringstream in(csv);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0],
            "kind,run,unit,observed,observed_x_m,observed_y_m,scored,members,score,pit,mean,median,"
            "sd,q05,q95,inside_90,bias,reference_score,climatology_score,source,note");
  EXPECT_EQ(lines[1], "runout,r1,m,100,,,1,20,2,0.5,104,104,3,99,109,1,4,,,runs.csv:r1,");
  EXPECT_EQ(lines[2].substr(0, 16), "runout,\"a, b\",m,");
  EXPECT_NE(lines[2].find(",0,-10,"), std::string::npos) << "outside the band, bias -10";
  // Not scored: no inside_90, the reason in the note.
  EXPECT_EQ(lines[3], "runout,r3,m,90,,,0,0,,,,,,,,,,,,,1 simulated value (at least 2 needed)");
  EXPECT_EQ(lines[4].substr(0, 23), "deposit,,m,,10,20,1,0,4");
}

TEST(ValidationPlots, PanelsForScoredScalarKindsAndPitBarsInProportion) {
  const std::string svg = ObservedVsSimulatedSvg(Report());
  EXPECT_NE(svg.find(">run-out: simulated against observed</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">observed (m)</text>"), std::string::npos);
  EXPECT_EQ(svg.find("deposit"), std::string::npos) << "no panel for deposits";
  EXPECT_EQ(ObservedVsSimulatedPanels(Report()).size(), 1u);
  const std::regex dot("<circle ");
  EXPECT_EQ(
      std::distance(std::sregex_iterator(svg.begin(), svg.end(), dot), std::sregex_iterator()),
      2);  // the scored scalars' medians
  EXPECT_NE(svg.find("<title>a, b</title>"), std::string::npos);
  // The one plot writer's frame: round ticks (the old panels had 95.5, 103.8, ...).
  EXPECT_NE(svg.find(">100</text>"), std::string::npos) << svg;
  fieldobs::ValidationReport none;
  EXPECT_NE(ObservedVsSimulatedSvg(none).find("no scalar observation was scored"),
            std::string::npos);
  EXPECT_NE(PitSvg(none).find("no PIT histogram"), std::string::npos);

  // PIT: bars of counts 1, 4, 2 (7 observations) under a top of max(4, 1.5 * 7/3) = 4: heights
  // of the plot box's height times count / 4.
  fieldobs::ValidationReport r = Report();
  r.kinds[0].pit.counts = {1, 4, 2};
  const std::string pit = PitSvg(r);
  EXPECT_NE(pit.find("PIT: run-out (7 observations)"), std::string::npos) << pit;
  std::vector<double> heights;
  const std::regex bar(R"re(height="([0-9.]+)" fill="#6a8fd0")re");
  for (auto it = std::sregex_iterator(pit.begin(), pit.end(), bar); it != std::sregex_iterator();
       ++it)
    heights.push_back(std::stod((*it)[1]));
  ASSERT_EQ(heights.size(), 3u);
  const double box = svg::kHeight - svg::kTop - svg::kBottom;
  EXPECT_NEAR(heights[0], box * 1 / 4, 0.01);
  EXPECT_NEAR(heights[1], box, 0.01);
  EXPECT_NEAR(heights[2], box * 2 / 4, 0.01);
}

TEST(WriteTextFile, WritesTheWholeTextOrThrowsLeavingNothing) {
  const auto dir = testing::FreshDir("write");
  const auto path = dir / "scores.json";
  WriteTextFile(path.string(), "first\n");
  WriteTextFile(path.string(), "second, longer\n");
  std::ifstream in(path);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "second, longer\n");
  EXPECT_THROW(WriteTextFile((dir / "no_such_dir" / "x.json").string(), "x"), std::runtime_error);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.exists();
  EXPECT_EQ(files, 1) << "no temporary file left behind";
}

}  // namespace
}  // namespace talus::io
