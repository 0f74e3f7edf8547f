// [[barriers]] of a scene file (io/scene_barriers.cpp) through io::LoadScene: the keys become
// Scene::barriers (capacity in kJ to J), a vector file gives one barrier per line feature, and bad
// input is an error naming the file, line and key before any rock runs.

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// A 60 x 30 m plane (x 0 .. 60, y -15 .. 15, 1 m cells); its [[barriers]] table is on line 10, its
// keys from line 11.
const std::string kScene = R"([terrain]
plane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[rock]
shape = { box = [0.5, 0.4, 0.3] }

[release]
points = [[5, 0]]

[[barriers]]
)";

const std::string kNet = R"(name = "net"
type = "flexible_net"
line = [[30, -10], [30, 10]]
height_m = 3
)";

std::string ErrorOf(const std::string& table) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", kScene + table);
  try {
    LoadScene((dir / "scene.toml").string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(SceneBarriers, KeysBecomeTheScenesBarriers) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml",
                     kScene + kNet + "capacity_kj = 500\n" +
                         "[[barriers]]\nname = \"wall\"\ntype = \"rigid_wall\"\n"
                         "line = [[40, -10], [42, 0], [40, 10]]\n"
                         "height_m = 0\ncapacity_kj = 2000.5\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.barriers.size(), 2u);
  const Barrier& net = s.scene.barriers[0];
  EXPECT_EQ(net.name, "net");
  EXPECT_EQ(net.type, BarrierType::kFlexibleNet);
  EXPECT_EQ(net.height_m, 3);
  EXPECT_EQ(net.capacity_J, 500000);
  EXPECT_EQ(net.vertices_m.back(), Eigen::Vector2d(30, 10));
  const Barrier& wall = s.scene.barriers[1];
  EXPECT_EQ(wall.type, BarrierType::kRigidWall);
  EXPECT_EQ(wall.height_m, 0);  // a barrier of no height stops only what touches the ground
  EXPECT_EQ(wall.capacity_J, 2000500);
  ASSERT_EQ(wall.vertices_m.size(), 3u);
}

TEST(SceneBarriers, AVectorFileGivesOneBarrierPerLineFeature) {
  const auto dir = testing::FreshDir("scene");
  std::ofstream(dir / "nets.geojson") << R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"name": "upper"},
 "geometry": {"type": "LineString", "coordinates": [[20, -10], [20, 10]]}},
{"type": "Feature", "properties": {"name": "lower"},
 "geometry": {"type": "LineString", "coordinates": [[50, -10], [50, 10]]}}]})";
  testing::WriteText(dir / "scene.toml", kScene +
                                             "file = \"nets.geojson\"\ntype = \"dam\"\n"
                                             "height_m = 6\ncapacity_kj = 50000\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.barriers.size(), 2u);
  EXPECT_EQ(s.scene.barriers[0].name, "upper");
  EXPECT_EQ(s.scene.barriers[1].name, "lower");
  EXPECT_EQ(s.scene.barriers[1].type, BarrierType::kDam);
  EXPECT_EQ(s.scene.barriers[1].capacity_J, 5e7);
}

// height_field, capacity_field and type_field: each line feature's own height (m), capacity (kJ)
// and type from its attributes (a number stored as text is read too), replacing the table's keys;
// a table key still applies where no field is named.
TEST(SceneBarriers, EachFeatureOfAFileCarriesItsOwnHeightCapacityAndType) {
  const auto dir = testing::FreshDir("scene");
  std::ofstream(dir / "nets.geojson") << R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"name": "upper", "h": 3.5, "cap": 500, "kind": "flexible_net"},
 "geometry": {"type": "LineString", "coordinates": [[20, -10], [20, 10]]}},
{"type": "Feature", "properties": {"name": "lower", "h": 6, "cap": "5000", "kind": "dam"},
 "geometry": {"type": "MultiLineString", "coordinates": [[[50, -10], [50, 0]], [[52, 0], [52, 10]]]}}]})";
  testing::WriteText(dir / "scene.toml", kScene +
                                             "file = \"nets.geojson\"\nheight_field = \"h\"\n"
                                             "capacity_field = \"cap\"\ntype_field = \"kind\"\n");
  SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.barriers.size(), 3u);  // the multi-line gives one barrier per part
  EXPECT_EQ(s.scene.barriers[1].name, "lower part 1");
  EXPECT_EQ(s.scene.barriers[2].name, "lower part 2");
  const Barrier& upper = s.scene.barriers[0];
  EXPECT_EQ(upper.name, "upper");
  EXPECT_EQ(upper.type, BarrierType::kFlexibleNet);
  EXPECT_EQ(upper.height_m, 3.5);
  EXPECT_EQ(upper.capacity_J, 500e3);
  for (int k : {1, 2}) {
    const Barrier& lower = s.scene.barriers[static_cast<std::size_t>(k)];
    EXPECT_EQ(lower.type, BarrierType::kDam);
    EXPECT_EQ(lower.height_m, 6);
    EXPECT_EQ(lower.capacity_J, 5000e3);
  }
  // Capacity per feature, height and type from the table.
  testing::WriteText(dir / "scene.toml",
                     kScene +
                         "file = \"nets.geojson\"\nname_field = \"name\"\n"
                         "capacity_field = \"cap\"\nheight_m = 4\ntype = \"rigid_wall\"\n");
  s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.barriers.size(), 3u);
  EXPECT_EQ(s.scene.barriers[0].capacity_J, 500e3);
  EXPECT_EQ(s.scene.barriers[2].capacity_J, 5000e3);
  EXPECT_EQ(s.scene.barriers[2].height_m, 4);
  EXPECT_EQ(s.scene.barriers[2].type, BarrierType::kRigidWall);
}

TEST(SceneBarriers, AFeaturesMissingOrNonPositiveAttributeIsAnErrorNamingFileFeatureAndField) {
  const auto dir = testing::FreshDir("scene");
  auto error = [&](const std::string& properties, const std::string& table) -> std::string {
    std::ofstream(dir / "nets.geojson") << R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"name": "a", "h": 4, "cap": 500, "kind": "dam"},
 "geometry": {"type": "LineString", "coordinates": [[20, -10], [20, 10]]}},
{"type": "Feature", "properties": )" + properties +
                                               R"(,
 "geometry": {"type": "LineString", "coordinates": [[50, -10], [50, 10]]}}]})";
    testing::WriteText(dir / "scene.toml", kScene + "file = \"nets.geojson\"\n" + table);
    try {
      LoadScene((dir / "scene.toml").string());
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  const std::string fields =
      "height_field = \"h\"\ncapacity_field = \"cap\"\ntype_field = \"kind\"\n";
  const std::string good = R"({"name": "b", "h": 4, "cap": 500, "kind": "dam"})";
  EXPECT_EQ(error(good, fields), "");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": 0, "kind": "dam"})", fields),
             "scene.toml:11: barriers[0].file (");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": 0, "kind": "dam"})", fields),
             "nets.geojson, feature 1): attribute 'cap' is 0: the capacity must be a number > 0 "
             "and <= 1000000 kJ");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": -20, "kind": "dam"})", fields),
             "feature 1): attribute 'cap' is -20: the capacity must be a number > 0");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": "lots", "kind": "dam"})", fields),
             "feature 1): attribute 'cap' is lots: the capacity must be a number");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": null, "kind": "dam"})", fields),
             "feature 1): attribute 'cap' is empty");
  EXPECT_HAS(error(R"({"name": "b", "h": 0, "cap": 500, "kind": "dam"})", fields),
             "feature 1): attribute 'h' is 0: the height must be a number > 0 and <= 100 m (a "
             "barrier only rocks touching the ground meet: height_m = 0 in its own table)");
  EXPECT_HAS(error(R"({"name": "b", "h": -3, "cap": 500, "kind": "dam"})", fields),
             "feature 1): attribute 'h' is -3: the height must be a number > 0");
  EXPECT_HAS(error(R"({"name": "b", "h": 4, "cap": 500, "kind": "fence"})", fields),
             "feature 1): attribute 'kind' is 'fence', not a barrier type");
  EXPECT_HAS(error(good, "height_field = \"height\"\ncapacity_kj = 500\ntype = \"dam\"\n"),
             "feature 0): no attribute 'height' (the attributes are: name, h, cap, kind)");
  EXPECT_HAS(error(good, fields + "capacity_kj = 500\n"),
             "barriers[0].capacity_kj: give capacity_kj or capacity_field (each feature's own), "
             "not both");
  EXPECT_HAS(ErrorOf(kNet + "capacity_field = \"cap\"\n"),
             "barriers[0].capacity_field: only the line features of a vector file ('file') have "
             "attributes");
}

TEST(SceneBarriers, BadInputIsAnErrorNamingFileLineAndKey) {
  EXPECT_HAS(ErrorOf(kNet + "capacity_kj = 0\n"),
             "scene.toml:15: barriers[0].capacity_kj: 0 kJ: the capacity must be > 0 kJ");
  EXPECT_HAS(ErrorOf(kNet + "capacity_kj = -500\n"),
             "scene.toml:15: barriers[0].capacity_kj: -500 kJ: the capacity must be > 0 kJ");
  EXPECT_HAS(ErrorOf("name = \"net\"\ntype = \"flexible_net\"\nline = [[30, -10], [30, 10]]\n"
                     "height_m = -2\ncapacity_kj = 500\n"),
             "scene.toml:14: barriers[0].height_m: -2 m: the height must be >= 0 m");
  EXPECT_HAS(ErrorOf("name = \"net\"\ntype = \"fence\"\nline = [[30, -10], [30, 10]]\n"
                     "height_m = 2\ncapacity_kj = 500\n"),
             "scene.toml:12: barriers[0].type: unknown barrier type 'fence': expected "
             "\"flexible_net\", \"rigid_wall\" or \"dam\"");
  EXPECT_HAS(ErrorOf("name = \"net\"\ntype = \"flexible_net\"\nline = [[30, -10]]\n"
                     "height_m = 2\ncapacity_kj = 500\n"),
             "scene.toml:13: barriers[0].line: a barrier needs at least 2 points, it has 1");
  EXPECT_HAS(ErrorOf("name = \"net\"\ntype = \"flexible_net\"\nline = [[30, -10], [30, 40]]\n"
                     "height_m = 2\ncapacity_kj = 500\n"),
             "scene.toml:13: barriers[0].line: the barrier 'net' is off the DEM or on nodata at "
             "(30, 15.5)");
  EXPECT_HAS(ErrorOf("name = \"net\"\ntype = \"flexible_net\"\nline = [[300, -10], [300, 10]]\n"
                     "height_m = 2\ncapacity_kj = 500\n"),
             "every part of a barrier must lie on the DEM");
  EXPECT_HAS(ErrorOf("name = \"net\"\nline = [[30, -10], [30, 10]]\nheight_m = 2\n"
                     "capacity_kj = 500\n"),
             "barriers[0].type: missing");
  EXPECT_HAS(ErrorOf(kNet), "barriers[0].capacity_kj: missing");
  EXPECT_HAS(ErrorOf(kNet + "capacity_kj = 500\nheight = 3\n"),
             "barriers[0].height: unknown key (did you mean 'height_m'?)");
  EXPECT_HAS(ErrorOf(kNet + "capacity_kj = 500\n[[barriers]]\n" + kNet + "capacity_kj = 50\n"),
             "the name 'net' is also that of");
  EXPECT_HAS(ErrorOf("type = \"dam\"\nheight_m = 2\ncapacity_kj = 500\n"),
             "barriers[0].line: give either a line");
}

}  // namespace
}  // namespace talus::io
