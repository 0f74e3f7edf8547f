#include "io/event_file.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <tuple>

#include "common/closest_name.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/format.hpp"
#include "common/sha256.hpp"
#include "ensemble/release.hpp"
#include "fieldobs/single_impacts.hpp"
#include "io/toml_section.hpp"
#include "io/vector.hpp"

namespace talus::io {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kKinds = {"runout",       "deposits", "impacts",       "scars",
                                         "trajectories", "zones",    "single_impacts"};

// The column keys of a single_impacts observation table (defaults: SingleImpactColumns).
fieldobs::SingleImpactColumns SingleImpactColumnsOf(const Section& o) {
  fieldobs::SingleImpactColumns c;
  c.id = o.String("id_column", c.id);
  c.energy_ratio = o.String("energy_ratio_column", c.energy_ratio);
  c.speed_out = o.String("speed_out_column", c.speed_out);
  c.scar_depth = o.String("scar_depth_column", c.scar_depth);
  return c;
}

// "(the DEM covers x .. y ..)" of a scene, for messages about places off it.
std::string DemCover(const SceneFile& scene) {
  const GridGeometry& g = scene.scene.terrain.heights().grid;
  return "(the DEM covers x " + TenDigits(g.x0_m) + " .. " + TenDigits(g.x_max_m()) + ", y " +
         TenDigits(g.y0_m) + " .. " + TenDigits(g.y_max_m()) + ")";
}

// The header of a table, for messages: "a, b, c".
std::string ColumnsOf(const CsvTable& table) {
  std::string out;
  for (const std::string& c : table.columns()) out += (out.empty() ? "" : ", ") + c;
  return out;
}

}  // namespace

GroundTable ReferenceGround(const GroundTable& scene_ground, bool* differs) {
  const GroundTable builtin = GroundTable::BuiltIn();
  GroundTable out = scene_ground;
  bool changed = false;
  for (int k = 0; k < out.size(); ++k) {
    const int b = builtin.IndexOfName(out.category(k).name);
    if (b < 0) continue;
    const GroundParams& want = builtin.params(b);
    GroundParams& have = out.mutable_params(k);
    changed = changed || have.model != want.model;
    for (const GroundFieldInfo& f : kGroundFields)
      changed = changed || have.*f.member != want.*f.member;
    have = want;
  }
  if (differs) *differs = changed;
  return out;
}

namespace {

// [[zones]]: lines and polygons that zone observations refer to.
void LoadZones(const Context& context, const Section& top, EventFile& event) {
  const toml::node* zones = top.Node("zones");
  if (!zones) return;
  const toml::array* list = zones->as_array();
  if (!list) top.Fail("zones", "expected [[zones]] tables (id, line or polygon)");
  for (std::size_t k = 0; k < list->size(); ++k) {
    const std::string name = "zones[" + std::to_string(k) + "]";
    const toml::table* t = list->get(k)->as_table();
    if (!t) context.Fail(list->get(k), name, "expected a table (id, line or polygon)");
    const Section z(context, t, name, {"id", "line", "polygon"});
    fieldobs::Zone zone;
    if (!z.Has("id")) context.Fail(t, name + ".id", "missing");
    zone.id = z.String("id", "");
    for (const fieldobs::Zone& other : event.observations.zones)
      if (other.id == zone.id) z.Fail("id", "zone '" + zone.id + "' is defined twice");
    zone.polygon = z.Has("polygon");
    if (zone.polygon == z.Has("line"))
      context.Fail(t, name,
                   "give exactly one of line and polygon ([[x, y], ...], map coordinates)");
    const char* key = zone.polygon ? "polygon" : "line";
    const toml::array* points = z.Node(key)->as_array();
    if (!points) z.Fail(key, "expected a list of [x, y] points (finite, m)");
    for (std::size_t p = 0; p < points->size(); ++p) {
      const std::vector<double> xy =
          z.NumbersOf(points->get(p), z.Key(key) + "[" + std::to_string(p) + "]", 2);
      zone.points.emplace_back(xy[0], xy[1]);
    }
    if (zone.points.size() < (zone.polygon ? 3u : 2u))
      z.Fail(key,
             zone.polygon ? "a polygon needs at least 3 points" : "a line needs at least 2 points");
    // A zone no rock can reach would score its observations against no rock ('passed' = 0 as
    // perfect): an error (another CRS, swapped coordinates), as for evaluation lines.
    ensemble::ReleaseGeometry geometry;
    geometry.kind = zone.polygon ? ensemble::ReleaseGeometry::Kind::kPolygon
                                 : ensemble::ReleaseGeometry::Kind::kLine;
    geometry.rings = {zone.points};
    if (!(ensemble::FractionOnTerrain(event.scene.scene.terrain, geometry) > 0))
      z.Fail(key, "the zone '" + zone.id + "' lies entirely outside the DEM or on nodata " +
                      DemCover(event.scene) + ", so no rock can reach it");
    event.observations.zones.push_back(zone);
  }
}

// The keys of one [[observations]] table that depend on its kind; returns the kind.
std::string CheckObservationKeys(const Context& context, const toml::table* t, const Section& o) {
  for (const char* required : {"kind", "file"})
    if (!o.Has(required)) context.Fail(t, o.Key(required), "missing");
  const std::string kind = o.String("kind", "");
  if (std::find(kKinds.begin(), kKinds.end(), kind) == kKinds.end()) {
    const std::string hint = ClosestName(kind, kKinds);
    o.Fail("kind", "unknown kind '" + kind + "'" +
                       (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                       "; known: runout, deposits, impacts, scars, trajectories, zones, "
                       "single_impacts");
  }
  for (const char* key :
       {"id_column", "energy_ratio_column", "speed_out_column", "scar_depth_column"})
    if (o.Has(key) && kind != "single_impacts")
      o.Fail(key, "only single_impacts tables take " + std::string(key));
  if (o.Has("run_column") && kind == "single_impacts")
    o.Fail("run_column", "single_impacts name their runs by id_column (default impact_id)");
  return kind;
}

// Rest positions as points of a vector file, placed in the DEM's CRS.
void ReadDepositVector(const Context& context, const Section& o, const std::string& file,
                       const fieldobs::TableColumns& columns, EventFile& event) {
  const auto points = ReadDepositPoints(file, event.scene.crs_wkt, columns.run,
                                        context.Where(o.Node("file")) + ": " + o.Key("file"));
  // A point without a run has no field run_column (a present field's empty value is an error).
  if (o.Has("run_column"))
    for (const fieldobs::DepositObservation& d : points)
      if (d.run.empty()) o.Fail("run_column", d.where + " has no field '" + columns.run + "'");
  event.observations.deposits.insert(event.observations.deposits.end(), points.begin(),
                                     points.end());
}

// The observations of one CSV table, read by the reader of its kind.
void ReadObservationCsv(const Section& o, const std::string& kind, const std::string& file,
                        const fieldobs::TableColumns& columns, const CsvTable* omega_samples,
                        EventFile& event) {
  const CsvTable table = CsvTable::Read(file);
  // Without its run column every row would be an observation of the whole scene: a run column
  // named on purpose must be there.
  if (o.Has("run_column") && !table.Has(columns.run))
    o.Fail("run_column", file + " has no column '" + columns.run +
                             "' (the header has: " + ColumnsOf(table) + ")");
  fieldobs::ObservationSet& into = event.observations;
  if (kind == "runout") fieldobs::ReadRunouts(table, columns, into);
  if (kind == "deposits") fieldobs::ReadDeposits(table, columns, into);
  if (kind == "impacts") fieldobs::ReadImpacts(table, columns, into, omega_samples);
  if (kind == "scars") fieldobs::ReadScars(table, columns, into);
  if (kind == "trajectories")
    fieldobs::ReadTrajectories(table, columns, event.scene.scene.terrain, into);
  if (kind == "zones") fieldobs::ReadZoneObservations(table, columns, into);
  if (kind == "single_impacts")
    fieldobs::ReadSingleImpactOutcomes(table, SingleImpactColumnsOf(o), into);
}

// One [[observations]] table (kind, file, ...): its observations and input files join `event`.
void LoadObservationTable(const Context& context, const toml::node* node, const std::string& name,
                          EventFile& event) {
  const toml::table* t = node->as_table();
  if (!t) context.Fail(node, name, "expected a table (kind, file)");
  const Section o(context, t, name,
                  {"kind", "file", "run_column", "omega_from", "id_column", "energy_ratio_column",
                   "speed_out_column", "scar_depth_column"});
  const std::string kind = CheckObservationKeys(context, t, o);
  const std::string file = context.Resolve(o.String("file", ""));
  if (!fs::exists(file)) o.Fail("file", "file not found: " + file);
  fieldobs::TableColumns columns;
  columns.run = o.String("run_column", columns.run);
  // Impacts: the angular speed after each impact from the next segment's first sample.
  std::optional<CsvTable> omega_samples;
  std::string omega_file;
  if (o.Has("omega_from")) {
    if (kind != "impacts")
      o.Fail("omega_from", "only impacts take omega_from (a table of trajectory samples)");
    omega_file = context.Resolve(o.String("omega_from", ""));
    if (!fs::exists(omega_file)) o.Fail("omega_from", "file not found: " + omega_file);
    omega_samples = CsvTable::Read(omega_file);
  }
  const std::size_t before = event.observations.size();
  const std::string extension = fs::path(file).extension().string();
  const bool csv = extension == ".csv" || extension == ".txt";
  if (!csv && kind != "deposits")
    o.Fail("file",
           file + ": " + kind + " observations are CSV tables (.csv); vector files hold deposits");
  if (csv)
    ReadObservationCsv(o, kind, file, columns, omega_samples ? &*omega_samples : nullptr, event);
  else
    ReadDepositVector(context, o, file, columns, event);
  if (event.observations.size() == before) o.Fail("file", file + " holds no observation");
  event.needs_episodes =
      event.needs_episodes || kind == "impacts" || kind == "scars" || kind == "single_impacts";
  for (const std::string& input : {file, omega_file})
    if (!input.empty() &&
        std::find(event.inputs.begin(), event.inputs.end(), input) == event.inputs.end())
      event.inputs.push_back(input);
}

// Every observation's run must be a run of the scene.
void CheckObservationRuns(const EventFile& event) {
  std::set<std::string> runs;
  const ensemble::ReleaseSpec& release = event.scene.release;
  for (long r = 0; r < release.release_count(); ++r)
    runs.insert(release.ReleaseName(static_cast<int>(r)));
  const auto check = [&](const std::string& run, const std::string& where) {
    if (!run.empty() && !runs.count(run))
      throw InputError(
          where + ": run '" + run + "' is not a run of the scene " + event.scene.path +
          (release.runs.empty() ? " (it has no run table; runs are named 0, 1, ...)" : ""));
  };
  for (const auto& o : event.observations.scalars) check(o.run, o.where);
  for (const auto& o : event.observations.deposits) check(o.run, o.where);
}

// A run is one release of one block: each quantity of it (at each zone) was observed once. A
// second row would count twice, or contradict the first; observations of the whole scene (no
// run) may repeat.
void CheckObservedOnce(const fieldobs::ObservationSet& observations) {
  std::map<std::tuple<fieldobs::Quantity, std::string, int>, std::string> first_scalar;
  for (const auto& o : observations.scalars) {
    if (o.run.empty()) continue;
    if (const auto [at, added] =
            first_scalar.emplace(std::tuple(o.quantity, o.run, o.zone), o.where);
        !added)
      throw InputError(
          o.where + ": run '" + o.run + "' has a second " + fieldobs::ToString(o.quantity) +
          " observation" +
          (o.zone >= 0
               ? " at zone '" + observations.zones[static_cast<std::size_t>(o.zone)].id + "'"
               : std::string()) +
          " (the first: " + at->second + "); a run's quantity is observed once");
  }
  std::map<std::string, std::string> first_deposit;
  for (const auto& o : observations.deposits) {
    if (o.run.empty()) continue;
    if (const auto [at, added] = first_deposit.emplace(o.run, o.where); !added)
      throw InputError(o.where + ": run '" + o.run + "' has a second rest position (the first: " +
                       at->second + "); a run's block rests at one place");
  }
}

// A rest position off the terrain is one no rock can reach: another CRS or swapped coordinates.
void CheckDepositsOnTerrain(const EventFile& event) {
  for (const auto& o : event.observations.deposits)
    if (!ensemble::OnTerrain(event.scene.scene.terrain, o.xy_m))
      throw InputError(o.where + ": the rest position (" + TenDigits(o.xy_m.x()) + ", " +
                       TenDigits(o.xy_m.y()) + ") is outside the DEM or on nodata " +
                       DemCover(event.scene) + ", so no rock can rest there");
}

// The hash (SHA-256) covers the event file, the observation tables and the scene's own hash.
std::string InputsHash(const EventFile& event) {
  Sha256 hash;
  for (std::size_t k = 0; k < event.inputs.size() - event.scene.inputs.size(); ++k) {
    std::ifstream in(event.inputs[k], std::ios::binary);
    hash.AddStream(in);
  }
  hash.Add(event.scene.inputs_hash);
  return hash.HexDigest();
}

}  // namespace

EventFile LoadEvent(const std::string& path) {
  const toml::table root = ParseTomlFile(path, "event file");
  const Context context(path);
  const Section top(context, &root, "", {"scene", "reference", "observations", "zones"});

  EventFile event;
  event.path = path;
  if (!top.Has("scene")) context.Fail(&root, "scene", "missing");
  const std::string scene = context.Resolve(top.String("scene", ""));
  try {
    event.scene = LoadScene(scene);
  } catch (const InputError& e) {
    throw InputError(context.Where(top.Node("scene")) + ": scene: " + e.what());
  }
  event.reference = top.String("reference", "table1");
  if (event.reference != "table1" && event.reference != "none")
    top.Fail("reference", "'" + event.reference + "': expected \"table1\" or \"none\"");

  LoadZones(context, top, event);

  const toml::node* list = top.Node("observations");
  if (!list) context.Fail(&root, "observations", "missing: give [[observations]] tables");
  const toml::array* tables = list->as_array();
  if (!tables || tables->empty())
    top.Fail("observations", "expected [[observations]] tables (kind, file)");
  event.inputs.push_back(path);
  for (std::size_t k = 0; k < tables->size(); ++k)
    LoadObservationTable(context, tables->get(k), "observations[" + std::to_string(k) + "]", event);

  CheckObservationRuns(event);
  CheckObservedOnce(event.observations);
  CheckDepositsOnTerrain(event);

  for (const std::string& input : event.scene.inputs) event.inputs.push_back(input);
  event.inputs_hash = InputsHash(event);
  return event;
}

}  // namespace talus::io
