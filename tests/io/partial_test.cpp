#include "io/partial.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "common/sha256.hpp"
#include "io/rocks_csv.hpp"
#include "tests/test_tmp.hpp"

namespace talus::io {
namespace {

PartialInfo Part(const std::string& dir, long first, long end, long total = 10) {
  PartialInfo p;
  p.dir = dir;
  p.version = "1.0";
  p.scene = "scene.toml";
  p.scene_file = "/data/scene.toml";
  p.inputs_hash = "abc";
  p.seed = 1;
  p.solver_preset = "default";
  p.rocks_per_release = total;
  p.total_rocks = total;
  p.first_rock = first;
  p.end_rock = end;
  p.counts.rocks = end - first;
  return p;
}

std::string Message(const std::vector<PartialInfo>& parts) {
  try {
    CheckPartials(parts);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckPartials, AcceptsATilingInAnyOrderAndSortsIt) {
  const auto parts = CheckPartials({Part("c", 7, 10), Part("a", 0, 3), Part("b", 3, 7)});
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].dir, "a");
  EXPECT_EQ(parts[1].dir, "b");
  EXPECT_EQ(parts[2].dir, "c");
}

TEST(CheckPartials, NamesOverlapsAndMissingRocks) {
  EXPECT_EQ(Message({Part("a", 0, 6), Part("b", 4, 10)}), "rocks 4:10 of b overlap rocks 0:6 of a");
  EXPECT_EQ(Message({Part("a", 0, 4), Part("b", 6, 10)}),
            "rocks 4:6 of 10 are in no partial result (the next part, b, starts at rock 6)");
  EXPECT_EQ(Message({Part("a", 0, 4)}), "rocks 4:10 of 10 are in no partial result");
  EXPECT_EQ(Message({Part("a", 2, 10)}),
            "rocks 0:2 of 10 are in no partial result (the next part, a, starts at rock 2)");
  EXPECT_EQ(Message({}), "no partial results to merge");
}

TEST(CheckPartials, NamesWhatDiffersBetweenRuns) {
  PartialInfo b = Part("b", 5, 10);
  b.seed = 2;
  EXPECT_EQ(Message({Part("a", 0, 5), b}), "a and b are parts of different runs: seeds 1 and 2");
  b = Part("b", 5, 10);
  b.version = "1.1";
  EXPECT_EQ(Message({Part("a", 0, 5), b}),
            "a and b are parts of different runs: talus versions 1.0 and 1.1");
  b = Part("b", 5, 10);
  b.inputs_hash = "abd";
  EXPECT_NE(Message({Part("a", 0, 5), b}).find("different runs: scenes (inputs hash)"),
            std::string::npos);
  b = Part("b", 5, 10);
  b.solver_preset = "fast";  // talus simulate --preset fast for one part only
  EXPECT_EQ(Message({Part("a", 0, 5), b}),
            "a and b are parts of different runs: solver presets default and fast");
}

TEST(ReadPartialInfo, ADirectoryWithoutPartialJsonIsNotAPart) {
  const auto dir = talus::testing::TestTmpRoot() / "talus_partial_test_empty";
  std::filesystem::create_directories(dir);
  EXPECT_THROW(ReadPartialInfo(dir.string()), InputError);
  std::ofstream(dir / "partial.json") << "{\"format\": \"something else\"}";
  try {
    ReadPartialInfo(dir.string());
    FAIL() << "accepted a partial.json of another format";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("partial.json"), std::string::npos) << e.what();
  }
}

// A part of rocks [first, end) of a 10-rock ensemble in `name`: rocks.csv with a row per rock
// (only the rock column filled), a partial.bin of made-up bytes and partial.json; `edit` changes
// the files before partial.json is written (so its checksums are those of the edited files).
std::string MakePart(const std::string& name, long first, long end,
                     const std::function<void(const std::filesystem::path&)>& edit = {}) {
  const auto dir = talus::testing::TestTmpRoot() / "talus_partial_test_files" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    std::ofstream csv(dir / "rocks.csv");
    csv << RocksCsvWriter::Header() << "\n";
    for (long rock = first; rock < end; ++rock) csv << rock << std::string(23, ',') << "\n";
    std::ofstream(dir / "partial.bin", std::ios::binary) << std::string("state \x01\x02\x03", 9);
  }
  if (edit) edit(dir);
  SceneFile scene;
  scene.path = "scene.toml";
  scene.release.releases.resize(1);
  scene.release.rocks_per_release = 10;
  ensemble::EnsembleReport report;
  report.rocks = end - first;
  std::ofstream(dir / "partial.json")
      << PartialJson(scene, "1.0", first, end, report,
                     {(dir / "rocks.csv").string(), (dir / "partial.bin").string()});
  return dir.string();
}

// The message of CheckPartFiles on the part in `dir` ("" when it passes).
std::string FilesMessage(const std::string& dir) {
  try {
    CheckPartFiles(ReadPartialInfo(dir));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void FlipBit(const std::filesystem::path& path, std::size_t byte) {
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  bytes.at(byte) = static_cast<char>(bytes[byte] ^ 1);
  std::ofstream(path, std::ios::binary) << bytes;
}

// talus merge took parts with duplicated or missing rows and damaged partial.bin files without an
// error: every file of a part is checked against the size and checksum in its partial.json.
TEST(CheckPartFiles, AFileChangedSinceThePartRanIsRefused) {
  const std::string a = MakePart("a", 0, 5), b = MakePart("b", 5, 10);
  EXPECT_EQ(FilesMessage(a), "");
  EXPECT_EQ(FilesMessage(b), "");
  // Every single-bit flip of partial.bin.
  const auto bin = std::filesystem::path(b) / "partial.bin";
  for (std::size_t byte = 0; byte < 9; ++byte) {
    FlipBit(bin, byte);
    EXPECT_NE(FilesMessage(b).find("partial.bin: 9 bytes with SHA-256 "), std::string::npos)
        << byte << ": " << FilesMessage(b);
    FlipBit(bin, byte);
  }
  EXPECT_EQ(FilesMessage(b), "");
  // Another part's rocks.csv; a row deleted; a file gone.
  std::filesystem::copy_file(std::filesystem::path(a) / "rocks.csv",
                             std::filesystem::path(b) / "rocks.csv",
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_NE(FilesMessage(b).find("rocks.csv: "), std::string::npos) << FilesMessage(b);
  EXPECT_NE(FilesMessage(b).find("changed or damaged since the part was run"), std::string::npos);
  std::filesystem::remove(std::filesystem::path(b) / "partial.bin");
  EXPECT_NE(FilesMessage(b).find("partial.bin: missing (partial.json lists it)"), std::string::npos)
      << FilesMessage(b);
}

// partial.json records each file's size and SHA-256, and the scene inputs' hash under its
// algorithm's name.
TEST(PartialJson, RecordsEachFilesSizeAndSha256) {
  const std::string dir = MakePart("recorded", 0, 5);
  const PartialInfo part = ReadPartialInfo(dir);
  ASSERT_EQ(part.files.size(), 2u);
  for (const char* name : {"rocks.csv", "partial.bin"}) {
    std::ifstream in(std::filesystem::path(dir) / name, std::ios::binary);
    const std::string bytes(std::istreambuf_iterator<char>(in), {});
    EXPECT_EQ(part.files.at(name).bytes, bytes.size()) << name;
    EXPECT_EQ(part.files.at(name).sha256, Sha256Hex(bytes)) << name;
  }
  std::ifstream in(std::filesystem::path(dir) / "partial.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.contains("inputs_sha256"));
  EXPECT_EQ(j["files"]["rocks.csv"]["sha256"], part.files.at("rocks.csv").sha256);
}

// A part that an older talus wrote (partial result format 3: FNV-1a 64 checksums, the inputs'
// hash as "inputs_hash_fnv1a64") cannot be checked: it is refused, naming its partial.json and
// saying how to run it again, never merged.
TEST(ReadPartialInfo, APartOfAnOlderTalusIsRefusedSayingHowToRunItAgain) {
  const std::string dir = MakePart("older", 5, 10);
  const auto json_path = std::filesystem::path(dir) / "partial.json";
  nlohmann::ordered_json j;
  {
    std::ifstream in(json_path);
    j = nlohmann::ordered_json::parse(in);
  }
  j["format_version"] = 3;
  j["inputs_hash_fnv1a64"] = "cbf29ce484222325";
  j.erase("inputs_sha256");
  for (auto& [name, entry] : j["files"].items()) {
    entry.erase("sha256");
    entry["fnv1a64"] = "af63bd4c8601b7df";
  }
  std::ofstream(json_path) << j.dump(2) << "\n";
  try {
    ReadPartialInfo(dir);
    ADD_FAILURE() << "a part of an older talus was read";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              json_path.string() +
                  ": a part written by an older talus (partial result format 3, this talus reads "
                  "5; its checksums are FNV-1a, this talus checks SHA-256): run the part again "
                  "with this talus (talus simulate scene.toml --rock-range 5:10 and the options "
                  "it ran with)");
  }
}

// Rows must be the part's rocks, each once and in order, even where the checksums agree (a
// partial.json written for the wrong files).
TEST(CheckPartFiles, RowsOutsideThePartsRangeAreRefusedNamingTheLine) {
  const auto rewrite = [](long first, long end, long skip) {
    return [=](const std::filesystem::path& dir) {
      std::ofstream csv(dir / "rocks.csv");
      csv << RocksCsvWriter::Header() << "\n";
      for (long rock = first; rock < end; ++rock)
        if (rock != skip) csv << rock << std::string(23, ',') << "\n";
    };
  };
  EXPECT_NE(FilesMessage(MakePart("dup", 5, 10, rewrite(0, 5, -1)))
                .find("rocks.csv:2: rock 0 where rock 5 was due (the part holds rocks 5:10)"),
            std::string::npos)
      << FilesMessage(MakePart("dup", 5, 10, rewrite(0, 5, -1)));
  EXPECT_NE(FilesMessage(MakePart("gap", 5, 10, rewrite(5, 10, 7)))
                .find("rocks.csv:4: rock 8 where rock 7 was due"),
            std::string::npos);
  EXPECT_NE(FilesMessage(MakePart("short", 5, 10, rewrite(5, 9, -1)))
                .find("rocks.csv: no row of rock 9 or later (the part holds rocks 5:10)"),
            std::string::npos)
      << FilesMessage(MakePart("short", 5, 10, rewrite(5, 9, -1)));
}

}  // namespace
}  // namespace talus::io
