#include "io/summary.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

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
  EXPECT_EQ(j["inputs_hash_fnv1a64"], scene.inputs_hash);
  EXPECT_EQ(j["ends"]["rest"], 7);
  EXPECT_EQ(j["ends"]["left_domain"], 2);
  EXPECT_EQ(j["ends"]["max_time"], 1);
  EXPECT_EQ(j["raised_at_release"], 3);
  EXPECT_EQ(j["stayed_at_release"], 4);
  // The options and ground table actually used, defaults included.
  EXPECT_EQ(j["solver"]["viscous"], "contact_friction");
  EXPECT_DOUBLE_EQ(j["solver"]["dt_s"].get<double>(), 0.002);
  EXPECT_DOUBLE_EQ(j["solver"]["tolerance_m_s"].get<double>(), 1e-7);
  EXPECT_EQ(j["ground"].size(), 8u);  // Table 1
  EXPECT_EQ(j["ground"]["medium"]["code"], 4);
  EXPECT_DOUBLE_EQ(j["ground"]["medium"]["mu_min"].get<double>(), 0.35);
  EXPECT_DOUBLE_EQ(j["ground"]["snow"]["mu_max"].get<double>(), 0.35);
  EXPECT_FALSE(j["ground"]["medium"].contains("drag_height_m"));  // no layer
  EXPECT_DOUBLE_EQ(j["trajectories_per_s"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(j["wall_time_s"].get<double>(), 2.0);
}

TEST(SummaryJson, HashFollowsTheInputs) {
  const auto dir = testing::FreshDir("hash");
  const std::string text =
      "[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\npoints = [[10, 0]]\n";
  testing::WriteText(dir / "scene.toml", text);
  const std::string a = LoadScene((dir / "scene.toml").string()).inputs_hash;
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).inputs_hash, a);
  testing::WriteText(dir / "scene.toml", text + "# comment\n");
  EXPECT_NE(LoadScene((dir / "scene.toml").string()).inputs_hash, a);
}

}  // namespace
}  // namespace talus::io
