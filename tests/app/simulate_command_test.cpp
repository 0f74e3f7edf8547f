// End to end through the talus program: `talus simulate` on a tiny scene, its failures, its
// interrupts and the command line's messages and exit codes.

#include <cpl_minixml.h>
#include <cpl_string.h>
#include <fcntl.h>
#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill is declared here
#include <spawn.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io/map_classes.hpp"
#include "run_talus.hpp"

namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  return talus::app::testing::FreshDir("talus_app_tests", name);
}

using talus::app::testing::RunCommand;

pid_t StartTalus(const std::vector<std::string>& arguments, const fs::path& log) {
  return talus::app::testing::StartProgram(TALUS_BINARY, arguments, log);
}

using talus::app::testing::kHangSeconds;
using talus::app::testing::WaitFor;

using talus::app::testing::Slurp;

// Every regular file of `dir` by name, with its contents.
std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files[entry.path().filename().string()] = Slurp(entry.path());
  return files;
}

// Names in `dir` of temporary files or staging directories (".<name>.talus-tmp-<pid>").
std::vector<std::string> Temporaries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".talus-tmp-") != std::string::npos) names.push_back(name);
  }
  return names;
}

std::string Talus(const std::string& arguments) {
  return std::string(TALUS_BINARY) + " " + arguments;
}

// The id of a process that has ended (a child that exited and was reaped).
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

const std::string kScene = talus::app::testing::SmallSlopeScene(3, R"(trajectories = true
trajectory_interval_s = 0.05
rasters = ["speed", "energy", "jump_height", "passages", "deposits", "reach_probability"]
)");

// kScene writing only rocks.csv and summary.json.
std::string LeanScene() {
  std::string lean = kScene;
  lean.replace(lean.find("trajectories = true"), 19, "trajectories = false");
  lean.replace(lean.find("rasters = ["),
               lean.find("]\n", lean.find("rasters = [")) - lean.find("rasters = [") + 1,
               "rasters = []\nquicklook = false\ngeopackage = false");
  return lean;
}

// The benchmark ramp (cases/ramp40) with far more rocks than a test waits for, and trajectories.
const char* kSlowScene = R"([terrain]
plane = { slope_deg = 40, slope_length_m = 200, runout_m = 150, width_m = 100, cell_m = 2 }
default_ground = "medium_hard"
[rock]
shape = { eota = "221", size_m = [0.93, 0.93, 0.47] }
density_kg_m3 = 2500
mass_kg = 780
[release]
points = [[10, 0]]
rocks = 100000
[output]
trajectories = true
trajectory_interval_s = 0.05
rasters = ["speed", "passages"]
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
    EXPECT_EQ(name.find(".talus-tmp-"), std::string::npos)
        << "temporary file left behind: " << name;
    // summary.json has the wall time and the threads, run.log the command line and the timings.
    if (name != "summary.json" && name != "run.log") {
      EXPECT_EQ(Slurp(entry.path()), Slurp(b / name)) << name << " differs between 1 and 2 threads";
      tifs += entry.path().extension() == ".tif";
    }
  }
  EXPECT_EQ(tifs, 12);
  EXPECT_TRUE(Slurp(a / "trajectories.h5") == Slurp(b / "trajectories.h5"));
  // The report's map of the quick-look's layer (speed_max here) is quicklook.png itself.
  const std::string quicklook = Slurp(a / "quicklook.png");
  char* base64 = CPLBase64Encode(static_cast<int>(quicklook.size()),
                                 reinterpret_cast<const GByte*>(quicklook.data()));
  ASSERT_NE(base64, nullptr);
  EXPECT_NE(Slurp(a / "report.html").find(std::string("data:image/png;base64,") + base64 + "\""),
            std::string::npos);
  CPLFree(base64);
  for (const char* name :
       {"rocks.csv", "trajectories.h5", "summary.json", "quicklook.png", "rocks.gpkg"})
    EXPECT_TRUE(fs::exists(a / name)) << name;
  const auto summary = nlohmann::json::parse(Slurp(a / "summary.json"));
  EXPECT_EQ(summary["rocks"], 6);
  EXPECT_EQ(summary["threads"], 1);
  std::ifstream csv(a / "rocks.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  EXPECT_EQ(lines, 7);
}

// rocks.gpkg is written by default, with the scene's releases, evaluation lines and barriers as
// layers beside the rocks', and a default QGIS style per layer in layer_styles: points in the
// quick-look's energy classes, the others one symbol each. ogrinfo (gdal-bin) lists every layer
// and the table without an error.
TEST(SimulateCommand, TheGeoPackageHasTheScenesLayersAndAStyleForEach) {
  const fs::path dir = FreshDir("geopackage");
  std::ofstream(dir / "scene.toml") << talus::app::testing::SmallSlopeScene(
      2, "trajectories = true\n",
      "[evaluation_lines]\nlines = [[[12, -6], [12, 6]]]\nnames = [\"mid\"]\n"
      "[[barriers]]\nname = \"net\"\ntype = \"flexible_net\"\nline = [[18, -6], [18, 6]]\n"
      "height_m = 3\ncapacity_kj = 500\n");
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string(),
                       &log),
            0)
      << log;
  const fs::path gpkg = dir / "out" / "rocks.gpkg";
  ASSERT_TRUE(fs::exists(gpkg)) << log;

  GDALAllRegister();
  const std::unique_ptr<GDALDataset, decltype(&GDALClose)> dataset(
      GDALDataset::Open(gpkg.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY), GDALClose);
  ASSERT_TRUE(dataset);
  std::vector<std::string> layers;
  for (OGRLayer* layer : dataset->GetLayers())
    if (std::string(layer->GetName()) != "layer_styles") layers.push_back(layer->GetName());
  std::sort(layers.begin(), layers.end());
  EXPECT_EQ(layers, (std::vector<std::string>{"barrier_impacts", "barriers", "end_points",
                                              "evaluation_crossings", "evaluation_lines", "paths",
                                              "release_lines", "release_points"}));
  OGRLayer* styles = dataset->GetLayerByName("layer_styles");
  ASSERT_NE(styles, nullptr);
  const std::size_t energy_classes = talus::io::EnergyLegend().classes.size();
  std::vector<std::string> styled;
  for (const auto& feature : *styles) {
    const std::string layer = feature->GetFieldAsString("f_table_name");
    styled.push_back(layer);
    EXPECT_EQ(feature->GetFieldAsInteger("useAsDefault"), 1) << layer;
    EXPECT_STREQ(feature->GetFieldAsString("f_geometry_column"), "geom") << layer;
    EXPECT_STREQ(feature->GetFieldAsString("update_time"), "2000/01/01 00:00:00+00") << layer;
    std::unique_ptr<CPLXMLNode, decltype(&CPLDestroyXMLNode)> qml(
        CPLParseXMLString(feature->GetFieldAsString("styleQML")), CPLDestroyXMLNode);
    ASSERT_TRUE(qml) << layer << ": the style is not XML";
    const CPLXMLNode* renderer = CPLGetXMLNode(qml.get(), "=qgis.renderer-v2");
    ASSERT_NE(renderer, nullptr) << layer;
    std::size_t ranges = 0, symbols = 0;
    for (const CPLXMLNode* c = CPLGetXMLNode(renderer, "ranges.range"); c; c = c->psNext)
      ranges += c->eType == CXT_Element;
    for (const CPLXMLNode* c = CPLGetXMLNode(renderer, "symbols.symbol"); c; c = c->psNext)
      symbols += c->eType == CXT_Element;
    const bool points =
        layer == "end_points" || layer == "evaluation_crossings" || layer == "barrier_impacts";
    EXPECT_EQ(ranges, points ? energy_classes : 0) << layer;
    EXPECT_EQ(symbols, points ? energy_classes : 1) << layer;
  }
  std::sort(styled.begin(), styled.end());
  EXPECT_EQ(styled, layers) << "one style per layer";

  if (RunCommand("command -v ogrinfo", &log) != 0)
    GTEST_SKIP() << "ogrinfo is not installed (Debian package gdal-bin, "
                    "scripts/debian-packages.txt): the listing by ogrinfo is not checked";
  ASSERT_EQ(RunCommand("ogrinfo -so -al " + gpkg.string(), &log), 0) << log;
  EXPECT_EQ(log.find("ERROR"), std::string::npos) << log;
  EXPECT_EQ(log.find("Warning"), std::string::npos) << log;
  for (const std::string& layer : layers)
    EXPECT_NE(log.find("Layer name: " + layer + "\n"), std::string::npos) << layer << "\n" << log;
  EXPECT_NE(log.find("Layer name: layer_styles\n"), std::string::npos) << log;
}

// A 35° slope as an ESRI ASCII grid (30 x 12 cells of 1 m, no CRS) with a nodata hole of 3 x 3
// cells in the rocks' way.
std::string SlopeDemWithAHole() {
  std::string text =
      "ncols 30\nnrows 12\nxllcorner 0\nyllcorner -6\ncellsize 1\n"
      "NODATA_value -9999\n";
  for (int row = 0; row < 12; ++row) {
    for (int column = 0; column < 30; ++column) {
      const bool hole = column >= 14 && column < 17 && row >= 4 && row < 7;
      text += hole ? "-9999" : std::to_string(21.0 - 0.7 * (column + 0.5));
      text += column + 1 < 30 ? " " : "\n";
    }
  }
  return text;
}

// Every raster of a run on a DEM with a nodata hole, as COGs with two percentiles: nodata in the
// hole whatever passed there, 0 counts or nodata statistics elsewhere where no rock passed; each
// band says what it is and which run made it (summary.json's inputs hash, the ground table), and
// the bytes are the same for 1 and 2 threads.
TEST(SimulateCommand, RastersAreNodataOverDemHolesAndDescribeThemselves) {
  const fs::path dir = FreshDir("hazard_rasters");
  talus::app::testing::Write(dir / "dem.asc", SlopeDemWithAHole());
  talus::app::testing::Write(dir / "scene.toml", R"([terrain]
dem = "dem.asc"
default_ground = "extra_hard"
[rock]
shape = { sphere = 0.2 }
[release]
lines = [[[2.5, -1.5], [2.5, 1.5]]]
rocks = 8
seed = 5
[solver]
max_time_s = 4
[output]
rasters = ["speed", "energy", "jump_height", "passages", "deposits", "reach_probability"]
percentiles = [95, 50]
raster_format = "cog"
quicklook = false
report = false
)");
  std::string log;
  for (const char* threads : {"1", "2"})
    ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                             " --out " + (dir / (std::string("out") + threads)).string() +
                             " --threads " + threads,
                         &log),
              0)
        << log;
  const auto summary = nlohmann::json::parse(Slurp(dir / "out1" / "summary.json"));
  GDALAllRegister();
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir / "out1"))
    if (entry.path().extension() == ".tif") names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names.size(), 15u);  // 3 quantities x (max, mean, p50, p95) + 3 counts
  for (const char* name : {"speed_p50.tif", "energy_p95.tif", "jump_height_p50.tif"})
    EXPECT_TRUE(std::find(names.begin(), names.end(), name) != names.end()) << name;
  long passed_hole_or_beyond = 0;
  for (const std::string& name : names) {
    const fs::path path = dir / "out1" / name;
    EXPECT_TRUE(Slurp(path) == Slurp(dir / "out2" / name)) << name;
    GDALDataset* d = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
    ASSERT_NE(d, nullptr) << name;
    EXPECT_STREQ(d->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG") << name;
    const std::string quantity = d->GetMetadataItem("TALUS_QUANTITY");
    const std::string statistic = d->GetMetadataItem("TALUS_STATISTIC");
    const bool count = statistic == "count" || statistic == "fraction";
    EXPECT_EQ(count ? quantity : quantity + "_" + statistic, name.substr(0, name.size() - 4));
    EXPECT_EQ(d->GetMetadataItem("TALUS_INPUTS_SHA256"),
              summary["inputs_sha256"].get<std::string>());
    EXPECT_EQ(d->GetMetadataItem("TALUS_VERSION"), summary["talus_version"].get<std::string>());
    EXPECT_STREQ(d->GetMetadataItem("TALUS_ROCKS"), "8");
    EXPECT_STREQ(d->GetMetadataItem("TALUS_SEED"), "5");
    EXPECT_EQ(nlohmann::json::parse(d->GetMetadataItem("TALUS_GROUND")), summary["ground"]);
    GDALRasterBand* band = d->GetRasterBand(1);
    const std::map<std::string, std::string> units = {
        {"speed", "m/s"},      {"energy", "J"},       {"jump_height", "m"},
        {"passages", "count"}, {"deposits", "count"}, {"reach_probability", "1"}};
    EXPECT_EQ(band->GetUnitType(), units.at(quantity)) << name;
    if (statistic == "p95") {
      EXPECT_EQ(band->GetDescription(), quantity == "jump_height"
                                            ? "jump height, 95th percentile over passing rocks"
                                            : quantity + ", 95th percentile over passing rocks");
    }
    int has_nodata = 0;
    EXPECT_EQ(band->GetNoDataValue(&has_nodata), -9999.0) << name;
    EXPECT_TRUE(has_nodata) << name;
    // Counts are Int32 (exact, integer classes in GIS), the others Float32.
    EXPECT_EQ(band->GetRasterDataType(), statistic == "count" ? GDT_Int32 : GDT_Float32) << name;
    std::vector<float> v(30 * 12);
    ASSERT_EQ(band->RasterIO(GF_Read, 0, 0, 30, 12, v.data(), 30, 12, GDT_Float32, 0, 0), CE_None);
    GDALClose(d);
    long passed = 0, untouched = 0;
    for (int row = 0; row < 12; ++row)
      for (int column = 0; column < 30; ++column) {
        const float value =
            v[static_cast<std::size_t>(row) * 30 + static_cast<std::size_t>(column)];
        if (column >= 14 && column < 17 && row >= 4 && row < 7) {
          EXPECT_EQ(value, -9999.0f) << name << " in the hole at " << column << ", " << row;
        } else if (value == (count ? 0.0f : -9999.0f)) {
          ++untouched;
        } else {
          EXPECT_TRUE(count ? value > 0 : value != -9999.0f) << name;
          ++passed;
          if (name == "passages.tif" && column >= 13) passed_hole_or_beyond += long(value);
        }
      }
    if (name != "deposits.tif") {
      EXPECT_GT(passed, 10) << name;  // rocks passed: values
    }
    EXPECT_GT(untouched, 50) << name;  // no rock passed: 0 or nodata
  }
  EXPECT_GT(passed_hole_or_beyond, 0);  // rocks rolled up to the hole (and ended there)
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
  EXPECT_EQ(summary["solver"]["preset"], "default");
  EXPECT_EQ(summary["solver"]["tolerance_m_s"], 1e-3);

  // --preset fast: the solver options the run used, recorded in summary.json; a bad name is a
  // bad input.
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "fast").string() + " --rocks 1 --preset fast",
                       &log),
            0)
      << log;
  const auto fast = nlohmann::json::parse(Slurp(dir / "fast" / "summary.json"));
  EXPECT_EQ(fast["solver"]["preset"], "fast");
  EXPECT_EQ(fast["solver"]["preset_from"], "command line");
  EXPECT_EQ(fast["solver"]["tolerance_m_s"], 1e-2);
  EXPECT_EQ(summary["solver"]["preset_from"], "scene");
  // --preset accurate wins over the scene's own dt_s and says so.
  std::string pinned = kScene;
  pinned.replace(pinned.find("[solver]\n"), 9, "[solver]\ndt_s = 0.002\n");
  std::ofstream(dir / "pinned.toml") << pinned;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "pinned.toml").string() +
                           " --out " + (dir / "accurate").string() + " --rocks 1 --preset accurate",
                       &log),
            0)
      << log;
  EXPECT_NE(log.find("--preset accurate overrides the scene's dt_s = 0.002 -> 0.001"),
            std::string::npos)
      << log;
  const auto accurate = nlohmann::json::parse(Slurp(dir / "accurate" / "summary.json"));
  EXPECT_EQ(accurate["solver"]["dt_s"], 0.001);
  EXPECT_EQ(accurate["solver"]["tolerance_m_s"], 1e-7);
  EXPECT_EQ(accurate["solver"]["preset_overrode"][0], "dt_s = 0.002 -> 0.001");
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "bad").string() + " --preset quick",
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("--preset: unknown preset 'quick'"), std::string::npos) << log;
}

// --self-check N: the subsample's statistics at dt and dt/2 with their verdict, printed and in
// summary.json; refused for a part and for more rocks than the run has.
TEST(SimulateCommand, SelfCheckIsPrintedAndWrittenToTheSummary) {
  const fs::path dir = FreshDir("self_check");
  std::ofstream(dir / "scene.toml") << kScene;
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string() + " --rocks 2 --self-check 4",
                       &log),
            0)
      << log;
  EXPECT_NE(log.find("Self-check: "), std::string::npos) << log;
  const auto summary = nlohmann::json::parse(Slurp(dir / "out" / "summary.json"));
  const auto& check = summary["self_check"];
  EXPECT_EQ(check["rocks"], 4);
  EXPECT_EQ(check["refined_dt_s"], 0.001);
  EXPECT_EQ(check["statistics"][0]["name"], "run-out median");
  EXPECT_TRUE(check["verdict"].is_string());
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "part").string() + " --self-check 4 --rock-range 0:2",
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("--self-check: not with --rock-range"), std::string::npos) << log;
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "many").string() + " --rocks 1 --self-check 9",
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("--self-check 9: the run has"), std::string::npos) << log;
  // The scene may ask for it ([solver] self_check); --self-check wins over it.
  std::string asking = kScene;
  asking.replace(asking.find("[solver]\n"), 9, "[solver]\nself_check = 3\n");
  std::ofstream(dir / "asking.toml") << asking;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "asked").string() + " --rocks 2",
                       &log),
            0)
      << log;
  EXPECT_EQ(nlohmann::json::parse(Slurp(dir / "asked" / "summary.json"))["self_check"]["rocks"], 3);
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "given").string() + " --rocks 2 --self-check 4",
                       &log),
            0)
      << log;
  EXPECT_EQ(nlohmann::json::parse(Slurp(dir / "given" / "summary.json"))["self_check"]["rocks"], 4);
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "off").string() + " --rocks 2 --self-check 0",
                       &log),
            0)
      << log;
  EXPECT_FALSE(nlohmann::json::parse(Slurp(dir / "off" / "summary.json")).contains("self_check"));
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "bad").string() + " --self-check 1",
                       &log),
            2)
      << log;
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "few").string() + " --rocks 1",
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("[solver] self_check 3: the run has"), std::string::npos) << log;
  asking.replace(asking.find("self_check = 3"), 14, "self_check = 1");
  std::ofstream(dir / "asking.toml") << asking;
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "asking.toml").string() +
                           " --out " + (dir / "one").string(),
                       &log),
            2)
      << log;
  EXPECT_NE(log.find("solver.self_check: 1 must be 0 (none) or >= 2 rocks"), std::string::npos)
      << log;
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
  std::string all = kScene;  // with a percentile the next run does not ask for
  all.replace(all.find("rasters = ["), 0, "percentiles = [50, 95]\n");
  std::ofstream(dir / "all.toml") << all;
  std::ofstream(dir / "lean.toml") << LeanScene();
  const std::string out = (dir / "out").string();
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "all.toml").string() +
                           " --out " + out,
                       &log),
            0)
      << log;
  ASSERT_TRUE(fs::exists(dir / "out" / "trajectories.h5"));
  ASSERT_TRUE(fs::exists(dir / "out" / "speed_p95.tif"));
  ASSERT_TRUE(fs::exists(dir / "out" / "speed_p50.tif"));
  ASSERT_TRUE(fs::exists(dir / "out" / "rocks.gpkg"));  // on by default
  std::ofstream(dir / "out" / "notes.txt") << "the user's own file";
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "lean.toml").string() +
                           " --out " + out,
                       &log),
            0)
      << log;
  EXPECT_FALSE(fs::exists(dir / "out" / "trajectories.h5"));
  EXPECT_FALSE(fs::exists(dir / "out" / "speed_p95.tif"));
  EXPECT_FALSE(fs::exists(dir / "out" / "speed_p50.tif"));
  EXPECT_FALSE(fs::exists(dir / "out" / "quicklook.png"));
  EXPECT_FALSE(fs::exists(dir / "out" / "rocks.gpkg"));
  EXPECT_TRUE(fs::exists(dir / "out" / "rocks.csv"));
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "out" / "notes.txt"));
}

// --out holding the user's own files named like talus outputs (report.html, which a scene with
// report = false does not write; partial.json, which a whole run does not) and like a temporary
// file of a dead process: all stay. Only what the earlier run's manifest lists is removed.
TEST(SimulateCommand, AUsersFilesNamedLikeOutputsStay) {
  const fs::path dir = FreshDir("users_files");
  std::ofstream(dir / "lean.toml") << LeanScene() + "report = false\n";
  const fs::path out = dir / "out";
  fs::create_directories(out);
  const std::string dead = std::to_string(DeadPid());
  const std::vector<std::string> users_files = {"report.html", "partial.json", ".notes.tmp-" + dead,
                                                "notes.txt"};
  for (const std::string& name : users_files) std::ofstream(out / name) << "the user's own file";
  std::string log;
  ASSERT_EQ(RunCommand(Talus("simulate " + (dir / "lean.toml").string() + " --out " + out.string()),
                       &log),
            0)
      << log;
  EXPECT_EQ(log.find("Removed"), std::string::npos) << log;
  for (const std::string& name : users_files)
    EXPECT_EQ(Slurp(out / name), "the user's own file") << name;
  EXPECT_EQ(Slurp(out / ".talus-outputs"), "rocks.csv\nsummary.json\nrun.log\n");
  // The next run with a report removes nothing of the user's either; a third without one removes
  // the report the second wrote (its manifest lists it), not the user's partial.json.
  std::ofstream(dir / "report.toml") << LeanScene();
  ASSERT_EQ(
      RunCommand(Talus("simulate " + (dir / "report.toml").string() + " --out " + out.string()),
                 &log),
      0)
      << log;
  EXPECT_NE(Slurp(out / "report.html"), "the user's own file");
  ASSERT_EQ(RunCommand(Talus("simulate " + (dir / "lean.toml").string() + " --out " + out.string()),
                       &log),
            0)
      << log;
  EXPECT_NE(log.find("Removed 1 outputs of an earlier run"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(out / "report.html"));
  EXPECT_EQ(Slurp(out / "partial.json"), "the user's own file");
  EXPECT_EQ(Slurp(out / (".notes.tmp-" + dead)), "the user's own file");
}

// SIGINT or SIGTERM in the middle of a run: the workers stop, the temporary files go, the exit
// code is 128 + the signal, and an earlier run's outputs in the directory are untouched.
void InterruptARun(int signal, const std::string& name) {
  const fs::path dir = FreshDir(name);
  std::ofstream(dir / "scene.toml") << kScene;
  std::ofstream(dir / "slow.toml") << kSlowScene;
  const fs::path out = dir / "out";
  std::string log;
  ASSERT_EQ(
      RunCommand(Talus("simulate " + (dir / "scene.toml").string() + " --out " + out.string()),
                 &log),
      0)
      << log;
  const auto earlier = Snapshot(out);
  ASSERT_EQ(earlier.size(), 20u);  // with the list of outputs, .talus-outputs, and run.log

  const pid_t pid = StartTalus(
      {"simulate", (dir / "slow.toml").string(), "--out", out.string(), "--threads", "2"},
      dir / "log.txt");
  ASSERT_GT(pid, 0);
  // Interrupt once the run has written into its temporary trajectory file (about a second into
  // it; waited for, not timed, so that a loaded machine does not signal it too early).
  const fs::path staging = out / (".talus-run.talus-tmp-" + std::to_string(pid));
  const fs::path trajectories = staging / (".trajectories.h5.talus-tmp-" + std::to_string(pid));
  const auto writing = [&] {
    std::error_code error;
    return fs::exists(trajectories, error) && fs::file_size(trajectories, error) > 0 && !error;
  };
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(kHangSeconds);
  while (!writing() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const bool was_writing = writing();
  ::kill(pid, signal);
  const int status = WaitFor(pid, kHangSeconds);
  log = Slurp(dir / "log.txt");
  EXPECT_TRUE(was_writing) << "the run did not get to write its trajectories\n" << log;
  EXPECT_EQ(status, 128 + signal) << log;
  EXPECT_NE(log.find(std::string("talus simulate: interrupted by ") +
                     (signal == SIGINT ? "SIGINT" : "SIGTERM")),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("; removed this run's temporary files, " + out.string() +
                     " is as it was before the run"),
            std::string::npos)
      << log;
  EXPECT_EQ(Temporaries(out), std::vector<std::string>());
  EXPECT_TRUE(Snapshot(out) == earlier) << "the earlier run's outputs changed";
}

TEST(SimulateCommand, SigintStopsTheRunRemovesItsTemporariesAndExits130) {
  InterruptARun(SIGINT, "sigint");
}

TEST(SimulateCommand, SigtermStopsTheRunRemovesItsTemporariesAndExits143) {
  InterruptARun(SIGTERM, "sigterm");
}

// Out of space (a 64 MiB tmpfs, filled up once the run writes; needs root, skipped otherwise):
// one line naming the file and the reason, exit 1, no temporary file, and the earlier run's
// outputs as they were. (Filled before the run, the disk would fail the run's estimate instead.)
TEST(SimulateCommand, AFullDiskIsOneErrorAndLeavesTheEarlierRunAsItWas) {
  const fs::path dir = FreshDir("full");
  std::ofstream(dir / "scene.toml") << kScene;
  std::ofstream(dir / "lean.toml") << LeanScene();
  const fs::path disk = dir / "disk";
  fs::create_directories(disk);
  if (::mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=64m") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs at " << disk << " (" << std::strerror(errno)
                 << "); this test needs root";
  struct Unmount {
    const fs::path& path;
    ~Unmount() { ::umount2(path.c_str(), MNT_DETACH); }
  } unmount{disk};
  const fs::path out = disk / "out";
  std::string log;
  ASSERT_EQ(RunCommand(Talus("simulate " + (dir / "lean.toml").string() + " --out " + out.string()),
                       &log),
            0)
      << log;
  const auto earlier = Snapshot(out);
  const pid_t pid = StartTalus(
      {"simulate", (dir / "scene.toml").string(), "--out", out.string(), "--rocks", "500"},
      dir / "log.txt");
  ASSERT_GT(pid, 0);
  const fs::path trajectories = out / (".talus-run.talus-tmp-" + std::to_string(pid)) /
                                (".trajectories.h5.talus-tmp-" + std::to_string(pid));
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(kHangSeconds);
  while (!fs::exists(trajectories) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(fs::exists(trajectories)) << "the run did not get to write its trajectories";
  {  // Fill the disk.
    std::FILE* ballast = std::fopen((disk / "ballast").c_str(), "wb");
    ASSERT_NE(ballast, nullptr);
    const std::vector<char> block(1 << 16, 'x');
    while (std::fwrite(block.data(), 1, block.size(), ballast) == block.size()) {
    }
    std::fclose(ballast);
  }
  EXPECT_EQ(WaitFor(pid, kHangSeconds), 1);
  fs::remove(disk / "ballast");
  log = Slurp(dir / "log.txt");
  EXPECT_NE(log.find("talus simulate: cannot write rock "), std::string::npos) << log;
  EXPECT_NE(log.find((out / "trajectories.h5").string() + ": No space left on device"),
            std::string::npos)
      << log;
  int error_lines = 0;
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);)
    // All but the scene's description and the run's estimate.
    error_lines += line.rfind("Scene ", 0) != 0 && line.rfind("Needs about ", 0) != 0;
  EXPECT_EQ(error_lines, 1) << log;
  EXPECT_EQ(Temporaries(out), std::vector<std::string>());
  EXPECT_TRUE(Snapshot(out) == earlier) << "the earlier run's outputs changed";
}

// A file-size limit (`ulimit -f` sets the soft and the hard one) hit while trajectories.h5 is
// written: one error and exit 1, no output and no temporary file. The process crashed in HDF5's
// exit handler (SIGSEGV, exit 139) after the error; talus merge did the same.
TEST(SimulateCommand, AHardFileSizeLimitIsOneErrorNotACrash) {
  const fs::path dir = FreshDir("hard_file_size_limit");
  std::ofstream(dir / "scene.toml") << kScene;
  const fs::path out = dir / "out";
  std::string log;
  EXPECT_EQ(RunCommand("ulimit -f 40; exec " + Talus("simulate " + (dir / "scene.toml").string() +
                                                     " --rocks 40 --out " + out.string()),
                       &log),
            1)
      << log;
  EXPECT_NE(log.find("trajectories.h5: File too large (no output written)"), std::string::npos)
      << log;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << log;
}

TEST(SimulateCommand, RemovesTheTemporariesOfDeadRunsOnly) {
  const fs::path dir = FreshDir("stale_temporaries");
  std::ofstream(dir / "lean.toml") << LeanScene();
  const fs::path out = dir / "out";
  const std::string dead = std::to_string(DeadPid()), alive = std::to_string(::getpid());
  fs::create_directories(out / (".talus-run.talus-tmp-" + dead));
  std::ofstream(out / (".talus-run.talus-tmp-" + dead) / (".trajectories.h5.talus-tmp-" + dead))
      << "x";
  std::ofstream(out / (".rocks.csv.talus-tmp-" + dead)) << "x";
  std::ofstream(out / (".rocks.csv.talus-tmp-" + alive)) << "x";
  std::string log;
  ASSERT_EQ(RunCommand(Talus("simulate " + (dir / "lean.toml").string() + " --out " + out.string()),
                       &log),
            0)
      << log;
  EXPECT_NE(log.find("Removed 2 temporary files of interrupted runs"), std::string::npos) << log;
  EXPECT_EQ(Temporaries(out), std::vector<std::string>{".rocks.csv.talus-tmp-" + alive});
}

// More threads than a few per core only cost memory (10 000 threads took 854 MB on a toy scene).
TEST(TalusCommandLine, ThreadsAreCappedAtAFewPerCore) {
  const fs::path dir = FreshDir("threads_cap");
  std::ofstream(dir / "scene.toml") << LeanScene();
  const std::string cores = std::to_string(std::max(1u, std::thread::hardware_concurrency()));
  for (const char* verb : {"simulate", "validate", "calibrate"}) {
    std::string log;
    EXPECT_EQ(RunCommand(Talus(std::string(verb) + " " + (dir / "scene.toml").string() + " --out " +
                               (dir / "out").string() + " --threads 10000"),
                         &log),
              2)
        << log;
    EXPECT_NE(log.find("--threads: must be <= "), std::string::npos) << log;
    EXPECT_NE(
        log.find(", got 10000 (this machine has " + cores + " cores; at most 4 threads per core"),
        std::string::npos)
        << log;
  }
  std::string log;
  EXPECT_EQ(RunCommand(Talus("simulate " + (dir / "scene.toml").string() + " --out " +
                             (dir / "out").string() + " --threads 16"),
                       &log),
            0)
      << log;  // 16 are allowed on any machine
}

// Censored endings are said where the user looks: rocks still moving at max_time are a WARNING
// line on stderr, an entry of summary.json's "warnings" and the "Warnings" list at the top of
// report.html (ensemble/run_warnings.hpp; each rule has its own test in run_warnings_test.cpp).
// With --quiet too: warnings are never silenced.
TEST(SimulateCommand, RocksAtMaxTimeAreWarnedInTheConsoleTheSummaryAndTheReport) {
  const fs::path dir = FreshDir("max_time_warning");
  std::string scene = kScene;
  scene.replace(scene.find("max_time_s = 4"), 14, "max_time_s = 0.5");
  std::ofstream(dir / "scene.toml") << scene;
  const fs::path out = dir / "out";
  std::string log;
  ASSERT_EQ(RunCommand(Talus("simulate " + (dir / "scene.toml").string() + " --out " +
                             out.string() + " --threads 1 --quiet"),
                       &log),
            0)
      << log;
  const std::string expected = "6 of 6 rocks (100.0 %) were still moving at max_time_s = 0.5 s";
  EXPECT_NE(log.find("talus simulate: WARNING: " + expected), std::string::npos) << log;
  // --quiet: the warning and nothing else; run.log has what a run without it would have printed.
  EXPECT_EQ(log.rfind("talus simulate: WARNING: ", 0), 0u) << log;
  EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  const std::string run_log = Slurp(out / "run.log");
  for (const std::string& line :
       {std::string("command: "), std::string(" --quiet\n"), std::string("\nScene "),
        std::string("\nWrote "), "talus simulate: WARNING: " + expected,
        std::string("finished: exit 0")})
    EXPECT_NE(run_log.find(line), std::string::npos) << line << "\n" << run_log;
  const auto summary = nlohmann::json::parse(Slurp(out / "summary.json"));
  ASSERT_EQ(summary["warnings"].size(), 1u) << summary["warnings"];
  EXPECT_NE(summary["warnings"][0].get<std::string>().find(expected), std::string::npos);
  const std::string report = Slurp(out / "report.html");
  const auto warnings = report.find("<h2>Warnings</h2>");
  ASSERT_NE(warnings, std::string::npos);
  EXPECT_LT(warnings, report.find("<h2>What ran</h2>"));  // at the top
  EXPECT_NE(report.find("<li>" + expected, warnings), std::string::npos);
}

// The cap on a run's address space in ARunTooLargeForTheMachineIsRefusedBeforeAnyRock; none under
// AddressSanitizer, whose shadow memory reserves terabytes of address space.
#if defined(__SANITIZE_ADDRESS__)
const std::string kAddressSpaceCap;
#else
const std::string kAddressSpaceCap = "ulimit -v 16000000 && ";
#endif

// A run whose estimated memory or disk exceeds what the machine has is refused before any rock
// runs (exit 2, nothing written), with the estimate, what is available and the knob to turn. The
// run's address space is capped at 16 GB (ulimit -v, which the estimate honours), so the memory
// case is refused on a node with more than the estimate's 96 GB too (not under AddressSanitizer:
// there the machine's own memory decides).
TEST(SimulateCommand, ARunTooLargeForTheMachineIsRefusedBeforeAnyRock) {
  const fs::path dir = FreshDir("too_large");
  // 3500 x 1000 cells; 10^9 rocks, each assumed to cross the diagonal: the values behind the
  // percentile rasters, spilled to disk, about 58 TB (the per-cell summaries in memory are
  // bounded by the cells, 0.5 GB here).
  const std::string raster_scene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 300, runout_m = 50, width_m = 100, cell_m = 0.1 }
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
points = [[10, 0], [20, 0]]
rocks = 500000000
[output]
rasters = ["speed", "energy", "jump_height"]
)";
  // 10^9 rocks' trajectories of 100 s every 0.01 s, and their paths in rocks.gpkg: over a PB.
  std::string disk_scene = raster_scene;
  disk_scene.replace(disk_scene.find("rasters = "), std::string::npos,
                     "trajectories = true\nquicklook = false\n");
  struct Case {
    std::string scene, options;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {raster_scene, "",
       {"of disk, but ", "values behind the percentile rasters", "(fewer rocks (--rocks)",
        "nothing was run"}},
      // Two evaluation lines: the summary reads four doubles per rock and line back, 96 GB.
      {raster_scene +
           "[evaluation_lines]\nlines = [[[50, -10], [50, 10]], [[60, -10], [60, 10]]]\n",
       "",
       {"of memory besides the ", " is available (", "evaluation line values behind the summary",
        "(fewer rocks (--rocks)", "nothing was run"}},
      {disk_scene, "",
       {"the outputs need about ", " PB of disk, but ", "trajectories.h5 (10002 samples per rock",
        "(trajectories = false", "rocks.gpkg (geopackage = false", "nothing was run"}},
  };
  for (const auto& [text, options, parts] : cases) {
    std::ofstream(dir / "scene.toml") << text;
    const fs::path out = dir / "out";
    std::string log;
    EXPECT_EQ(RunCommand(kAddressSpaceCap + Talus("simulate " + (dir / "scene.toml").string() +
                                                  " --out " + out.string() + options),
                         &log),
              2)
        << log;
    for (const std::string& part : parts) EXPECT_NE(log.find(part), std::string::npos) << log;
    EXPECT_EQ(log.find("rocks in"), std::string::npos) << log;  // no rock ran
    EXPECT_TRUE(fs::is_empty(out)) << "nothing is written";
  }
}

// Exit codes: 2 for bad input or usage on every verb, with a message that says what is wrong.
TEST(TalusCommandLine, BadInputSaysWhatIsWrongAndExits2) {
  const fs::path dir = FreshDir("bad_input");
  std::ofstream(dir / "scene.toml") << kScene;
  std::ofstream(dir / "file") << "not a directory";
  const std::string scene = (dir / "scene.toml").string(), out = (dir / "out").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"simulate " + scene + " --out " + out + " --rocks 0", "--rocks: must be >= 1, got 0"},
      {"simulate " + scene + " --out " + out + " --rocks many", "--rocks: must be an integer"},
      {"simulate " + scene + " --out " + out + " --seed -1", "--seed: must be >= 0, got -1"},
      {"simulate " + scene + " --out " + out + " --threads -2", "--threads: must be >= 0"},
      {"simulate " + scene + " --out " + out + " --threads 10000",
       "--threads: must be <= "},  // and the machine's cores: a test below

      {"simulate " + dir.string() + " --out " + out,
       dir.string() + " is a directory, not a scene file (did you mean " + scene + "?)"},
      {"simulate " + scene + " --out " + (dir / "file" / "out").string(),
       "cannot create the output directory " + (dir / "file" / "out").string() +
           ": Not a directory"},
      {"simulate " + scene + " --out " + (dir / "file").string(), "exists and is not a directory"},
      {"simulate " + scene, "--out is required"},
      {"demo --seed -1", "--seed: must be >= 0, got -1"},
      {"rock info", "give a point cloud FILE or --builtin NAME"},
      {"rock info --builtin nope", "unknown built-in shape 'nope'"},
      {"rock hull " + (dir / "missing.ply").string() + " -o x.ply", "missing.ply"},
      {"frobnicate", "A subcommand is required"},
      {"", "A subcommand is required"},
  };
  for (const auto& [arguments, message] : cases) {
    std::string log;
    EXPECT_EQ(RunCommand(Talus(arguments), &log), 2) << arguments << "\n" << log;
    EXPECT_NE(log.find(message), std::string::npos) << arguments << "\n" << log;
  }
  EXPECT_FALSE(fs::exists(out));
  std::string log;
  EXPECT_EQ(RunCommand(Talus("--help"), &log), 0) << log;
  EXPECT_EQ(RunCommand(Talus("simulate --help"), &log), 0) << log;
}

}  // namespace

namespace talus::app {
namespace {

using talus::app::testing::RunCommand;

// The README's `talus rock` commands run on the example scan shipped in docs/examples
// (scripts/make_example_scan.py): 4000 points on the visible part of a rough boulder and 20 stray
// points, which the default cleaning must remove, leaving a hull of the boulder's size.
TEST(RockCommand, TheReadmesExampleScanIsReadAndItsStrayPointsRemoved) {
  const std::string scan = std::string(TALUS_SOURCE_DIR) + "/docs/examples/scan.ply";
  std::string log;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " rock info " + scan +
                           " --density 2650 --json 2>/dev/null",
                       &log),
            0)
      << log;
  const nlohmann::json info = nlohmann::json::parse(log);
  EXPECT_EQ(info["points_read"], 4020);
  EXPECT_EQ(info["cleaning"]["outliers"], 20);
  // The boulder's semi-axes 0.45 x 0.30 m (+- 8 % bumps) in plan; the strays reach 1.2 m.
  EXPECT_LT(info["dimensions_m"][0].get<double>(), 1.0);
  EXPECT_GT(info["dimensions_m"][0].get<double>(), 0.7);
  const std::string xyz = std::string(TALUS_SOURCE_DIR) + "/docs/examples/scan.xyz";
  const std::filesystem::path dir = talus::app::testing::FreshDir("rock", "example_scan");
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " rock hull " + xyz + " --max-vertices 64 -o " +
                           (dir / "hull.ply").string(),
                       &log),
            0)
      << log;
  EXPECT_TRUE(std::filesystem::exists(dir / "hull.ply"));
}

}  // namespace
}  // namespace talus::app
