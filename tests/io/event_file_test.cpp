// Event files: observation tables by kind, rest positions from vector files in the DEM's CRS, the
// impacts' angular speed from a table of trajectory samples (omega_from), and errors before any
// rock runs.

#include "io/event_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/error.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

std::string ErrorOf(const std::filesystem::path& event) {
  try {
    LoadEvent(event.string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A 20 x 20 cell DEM of 10 m cells in UTM 32N (EPSG:32632) near Innsbruck, flat, and two runs.
std::filesystem::path MakeEvent(const std::string& name, int dem_epsg) {
  auto dir = testing::FreshDir(name);
  std::vector<std::vector<double>> rows(20, std::vector<double>(20, 600.0));
  testing::WriteGdalRaster(dir / "dem.tif", rows, {680000, 10, 0, 5240200, 0, -10}, dem_epsg,
                           std::nullopt);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\ndem = \"dem.tif\"\n[rock]\nshape = { box = [0.5, 0.5, 0.5] }\n"
                     "[release]\nruns = \"runs.csv\"\n");
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m\nA,680050,5240150\nB,680100,5240100\n");
  return dir;
}

TEST(LoadEvent, TablesOfEveryKindAndTheirRuns) {
  const auto dir = MakeEvent("kinds", 32632);
  testing::WriteText(dir / "obs.csv",
                     "trajectory_id,x_m,y_m,observed_runout_m,scar_length_m\n"
                     "A,680060,5240100,50,1.5\nB,680120,5240060,44,\n");
  testing::WriteText(dir / "impacts.csv",
                     "trajectory_id,incoming_speed_mps,outgoing_speed_mps\nA,10,5\n");
  testing::WriteText(dir / "event.toml", R"(scene = "scene.toml"
[[observations]]
kind = "runout"
file = "obs.csv"
[[observations]]
kind = "deposits"
file = "obs.csv"
[[observations]]
kind = "scars"
file = "obs.csv"
[[observations]]
kind = "impacts"
file = "impacts.csv"
)");
  const EventFile e = LoadEvent((dir / "event.toml").string());
  EXPECT_EQ(e.observations.scalars.size(), 2u + 1u + 2u);  // runouts, scar (B empty), impact
  EXPECT_EQ(e.observations.deposits.size(), 2u);
  EXPECT_TRUE(e.needs_episodes);
  EXPECT_EQ(e.reference, "table1");
  // The event, two tables (obs.csv once), the scene and its inputs.
  EXPECT_EQ(e.inputs.size(), 3u + e.scene.inputs.size());
  EXPECT_EQ(e.inputs_hash.size(), 64u);  // SHA-256, hex
}

TEST(LoadEvent, RestPositionsFromAVectorFileAreReprojectedToTheDem) {
  // The points are stored in WGS 84 (GeoJSON's default CRS); the DEM is in UTM 32N. The positions
  // must arrive in the DEM's coordinates: the reference values come from a direct OGR
  // transformation, to 1 mm.
  const auto dir = MakeEvent("vector", 32632);
  OGRSpatialReference utm, wgs;
  utm.importFromEPSG(32632);
  wgs.importFromEPSG(4326);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> to_wgs(
      OGRCreateCoordinateTransformation(&utm, &wgs));
  double x = 680060, y = 5240100;
  ASSERT_TRUE(to_wgs->Transform(1, &x, &y));
  char text[512];
  std::snprintf(text, sizeof text,
                R"({"type": "FeatureCollection", "features": [{"type": "Feature",
 "properties": {"trajectory_id": "B", "radius_m": 2.5},
 "geometry": {"type": "Point", "coordinates": [%.12f, %.12f]}}]})",
                x, y);
  testing::WriteText(dir / "deposits.geojson", text);
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"deposits\"\nfile = "
                     "\"deposits.geojson\"\n");
  const EventFile e = LoadEvent((dir / "event.toml").string());
  ASSERT_EQ(e.observations.deposits.size(), 1u);
  const auto& d = e.observations.deposits[0];
  EXPECT_EQ(d.run, "B");
  EXPECT_NEAR(d.xy_m.x(), 680060, 1e-3);
  EXPECT_NEAR(d.xy_m.y(), 5240100, 1e-3);
  ASSERT_TRUE(d.radius_m.has_value());
  EXPECT_EQ(*d.radius_m, 2.5);
}

TEST(LoadEvent, ACrsTheDemLacksIsAnError) {
  // A GeoPackage-like CRS (explicit EPSG:31287 in the GeoJSON) over a DEM without CRS.
  const auto dir = MakeEvent("no_crs", 0);
  testing::WriteText(dir / "deposits.geojson",
                     R"({"type": "FeatureCollection", "crs": {"type": "name", "properties":
 {"name": "urn:ogc:def:crs:EPSG::31287"}}, "features": [{"type": "Feature", "properties": {},
 "geometry": {"type": "Point", "coordinates": [680060, 5240100]}}]})");
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"deposits\"\nfile = "
                     "\"deposits.geojson\"\n");
  EXPECT_HAS(ErrorOf(dir / "event.toml"),
             "event.toml:4: observations[0].file: " + (dir / "deposits.geojson").string() +
                 " has a CRS but the DEM has none");
}

TEST(LoadEvent, BadEventsNameFileLineAndKey) {
  const auto dir = MakeEvent("bad", 32632);
  testing::WriteText(dir / "obs.csv", "trajectory_id,observed_runout_m\nA,50\nC,3\n");
  const auto write = [&](const std::string& text) {
    testing::WriteText(dir / "event.toml", text);
    return ErrorOf(dir / "event.toml");
  };
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"obs.csv\"\n"),
             "obs.csv:3: run 'C' is not a run of the scene");
  EXPECT_HAS(
      write("scene = \"none.toml\"\n[[observations]]\nkind = \"runout\"\nfile = \"obs.csv\"\n"),
      "event.toml:1: scene: ");
  EXPECT_HAS(write("scene = \"scene.toml\"\n"), "observations: missing");
  EXPECT_HAS(write("scene = \"scene.toml\"\nsceen = 1\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"obs.csv\"\n"),
             "event.toml:2: sceen: unknown key (did you mean 'scene'?)");
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"nothing.csv\"\n"),
             "event.toml:4: observations[0].file: file not found");
  EXPECT_HAS(write("scene = \"scene.toml\"\nreference = \"table2\"\n[[observations]]\nkind = "
                   "\"runout\"\nfile = \"obs.csv\"\n"),
             "event.toml:2: reference: 'table2': expected \"table1\" or \"none\"");
  testing::WriteText(dir / "empty.csv", "trajectory_id,observed_runout_m\n");
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"empty.csv\"\n"),
             "holds no observation");
}

TEST(LoadEvent, ZonesAreLinesOrPolygonsThatZoneObservationsName) {
  const auto dir = MakeEvent("zones", 32632);
  testing::WriteText(dir / "zones.csv", "trajectory_id,zone_id,quantity,value\nA,fence,passed,1\n");
  const auto write = [&](const std::string& zones) {
    testing::WriteText(dir / "event.toml", "scene = \"scene.toml\"\n" + zones +
                                               "[[observations]]\nkind = \"zones\"\n"
                                               "file = \"zones.csv\"\n");
    return ErrorOf(dir / "event.toml");
  };
  EXPECT_EQ(write("[[zones]]\nid = \"fence\"\nline = [[680000, 5240100], [680200, 5240100]]\n"),
            "");
  const EventFile e = LoadEvent((dir / "event.toml").string());
  ASSERT_EQ(e.observations.zones.size(), 1u);
  EXPECT_FALSE(e.observations.zones[0].polygon);
  EXPECT_EQ(e.observations.scalars.size(), 1u);
  EXPECT_HAS(write("[[zones]]\nid = \"fence\"\nline = [[0, 0]]\n"),
             "event.toml:4: zones[0].line: a line needs at least 2 points");
  EXPECT_HAS(write("[[zones]]\nid = \"fence\"\nline = [[0, 0], [1, 1]]\npolygon = [[0, 0], [1, "
                   "0], [1, 1]]\n"),
             "zones[0]: give exactly one of line and polygon");
  EXPECT_HAS(write("[[zones]]\nid = \"fence\"\nlne = [[0, 0], [1, 1]]\n"),
             "zones[0].lne: unknown key (did you mean 'line'?)");
  EXPECT_HAS(write(""),
             "zones.csv:2: column 'zone_id': unknown zone 'fence' (the event's zones: none)");
}

// talus validate scored, with no word, rest positions and a zone off the terrain (another CRS,
// swapped coordinates: no rock can get there), every row of a table whose run_column it lacks as
// an observation of the whole scene, and a run listed twice twice. Each is an error naming the
// file and line or key; repeated observations of the whole scene (no run) are not.
TEST(LoadEvent, ObservationsNoRockCanReachOrOfAMisnamedOrRepeatedRunAreErrors) {
  const auto dir = MakeEvent("unreachable", 32632);
  const auto write = [&](const std::string& observations, const std::string& zones = "") {
    testing::WriteText(dir / "event.toml", "scene = \"scene.toml\"\n" + zones + observations);
    return ErrorOf(dir / "event.toml");
  };
  const std::string obs = (dir / "obs.csv").string();
  // (a) A rest position 5 km north of the DEM (x 680000 .. 680200, y 5240000 .. 5240200).
  testing::WriteText(dir / "obs.csv",
                     "trajectory_id,x_m,y_m\nA,680060,5240100\nB,680060,5245100\n");
  EXPECT_HAS(write("[[observations]]\nkind = \"deposits\"\nfile = \"obs.csv\"\n"),
             obs +
                 ":3: the rest position (680060, 5245100) is outside the DEM or on nodata (the "
                 "DEM covers x 680005 .. 680195, y 5240005 .. 5240195)");
  // (b) A zone line, and a polygon, 4 km off.
  testing::WriteText(dir / "zones.csv", "trajectory_id,zone_id,quantity,value\nA,fence,passed,0\n");
  const std::string zone_obs = "[[observations]]\nkind = \"zones\"\nfile = \"zones.csv\"\n";
  EXPECT_HAS(write(zone_obs,
                   "[[zones]]\nid = \"fence\"\nline = [[684000, 5240000], [684000, "
                   "5240200]]\n"),
             "event.toml:4: zones[0].line: the zone 'fence' lies entirely outside the DEM");
  EXPECT_HAS(write(zone_obs,
                   "[[zones]]\nid = \"fence\"\npolygon = [[684000, 5240000], [684100, "
                   "5240000], [684100, 5240100]]\n"),
             "event.toml:4: zones[0].polygon: the zone 'fence' lies entirely outside the DEM");
  EXPECT_EQ(write(zone_obs,
                  "[[zones]]\nid = \"fence\"\npolygon = [[679000, 5239000], [681000, "
                  "5239000], [681000, 5241000], [679000, 5241000]]\n"),
            "");  // around the whole DEM
  // (c) run_column naming a column the table lacks; without run_column the default's absence
  // still means observations of the whole scene.
  testing::WriteText(dir / "obs.csv", "trajectory_id,observed_runout_m\nA,50\nB,44\n");
  EXPECT_HAS(write("[[observations]]\nkind = \"runout\"\nfile = \"obs.csv\"\nrun_column = "
                   "\"run\"\n"),
             "event.toml:5: observations[0].run_column: " + obs +
                 " has no column 'run' (the header has: trajectory_id, observed_runout_m)");
  testing::WriteText(dir / "scene_obs.csv", "observed_runout_m\n50\n50\n44\n");
  EXPECT_EQ(write("[[observations]]\nkind = \"runout\"\nfile = \"scene_obs.csv\"\n"), "");
  // (d) A run listed twice, in one table or in two.
  testing::WriteText(dir / "obs.csv", "trajectory_id,observed_runout_m\nA,50\nB,44\nA,80\n");
  EXPECT_HAS(write("[[observations]]\nkind = \"runout\"\nfile = \"obs.csv\"\n"),
             obs + ":4: run 'A' has a second runout observation (the first: " + obs + ":2)");
  testing::WriteText(dir / "obs.csv", "trajectory_id,observed_runout_m\nA,50\n");
  testing::WriteText(dir / "more.csv", "trajectory_id,observed_runout_m\nA,50\n");
  EXPECT_HAS(write("[[observations]]\nkind = \"runout\"\nfile = \"obs.csv\"\n"
                   "[[observations]]\nkind = \"runout\"\nfile = \"more.csv\"\n"),
             "more.csv:2: run 'A' has a second runout observation");
  testing::WriteText(dir / "obs.csv",
                     "trajectory_id,x_m,y_m\nA,680060,5240100\nA,680070,5240100\n");
  EXPECT_HAS(write("[[observations]]\nkind = \"deposits\"\nfile = \"obs.csv\"\n"),
             obs + ":3: run 'A' has a second rest position (the first: " + obs + ":2)");
}

TEST(ReferenceGround, Table1ValuesForBuiltInCategoriesOnly) {
  GroundTable table = GroundTable::BuiltIn();
  bool differs = true;
  ReferenceGround(table, &differs);
  EXPECT_FALSE(differs);
  table.mutable_params(table.IndexOfName("hard")).mu_min = 0.9;
  const int user = table.Set({"scree", 20, GroundParams{0.5, 1.5, 100, 2, 0.3}});
  const GroundTable reference = ReferenceGround(table, &differs);
  EXPECT_TRUE(differs);
  EXPECT_EQ(reference.params(reference.IndexOfName("hard")).mu_min, 0.55);
  EXPECT_EQ(reference.params(user).mu_min, 0.5);  // user categories unchanged
}

// Two flight segments of one block on a plane; the impact ends segment s0 and starts s1.
std::filesystem::path MakeEventDir(const std::string& name, const std::string& observations) {
  auto dir = testing::FreshDir(name);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = {}\n[rock]\nshape = { box = [0.4, 0.4, 0.4] }\n"
                     "[release]\nruns = \"runs.csv\"\n");
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m\ns0,10,0\ns1,12,0\n");
  testing::WriteText(dir / "contacts.csv",
                     "trajectory_id,next_segment_id,incoming_vx_mps,incoming_vy_mps,"
                     "incoming_vz_mps,outgoing_vx_mps,outgoing_vy_mps,outgoing_vz_mps\n"
                     "s0,s1,3,0,-4,2,0,0\n");
  testing::WriteText(dir / "samples.csv",
                     "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\n"
                     "s0,0,1,0,0\ns1,0,0,6,8\ns1,0.1,0,0,1\n");
  testing::WriteText(dir / "event.toml", "scene = \"scene.toml\"\n" + observations);
  return dir;
}

std::string ErrorOfDir(const std::filesystem::path& dir) {
  try {
    LoadEvent((dir / "event.toml").string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LoadEvent, ImpactsTakeTheirAngularSpeedFromTrajectorySamples) {
  const auto dir = MakeEventDir("omega_from",
                                "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                "omega_from = \"samples.csv\"\n");
  const EventFile event = LoadEvent((dir / "event.toml").string());
  ASSERT_EQ(event.observations.scalars.size(), 3u);
  const fieldobs::ScalarObservation& omega = event.observations.scalars[2];
  EXPECT_EQ(omega.quantity, fieldobs::Quantity::kImpactAngularSpeedOut);
  EXPECT_EQ(omega.run, "s0");
  EXPECT_NEAR(omega.value, 10.0, 1e-12);  // |(0, 6, 8)|, s1's first sample
  EXPECT_TRUE(event.needs_episodes);
  const auto has_input = [&](const char* file) {
    return std::any_of(event.inputs.begin(), event.inputs.end(), [&](const std::string& input) {
      return std::filesystem::path(input).filename() == file;
    });
  };
  EXPECT_TRUE(has_input("samples.csv"));  // hashed with the other tables
  // Without omega_from the same table gives speed and energy ratio only.
  const auto plain = MakeEventDir(
      "omega_plain", "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n");
  EXPECT_EQ(LoadEvent((plain / "event.toml").string()).observations.scalars.size(), 2u);
}

TEST(LoadEvent, OmegaFromErrorsNameFileLineAndKey) {
  EXPECT_HAS(
      ErrorOfDir(MakeEventDir("omega_runout",
                              "[[observations]]\nkind = \"runout\"\nfile = \"contacts.csv\"\n"
                              "omega_from = \"samples.csv\"\n")),
      "event.toml:5: observations[0].omega_from: only impacts take omega_from");
  EXPECT_HAS(
      ErrorOfDir(MakeEventDir("omega_missing",
                              "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                              "omega_from = \"nothere.csv\"\n")),
      "event.toml:5: observations[0].omega_from: file not found: ");
  EXPECT_HAS(
      ErrorOfDir(MakeEventDir("omega_typo",
                              "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                              "omega_form = \"samples.csv\"\n")),
      "observations[0].omega_form: unknown key (did you mean 'omega_from'?)");
  const auto dir = MakeEventDir("omega_unknown_segment",
                                "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                "omega_from = \"samples.csv\"\n");
  testing::WriteText(
      dir / "samples.csv",
      "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\ns0,0,1,0,0\n");
  EXPECT_HAS(ErrorOfDir(dir),
             "contacts.csv:2: column 'next_segment_id': segment 's1' has no sample");
}

}  // namespace
}  // namespace talus::io

namespace talus::io {
namespace {

// A 30 deg plane scene whose runs are the impacts of impacts.csv (with `release` as the
// single_impacts table) and an event scoring them (`observation`: extra keys).
std::filesystem::path MakeSingleImpacts(const std::string& name, const std::string& release,
                                        const std::string& observation, const std::string& table) {
  auto dir = testing::FreshDir(name);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = { slope_deg = 30, slope_length_m = 40, runout_m = 10, "
                     "width_m = 20, cell_m = 1 }\n[rock]\nshape = { box = [0.5, 0.5, 0.5] }\n"
                     "[release]\nsingle_impacts = " +
                         release + "\nrocks = 4\n");
  testing::WriteText(dir / "impacts.csv", table);
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"single_impacts\"\n"
                     "file = \"impacts.csv\"\n" +
                         observation);
  return dir;
}

const char* kImpacts =
    "impact_id,incoming_total_speed_mps,impact_angle_deg,ratio,depth_m\n"
    "i1,20,30,0.4,0.1\ni2,15,10,0.6,0.05\n";

TEST(LoadEvent, SingleImpactsAreRunsOnThePlaneAndObservationsOfTheirFirstEpisode) {
  const auto dir = MakeSingleImpacts("single_impacts", "{ file = \"impacts.csv\" }",
                                     "energy_ratio_column = \"ratio\"\n"
                                     "scar_depth_column = \"depth_m\"\n",
                                     kImpacts);
  const EventFile event = LoadEvent((dir / "event.toml").string());
  const ensemble::ReleaseSpec& release = event.scene.release;
  ASSERT_EQ(release.runs.size(), 2u);
  EXPECT_EQ(release.runs[1].id, "i2");
  EXPECT_EQ(release.runs[0].xy_m, Eigen::Vector2d(20, 0));  // the middle of the slope
  EXPECT_NEAR(release.runs[0].velocity_m_s.norm(), 20, 1e-12);
  EXPECT_EQ(release.height_reference, ensemble::ReleaseSpec::HeightReference::kLowestPoint);
  EXPECT_FALSE(release.runs[0].orientation);  // random per rock
  const auto fixed = MakeSingleImpacts("single_impacts_fixed",
                                       "{ file = \"impacts.csv\" }\norientation = [0, 1, 0, 0]",
                                       "energy_ratio_column = \"ratio\"\n", kImpacts);
  const EventFile flipped = LoadEvent((fixed / "event.toml").string());
  // Every impact's rocks take [release] orientation (the runs have none of their own).
  const ensemble::ReleaseSpec& f = flipped.scene.release;
  EXPECT_FALSE(f.runs[1].orientation);
  ASSERT_TRUE(f.orientation);
  const ensemble::ReleasedRock rock =
      ensemble::Release(flipped.scene.scene, f, f.rocks_per_release);
  EXPECT_EQ(f.ReleaseOf(f.rocks_per_release), 1);
  const Eigen::Quaterniond shape =
      rock.start.orientation * rock.shape->principal_to_input.conjugate();
  EXPECT_NEAR(std::abs(shape.dot(Eigen::Quaterniond(0, 1, 0, 0))), 1.0, 1e-12);
  EXPECT_TRUE(event.needs_episodes);
  ASSERT_EQ(event.observations.scalars.size(), 4u);  // energy ratios and scar depths
  EXPECT_EQ(event.observations.scalars[1].run, "i2");
  EXPECT_EQ(event.observations.scalars[1].value, 0.6);
  EXPECT_EQ(event.observations.scalars[3].quantity, fieldobs::Quantity::kImpactScarDepth);
  EXPECT_EQ(event.observations.scalars[3].value, 0.05);
  EXPECT_TRUE(event.not_scored.empty());
}

TEST(LoadEvent, SingleImpactErrorsNameFileLineAndKey) {
  const auto error = [](const std::string& name, const std::string& release,
                        const std::string& observation, const std::string& table = kImpacts) {
    return ErrorOf(MakeSingleImpacts(name, release, observation, table) / "event.toml");
  };
  const std::string file = "{ file = \"impacts.csv\" }";
  const std::string ratio = "energy_ratio_column = \"ratio\"\n";
  EXPECT_HAS(error("si_no_outcome", file, ""), "no observed outcome: give the column energy_ratio");
  EXPECT_HAS(error("si_run_column", file, ratio + "run_column = \"impact_id\"\n"),
             "run_column: single_impacts name their runs by id_column");
  EXPECT_HAS(error("si_angle", file, ratio,
                   "impact_id,incoming_total_speed_mps,impact_angle_deg,ratio\ni1,20,91,0.4\n"),
             "impacts.csv:2: column 'impact_angle_deg': impact angle 91 deg is outside (0, 90]");
  EXPECT_HAS(error("si_key", "{ file = \"impacts.csv\", clearance = 0.1 }", ratio),
             "release.single_impacts.clearance");
  EXPECT_HAS(error("si_off", "{ file = \"impacts.csv\", at = [100, 0] }", ratio),
             "release.single_impacts.at: (100, 0) is outside the DEM");
  EXPECT_HAS(error("si_missing", "{ file = \"missing.csv\" }", ratio), "file not found");
  EXPECT_HAS(error("si_height", file + "\nheight_m = 2", ratio),
             "release.height_m: a single-impact table sets each run's start");
  EXPECT_HAS(error("si_points", file + "\npoints = [[5, 0]]", ratio),
             "release.single_impacts: a single-impact table cannot be combined with points");
  // Over a DEM the point of the impacts must be given.
  const auto dem = MakeEvent("si_dem", 32632);
  testing::WriteText(dem / "impacts.csv", kImpacts);
  testing::WriteText(dem / "scene.toml",
                     "[terrain]\ndem = \"dem.tif\"\n[rock]\nshape = { box = [0.5, 0.5, 0.5] }\n"
                     "[release]\nsingle_impacts = { file = \"impacts.csv\" }\n");
  std::string dem_error;
  try {
    LoadScene((dem / "scene.toml").string());
  } catch (const InputError& e) {
    dem_error = e.what();
  }
  EXPECT_HAS(dem_error, "release.single_impacts.at: missing: give the point [x, y] of the DEM");
  // An impact the scene does not release is not a run of it.
  EXPECT_HAS(ErrorOf([&] {
               const auto dir = MakeSingleImpacts("si_unknown", file, ratio, kImpacts);
               testing::WriteText(dir / "observed.csv", "impact_id,ratio\ni3,0.5\n");
               testing::WriteText(dir / "event.toml",
                                  "scene = \"scene.toml\"\n[[observations]]\nkind = "
                                  "\"single_impacts\"\nfile = \"observed.csv\"\n" +
                                      ratio);
               return dir / "event.toml";
             }()),
             "observed.csv:2: run 'i3' is not a run of the scene");
}

}  // namespace
}  // namespace talus::io
