#include "io/calibration_checkpoint.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "common/error.hpp"
#include "common/sha256.hpp"
#include "test_files.hpp"
#include "tests/io/older_checkpoint.hpp"

namespace talus::io {
namespace {

using calibration::Evaluation;

// Bits of a double: "bit for bit" means that, not ==, which NaN never meets.
bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

Evaluation Sample(double seed) {
  Evaluation e;
  e.u = Eigen::Vector2d(0.1 + seed, 1.0 / 3.0);
  e.values = Eigen::Vector2d(0.55 * (1 + seed), std::nextafter(2.0, 3.0));
  e.value = 1.0 / 7.0 + seed;
  e.data = 0.1 + 0.2;  // 0.30000000000000004: needs all 17 digits
  e.prior = 1e-300;
  e.kind_scores = {12.345678901234567, 6.02214076e23};
  e.kind_scored = {7, 0};
  e.residuals = Eigen::Vector3d(-0.5, 1e-17, 3);
  e.rocks = 1234567;
  e.failed_rocks = 2;
  e.wall_time_s = 0.123456789;
  return e;
}

std::string WriteCheckpoint(const std::string& name, const std::string& text) {
  const auto dir = testing::FreshDir(name);
  std::string path = (dir / "checkpoint.json").string();
  testing::WriteText(path, text);
  return path;
}

void ExpectSameVector(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  ASSERT_EQ(a.size(), b.size());
  for (Eigen::Index k = 0; k < a.size(); ++k) EXPECT_TRUE(SameBits(a[k], b[k])) << k;
}

TEST(CalibrationCheckpoint, EveryNumberComesBackBitForBit) {
  CalibrationCheckpoint c;
  c.path_hash = "abc123";
  c.holdout = {"run 2", "run\"7\""};
  c.folds = 3;
  c.stages["fit"] = {Sample(0), Sample(0.25)};
  c.stages["fold1"] = {Sample(0.5)};
  const CalibrationCheckpoint back = ReadCheckpoint(WriteCheckpoint("round", CheckpointJson(c)));
  EXPECT_EQ(back.path_hash, "abc123");
  EXPECT_EQ(back.holdout, c.holdout);
  EXPECT_EQ(back.folds, 3);
  ASSERT_EQ(back.stages.size(), 2u);
  for (const auto& [name, evaluations] : c.stages) {
    ASSERT_EQ(back.stages.at(name).size(), evaluations.size()) << name;
    for (std::size_t k = 0; k < evaluations.size(); ++k) {
      const Evaluation& a = evaluations[k];
      const Evaluation& b = back.stages.at(name)[k];
      ExpectSameVector(a.u, b.u);
      ExpectSameVector(a.values, b.values);
      ExpectSameVector(a.residuals, b.residuals);
      EXPECT_TRUE(SameBits(a.value, b.value));
      EXPECT_TRUE(SameBits(a.data, b.data));
      EXPECT_TRUE(SameBits(a.prior, b.prior));
      EXPECT_TRUE(SameBits(a.wall_time_s, b.wall_time_s));
      ASSERT_EQ(b.kind_scores.size(), 2u);
      EXPECT_TRUE(SameBits(a.kind_scores[1], b.kind_scores[1]));
      EXPECT_EQ(b.kind_scored, a.kind_scored);
      EXPECT_EQ(b.rocks, a.rocks);
      EXPECT_EQ(b.failed_rocks, a.failed_rocks);
      EXPECT_TRUE(b.feasible);
    }
  }
  // Writing what was read gives the same bytes.
  EXPECT_EQ(CheckpointJson(back), CheckpointJson(c));
}

TEST(CalibrationCheckpoint, AnInfeasibleEvaluationKeepsItsReasonAndItsNaNs) {
  Evaluation e = Sample(0);
  e.feasible = false;
  e.infeasible = "mu_min 2.1 > mu_max 2";
  e.value = std::numeric_limits<double>::quiet_NaN();
  e.data = std::numeric_limits<double>::quiet_NaN();
  e.kind_scores[0] = std::numeric_limits<double>::quiet_NaN();
  CalibrationCheckpoint c;
  c.stages["fit"] = {e};
  const std::string json = CheckpointJson(c);
  EXPECT_NE(json.find("\"value\":null"), std::string::npos) << json;
  const Evaluation back = ReadCheckpoint(WriteCheckpoint("nan", json)).stages.at("fit").at(0);
  EXPECT_FALSE(back.feasible);
  EXPECT_EQ(back.infeasible, e.infeasible);
  EXPECT_TRUE(std::isnan(back.value));
  EXPECT_TRUE(std::isnan(back.data));
  EXPECT_TRUE(std::isnan(back.kind_scores[0]));
  EXPECT_EQ(back.kind_scores[1], e.kind_scores[1]);
}

TEST(CalibrationCheckpoint, AnEmptyCheckpointHasNoStages) {
  const CalibrationCheckpoint back =
      ReadCheckpoint(WriteCheckpoint("empty", CheckpointJson(CalibrationCheckpoint{})));
  EXPECT_TRUE(back.stages.empty());
  EXPECT_TRUE(back.holdout.empty());
  EXPECT_EQ(back.folds, 0);
}

// The message names the file and says what is wrong with it.
void ExpectRefused(const std::string& path, const std::string& says) {
  try {
    ReadCheckpoint(path);
    ADD_FAILURE() << path << " was read";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find(says), std::string::npos) << what;
  }
}

TEST(CalibrationCheckpoint, AMissingTruncatedOrForeignFileIsAnInputErrorNamingIt) {
  const auto dir = testing::FreshDir("missing");
  ExpectRefused((dir / "checkpoint.json").string(), "cannot read the checkpoint");
  CalibrationCheckpoint c;
  c.stages["fit"] = {Sample(0)};
  const std::string json = CheckpointJson(c);
  ExpectRefused(WriteCheckpoint("truncated", json.substr(0, json.size() / 2)),
                "not a calibration checkpoint");
  ExpectRefused(WriteCheckpoint("foreign", "{\"rocks\": 3}"), "not a calibration checkpoint");
  ExpectRefused(WriteCheckpoint("wrong_type",
                                "{\"path_sha256\": 1, \"holdout\": [], \"folds\": 0, "
                                "\"stages\": {}}"),
                "not a calibration checkpoint");
}

// The checkpoint's JSON with one edit.
template <class Edit>
std::string Edited(nlohmann::json j, Edit edit) {
  edit(j);
  return j.dump();
}

// A value edited by hand (here the last evaluation's, lowered to a fake optimum) no longer matches
// the checksum: the checkpoint is refused instead of replayed. So are other edits, and a
// checkpoint without a checksum.
TEST(CalibrationCheckpoint, AnEditedValueIsRefusedByTheChecksum) {
  CalibrationCheckpoint c;
  c.path_hash = "abc123";
  c.stages["fit"] = {Sample(0), Sample(0.25)};
  const nlohmann::json j = nlohmann::json::parse(CheckpointJson(c));
  using J = nlohmann::json;
  ExpectRefused(
      WriteCheckpoint("edited", Edited(j, [](J& e) { e["stages"]["fit"][1]["value"] = 1e-3; })),
      "does not match its checksum");
  ExpectRefused(
      WriteCheckpoint("edited_u", Edited(j, [](J& e) { e["stages"]["fit"][0]["u"] = J::array(); })),
      "does not match its checksum");
  ExpectRefused(
      WriteCheckpoint("edited_hash", Edited(j, [](J& e) { e["path_sha256"] = "abc124"; })),
      "does not match its checksum");
  ExpectRefused(WriteCheckpoint("no_checksum", Edited(j, [](J& e) { e.erase("sha256"); })),
                "has no checksum (\"sha256\"): remove it and run talus calibrate without --resume");
  // Unchanged, it reads.
  EXPECT_NO_THROW(ReadCheckpoint(WriteCheckpoint("unchanged", j.dump())));
}

// The checksum is the SHA-256 of the checkpoint's JSON without it, and the inputs' hash goes in
// under its algorithm's name too.
TEST(CalibrationCheckpoint, TheChecksumIsTheSha256OfWhatItHolds) {
  CalibrationCheckpoint c;
  c.path_hash = std::string(64, 'a');
  c.stages["fit"] = {Sample(0)};
  nlohmann::json j = nlohmann::json::parse(CheckpointJson(c));
  ASSERT_TRUE(j.contains("sha256"));
  const std::string checksum = j["sha256"];
  EXPECT_EQ(checksum.size(), 64u);
  EXPECT_EQ(j["path_sha256"], c.path_hash);
  j.erase("sha256");
  EXPECT_EQ(checksum, Sha256Hex(j.dump()));
}

// A checkpoint that an older talus wrote (an FNV-1a 64 checksum, "fnv1a64", and its calibration's
// FNV-1a hash as "path_hash"; this one as that talus wrote it) is refused, naming the file and
// saying what to do, never replayed and never misread.
TEST(CalibrationCheckpoint, ACheckpointOfAnOlderTalusIsRefusedSayingWhatToDo) {
  const std::string older = talus::testing::kOlderTalusCheckpoint;
  const std::string path = WriteCheckpoint("older_talus", older);
  ExpectRefused(path,
                "a checkpoint of an older talus (its checksum is FNV-1a, \"fnv1a64\"; this talus "
                "checks SHA-256), which cannot be resumed: remove it and run talus calibrate "
                "without --resume to start afresh");
}

// Every evaluation must have the calibration's shape (Sample's: 2 coordinates, 2 kinds, 3
// residuals) and finite numbers where an evaluation always has them; the message names the file,
// the stage and the evaluation. ("u": [] crashed talus calibrate --resume.)
TEST(CalibrationCheckpoint, EvaluationsOfAnotherShapeOrNotFiniteAreRefusedNamingTheEntry) {
  const std::map<std::string, EvaluationShape> shapes = {{"fit", {2, 2, 3}}, {"fold1", {2, 1, 4}}};
  const auto refused = [&](const CalibrationCheckpoint& c, const std::string& says) {
    const std::string path = "dir/checkpoint.json";
    try {
      CheckEvaluations(c, path, shapes);
      ADD_FAILURE() << "accepted, expected: " << says;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(says), std::string::npos) << what;
    }
  };
  const auto with = [](auto edit) {
    CalibrationCheckpoint c;
    c.stages["fit"] = {Sample(0), Sample(0.25)};
    edit(c.stages["fit"][1]);
    return c;
  };
  EXPECT_NO_THROW(CheckEvaluations(with([](Evaluation&) {}), "x", shapes));
  refused(with([](Evaluation& e) { e.u.resize(0); }),
          "stages.fit[1]: \"u\" has 0 entries, the calibration 2 parameters");
  refused(with([](Evaluation& e) { e.u = Eigen::VectorXd::Constant(6, 0.5); }),
          "stages.fit[1]: \"u\" has 6 entries");
  refused(with([](Evaluation& e) { e.values.resize(1); }), "stages.fit[1]: \"values\" has 1");
  refused(with([](Evaluation& e) { e.kind_scores.push_back(1); }), "\"kind_scores\" has 3");
  refused(with([](Evaluation& e) { e.kind_scored.clear(); }), "\"kind_scored\" has 0");
  refused(with([](Evaluation& e) { e.residuals.resize(2); }), "\"residuals\" has 2");
  refused(with([](Evaluation& e) { e.u[0] = std::numeric_limits<double>::quiet_NaN(); }),
          "stages.fit[1]: \"u\" holds a number that is not finite");
  refused(with([](Evaluation& e) { e.value = std::numeric_limits<double>::infinity(); }),
          "\"value\" is not a finite number");
  refused(with([](Evaluation& e) { e.residuals[2] = std::numeric_limits<double>::quiet_NaN(); }),
          "\"residuals\" holds a number that is not finite");
  refused(with([](Evaluation& e) { e.failed_rocks = e.rocks + 1; }), "not counts of rocks");
  // A stage's own shape; a stage the calibration does not have.
  CalibrationCheckpoint fold;
  fold.stages["fold1"] = {Sample(0)};
  refused(fold, "stages.fold1[0]: \"kind_scores\" has 2 entries, the calibration 1");
  CalibrationCheckpoint other;
  other.stages["fold2"] = {};
  refused(other, "stages.fold2: this calibration has no such optimisation");
  // An infeasible evaluation's value may be NaN; a feasible one's not.
  EXPECT_NO_THROW(CheckEvaluations(with([](Evaluation& e) {
                                     e.feasible = false;
                                     e.value = std::numeric_limits<double>::quiet_NaN();
                                   }),
                                   "x", shapes));
}

}  // namespace
}  // namespace talus::io
