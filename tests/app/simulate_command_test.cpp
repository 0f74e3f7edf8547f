// End to end through the talus program: `talus simulate` on a tiny scene.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "talus_app_tests" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Runs a command; returns its exit status and puts stdout + stderr in *output.
int RunCommand(const std::string& command, std::string* output) {
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  std::array<char, 4096> buffer;
  output->clear();
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
    output->append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* kScene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_hard"
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
points = [[3, 0]]
lines = [[[4, -2], [4, 2]]]
rocks = 3
[solver]
max_time_s = 4
[output]
trajectories = true
trajectory_interval_s = 0.05
rasters = ["speed", "energy", "jump_height", "passages", "deposits", "reach_probability"]
)";

TEST(SimulateCommand, WritesEveryOutputIdenticallyForOneAndTwoThreads) {
  const fs::path dir = FreshDir("outputs");
  std::ofstream(dir / "scene.toml") << kScene;
  std::string log;
  for (const char* threads : {"1", "2"}) {
    const std::string out = (dir / (std::string("out") + threads)).string();
    ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                             " --out " + out + " --threads " + threads,
                         &log),
              0)
        << log;
  }
  const fs::path a = dir / "out1", b = dir / "out2";
  int tifs = 0;
  for (const auto& entry : fs::directory_iterator(a)) {
    const std::string name = entry.path().filename().string();
    EXPECT_NE(name[0], '.') << "temporary file left behind: " << name;
    if (entry.path().extension() == ".tif" || name == "rocks.csv") {
      EXPECT_EQ(Slurp(entry.path()), Slurp(b / name)) << name << " differs between 1 and 2 threads";
      tifs += entry.path().extension() == ".tif";
    }
  }
  EXPECT_EQ(tifs, 12);
  for (const char* name : {"rocks.csv", "trajectories.h5", "summary.json", "quicklook.png"})
    EXPECT_TRUE(fs::exists(a / name)) << name;
  const auto summary = nlohmann::json::parse(Slurp(a / "summary.json"));
  EXPECT_EQ(summary["rocks"], 6);
  EXPECT_EQ(summary["threads"], 1);
  std::ifstream csv(a / "rocks.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 7);
}

TEST(SimulateCommand, OverridesRocksAndSeed) {
  const fs::path dir = FreshDir("overrides");
  std::ofstream(dir / "scene.toml") << kScene;
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string() + " --rocks 1 --seed 9",
                       &log),
            0)
      << log;
  const auto summary = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  EXPECT_EQ(summary["rocks"], 2);
  EXPECT_EQ(summary["seed"], 9);
}

// --rocks is checked like the scene's rocks: 2 releases x 2^63 - 1 rocks used to overflow to a
// "successful" run of no rock.
TEST(SimulateCommand, TooManyRocksOnTheCommandLineIsAnError) {
  const fs::path dir = FreshDir("too_many");
  std::ofstream(dir / "scene.toml") << kScene;
  std::string log;
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string() + " --rocks 9223372036854775807",
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("--rocks 9223372036854775807: "), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir / "out" / "rocks.csv"));
}

TEST(SimulateCommand, BadSceneFailsBeforeAnyWorkNamingFileLineAndKey) {
  const fs::path dir = FreshDir("bad");
  std::string scene = kScene;
  scene.replace(scene.find("rocks = 3"), 9, "rock = 3");
  std::ofstream(dir / "scene.toml") << scene;
  std::string log;
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string(),
                       &log),
            2);
  EXPECT_NE(log.find("scene.toml:9: release.rock: unknown key (did you mean 'rocks'?)"),
            std::string::npos)
      << log;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(SimulateCommand, ARunRemovesOutputsOfAnEarlierRunThatItDoesNotWrite) {
  const fs::path dir = FreshDir("stale");
  std::ofstream(dir / "all.toml") << kScene;
  std::string lean = kScene;
  lean.replace(lean.find("trajectories = true"), 19, "trajectories = false");
  lean.replace(lean.find("rasters = ["),
               lean.find("]\n", lean.find("rasters = [")) - lean.find("rasters = [") + 1,
               "rasters = []\nquicklook = false");
  std::ofstream(dir / "lean.toml") << lean;
  const std::string out = (dir / "out").string();
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "all.toml").string() +
                           " --out " + out,
                       &log),
            0)
      << log;
  ASSERT_TRUE(fs::exists(dir / "out" / "trajectories.h5"));
  ASSERT_TRUE(fs::exists(dir / "out" / "speed_p95.tif"));
  std::ofstream(dir / "out" / "notes.txt") << "the user's own file";
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "lean.toml").string() +
                           " --out " + out,
                       &log),
            0)
      << log;
  EXPECT_FALSE(fs::exists(dir / "out" / "trajectories.h5"));
  EXPECT_FALSE(fs::exists(dir / "out" / "speed_p95.tif"));
  EXPECT_FALSE(fs::exists(dir / "out" / "quicklook.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "rocks.csv"));
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "out" / "notes.txt"));
}

}  // namespace
