// The fitted ground table (ground_table.toml, ground_table.csv) and history.csv of talus calibrate.

#include "io/calibration_outputs.hpp"

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "common/csv_table.hpp"
#include "tests/calibration/fixtures.hpp"

namespace talus::io {
namespace {

using calibration::GroundField;
using calibration::testing::Spec;

// Categories whose names are no bare TOML keys (a blank, a dot, brackets and a line break, a
// quote and a backslash, a comma), each with mu_min free, on a plane of runs observed by their
// run-outs (the objective is built, never run).
struct OddNames : calibration::testing::PlaneRuns {
  std::vector<std::string> names = {"zone 1", "meadow.v2", "x]\n[y", "q\"\\", "a,b", "plain-name"};
  std::unique_ptr<calibration::Objective> objective;

  OddNames() : PlaneRuns(3, 2) {
    std::vector<calibration::ParameterSpec> specs;
    for (std::size_t k = 0; k < names.size(); ++k) {
      GroundCategory c = scene.ground.category(scene.ground.IndexOfName("medium"));
      c.name = names[k];
      c.code = 50 + static_cast<int>(k);
      c.params.mu_min = 0.3 + 0.01 * static_cast<double>(k);
      scene.ground.Set(c);
      specs.push_back(Spec(names[k], GroundField::kMuMin, 0.1, 1.0));
    }
    fieldobs::ObservationSet observations;
    for (const ensemble::ReleaseRun& run : release.runs)
      observations.scalars.push_back({fieldobs::Quantity::kRunout, run.id, 50, run.id});
    calibration::ObjectiveOptions options;
    options.normalise = false;
    objective =
        std::make_unique<calibration::Objective>(scene, release, observations, specs, options);
  }
};

// ground_table.toml wrote [ground.zone 1], which no TOML reader accepts, made "meadow.v2" a nested
// table and let a name with "]\n[" open a table of its own. Each name is a key of [ground] again.
TEST(CalibrationOutputs, GroundTableTomlQuotesNamesThatAreNoBareKeys) {
  const OddNames odd;
  CalibrationFile file;
  file.path = "cal.toml";
  const std::string text = GroundTableToml(file, *odd.objective, odd.scene.ground);
  toml::table parsed;
  try {
    parsed = toml::parse(text);
  } catch (const toml::parse_error& e) {
    FAIL() << e.what() << "\n" << text;
  }
  const toml::table* ground = parsed["ground"].as_table();
  ASSERT_NE(ground, nullptr) << text;
  EXPECT_EQ(ground->size(), odd.names.size()) << text;
  for (std::size_t k = 0; k < odd.names.size(); ++k) {
    const GroundCategory& c = odd.scene.ground.category(odd.scene.ground.IndexOfName(odd.names[k]));
    EXPECT_EQ((*ground)[odd.names[k]]["code"].value<int>(), c.code) << odd.names[k] << "\n" << text;
    EXPECT_EQ((*ground)[odd.names[k]]["mu_min"].value<double>(), c.params.mu_min) << odd.names[k];
  }
  EXPECT_NE(text.find("[ground.plain-name]"), std::string::npos) << text;  // bare where it may be
}

// A fitted value the observations do not support is marked in ground_table.toml, with the reason:
// unidentified (flat profile) or at a bound of its range; the others carry no comment, and the
// file still reads back every value exactly.
TEST(CalibrationOutputs, GroundTableTomlMarksUnidentifiedAndAtBoundValues) {
  const OddNames odd;
  CalibrationFile file;
  file.path = "cal.toml";
  calibration::CalibrationSummary run;
  const int n = odd.objective->dimension();
  run.fit.best.u = Eigen::VectorXd::Constant(n, 0.5);
  run.fit.best.u[0] = 1.0;  // "zone 1" at its upper bound, 1.0
  run.fit.best.u[5] = 0.0;  // "plain-name" at its lower bound, 0.1
  run.profiles.resize(static_cast<std::size_t>(n));
  for (auto& profile : run.profiles) profile.identified = true;
  run.profiles[1].identified = false;  // "meadow.v2"
  const std::string text = GroundTableToml(file, *odd.objective, odd.scene.ground, &run);
  const toml::table parsed = toml::parse(text);
  for (std::size_t k = 0; k < odd.names.size(); ++k) {
    const GroundCategory& c = odd.scene.ground.category(odd.scene.ground.IndexOfName(odd.names[k]));
    EXPECT_EQ(parsed["ground"][odd.names[k]]["mu_min"].value<double>(), c.params.mu_min) << text;
  }
  const auto line_of = [&](const std::string& category_header) {
    const std::size_t block = text.find(category_header);
    const std::size_t at = text.find("mu_min = ", block);
    return text.substr(at, text.find('\n', at) - at);
  };
  EXPECT_NE(line_of("[ground.\"zone 1\"]").find("# at the upper bound of its range (1)"),
            std::string::npos)
      << text;
  EXPECT_NE(line_of("[ground.\"meadow.v2\"]").find("# unidentified: the observations do not"),
            std::string::npos)
      << text;
  EXPECT_NE(line_of("[ground.plain-name]").find("# at the lower bound of its range (0.1)"),
            std::string::npos)
      << text;
  EXPECT_EQ(line_of("[ground.\"a,b\"]").find('#'), std::string::npos) << text;
  EXPECT_EQ(line_of("[ground.plain-name]").find("unidentified"), std::string::npos) << text;
  // Without the run (the fit alone), no comment at all.
  const std::string bare = GroundTableToml(file, *odd.objective, odd.scene.ground);
  EXPECT_EQ(bare.find("# at the"), std::string::npos);
  EXPECT_EQ(bare.find("# unidentified"), std::string::npos);
}

// ground_table.csv and history.csv: a name with a comma, quote or line break is one quoted field.
TEST(CalibrationOutputs, GroundTableCsvAndHistoryQuoteNames) {
  const OddNames odd;
  const CsvTable table = CsvTable::Parse(GroundTableCsv(*odd.objective, odd.scene.ground), "t.csv");
  ASSERT_EQ(table.rows(), static_cast<int>(odd.names.size()));
  std::vector<std::string> names;
  for (int r = 0; r < table.rows(); ++r) names.push_back(table.Text(r, "category"));
  std::vector<std::string> want = odd.names;
  std::sort(want.begin(), want.end());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, want);

  const CsvTable history =
      CsvTable::Parse(HistoryCsv(*odd.objective, calibration::OptimizerSummary{}), "h.csv");
  for (const std::string& name : odd.names) EXPECT_TRUE(history.Has(name + ".mu_min")) << name;
}

}  // namespace
}  // namespace talus::io
