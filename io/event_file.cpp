#include "io/event_file.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "io/vector.hpp"

namespace talus::io {
namespace {

namespace fs = std::filesystem;

std::string Line(const std::string& file, const toml::node* node) {
  if (node && node->source().begin.line > 0)
    return file + ":" + std::to_string(node->source().begin.line);
  return file;
}

[[noreturn]] void Fail(const std::string& file, const toml::node* node, const std::string& key,
                       const std::string& reason) {
  throw InputError(Line(file, node) + ": " + key + ": " + reason);
}

std::string StringKey(const std::string& file, const toml::table& t, const std::string& key,
                      const std::string& name, bool required, const std::string& fallback = "") {
  const toml::node* node = t.get(key);
  if (!node) {
    if (required) Fail(file, &t, name, "missing");
    return fallback;
  }
  if (!node->is_string()) Fail(file, node, name, "expected a string");
  return std::string(*node->value<std::string>());
}

const std::vector<std::string> kKinds = {"runout", "deposits",     "impacts",
                                         "scars",  "trajectories", "zones"};

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
    changed = changed || have.mu_min != want.mu_min || have.mu_max != want.mu_max ||
              have.beta_1_s != want.beta_1_s || have.kappa_1_m != want.kappa_1_m ||
              have.nu_1_s != want.nu_1_s;
    have = want;
  }
  if (differs) *differs = changed;
  return out;
}

EventFile LoadEvent(const std::string& path) {
  if (!fs::exists(path)) throw InputError(path + ": event file not found");
  if (fs::is_directory(path)) throw InputError(path + ": is a directory, not an event file");
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(path + ":" + std::to_string(e.source().begin.line) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
  const fs::path dir = fs::path(path).parent_path();
  const auto resolve = [&](const std::string& p) {
    const fs::path q(p);
    return (q.is_absolute() ? q : dir / q).lexically_normal().string();
  };
  for (const auto& [key, node] : root) {
    const std::string k(key.str());
    if (k != "scene" && k != "reference" && k != "observations" && k != "zones") {
      const std::string hint = ClosestName(k, {"scene", "reference", "observations", "zones"});
      Fail(path, &node, k, "unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
    }
  }

  EventFile event;
  event.path = path;
  const std::string scene = resolve(StringKey(path, root, "scene", "scene", true));
  try {
    event.scene = LoadScene(scene);
  } catch (const InputError& e) {
    throw InputError(Line(path, root.get("scene")) + ": scene: " + e.what());
  }
  event.reference = StringKey(path, root, "reference", "reference", false, "table1");
  if (event.reference != "table1" && event.reference != "none")
    Fail(path, root.get("reference"), "reference",
         "'" + event.reference + "': expected \"table1\" or \"none\"");

  // [[zones]]: lines and polygons that zone observations refer to.
  if (const toml::node* zones = root.get("zones")) {
    const toml::array* list = zones->as_array();
    if (!list) Fail(path, zones, "zones", "expected [[zones]] tables (id, line or polygon)");
    for (std::size_t k = 0; k < list->size(); ++k) {
      const std::string name = "zones[" + std::to_string(k) + "]";
      const toml::table* t = list->get(k)->as_table();
      if (!t) Fail(path, list->get(k), name, "expected a table (id, line or polygon)");
      for (const auto& [key, node] : *t) {
        const std::string key_name(key.str());
        if (key_name != "id" && key_name != "line" && key_name != "polygon") {
          const std::string hint = ClosestName(key_name, {"id", "line", "polygon"});
          Fail(path, &node, name + "." + key_name,
               "unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
        }
      }
      fieldobs::Zone zone;
      zone.id = StringKey(path, *t, "id", name + ".id", true);
      for (const fieldobs::Zone& other : event.observations.zones)
        if (other.id == zone.id)
          Fail(path, t->get("id"), name + ".id", "zone '" + zone.id + "' is defined twice");
      zone.polygon = t->get("polygon") != nullptr;
      if (zone.polygon == (t->get("line") != nullptr))
        Fail(path, t, name,
             "give exactly one of line and polygon ([[x, y], ...], map coordinates)");
      const char* key = zone.polygon ? "polygon" : "line";
      const toml::array* points = t->get(key)->as_array();
      const auto bad = [&] {
        Fail(path, t->get(key), name + "." + key, "expected a list of [x, y] points (finite, m)");
      };
      if (!points) bad();
      for (const toml::node& p : *points) {
        const toml::array* xy = p.as_array();
        if (!xy || xy->size() != 2) bad();
        const auto x = xy->get(0)->value<double>(), y = xy->get(1)->value<double>();
        if (!x || !y || !std::isfinite(*x) || !std::isfinite(*y)) bad();
        zone.points.emplace_back(*x, *y);
      }
      if (zone.points.size() < (zone.polygon ? 3u : 2u))
        Fail(path, t->get(key), name + "." + key,
             zone.polygon ? "a polygon needs at least 3 points" : "a line needs at least 2 points");
      event.observations.zones.push_back(zone);
    }
  }

  const toml::node* list = root.get("observations");
  if (!list) Fail(path, &root, "observations", "missing: give [[observations]] tables");
  const toml::array* tables = list->as_array();
  if (!tables || tables->empty())
    Fail(path, list, "observations", "expected [[observations]] tables (kind, file)");
  event.inputs.push_back(path);
  for (std::size_t k = 0; k < tables->size(); ++k) {
    const std::string name = "observations[" + std::to_string(k) + "]";
    const toml::table* t = tables->get(k)->as_table();
    if (!t) Fail(path, tables->get(k), name, "expected a table (kind, file)");
    for (const auto& [key, node] : *t) {
      const std::string key_name(key.str());
      if (key_name != "kind" && key_name != "file" && key_name != "run_column" &&
          key_name != "omega_from") {
        const std::string hint =
            ClosestName(key_name, {"kind", "file", "run_column", "omega_from"});
        Fail(path, &node, name + "." + key_name,
             "unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
      }
    }
    const std::string kind = StringKey(path, *t, "kind", name + ".kind", true);
    if (std::find(kKinds.begin(), kKinds.end(), kind) == kKinds.end()) {
      const std::string hint = ClosestName(kind, kKinds);
      Fail(path, t->get("kind"), name + ".kind",
           "unknown kind '" + kind + "'" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
               "; known: runout, deposits, impacts, scars, trajectories, zones");
    }
    const std::string file = resolve(StringKey(path, *t, "file", name + ".file", true));
    if (!fs::exists(file)) Fail(path, t->get("file"), name + ".file", "file not found: " + file);
    fieldobs::TableColumns columns;
    columns.run = StringKey(path, *t, "run_column", name + ".run_column", false, columns.run);
    // Impacts: the angular speed after each impact from the next segment's first sample.
    std::optional<CsvTable> omega_samples;
    std::string omega_file;
    if (t->get("omega_from")) {
      if (kind != "impacts")
        Fail(path, t->get("omega_from"), name + ".omega_from",
             "only impacts take omega_from (a table of trajectory samples)");
      omega_file = resolve(StringKey(path, *t, "omega_from", name + ".omega_from", true));
      if (!fs::exists(omega_file))
        Fail(path, t->get("omega_from"), name + ".omega_from", "file not found: " + omega_file);
      omega_samples = CsvTable::Read(omega_file);
    }
    const std::size_t before = event.observations.size();
    const std::string extension = fs::path(file).extension().string();
    const bool csv = extension == ".csv" || extension == ".txt";
    if (!csv && kind != "deposits")
      Fail(path, t->get("file"), name + ".file",
           file + ": " + kind + " observations are CSV tables (.csv); vector files hold deposits");
    if (!csv) {
      // Rest positions as points of a vector file, placed in the DEM's CRS.
      const auto points = ReadDepositPoints(file, event.scene.crs_wkt, columns.run,
                                            Line(path, t->get("file")) + ": " + name + ".file");
      event.observations.deposits.insert(event.observations.deposits.end(), points.begin(),
                                         points.end());
    } else {
      const CsvTable table = CsvTable::Read(file);
      if (kind == "runout") fieldobs::ReadRunouts(table, columns, event.observations);
      if (kind == "deposits") fieldobs::ReadDeposits(table, columns, event.observations);
      if (kind == "impacts")
        fieldobs::ReadImpacts(table, columns, event.observations,
                              omega_samples ? &*omega_samples : nullptr);
      if (kind == "scars") fieldobs::ReadScars(table, columns, event.observations);
      if (kind == "trajectories")
        fieldobs::ReadTrajectories(table, columns, event.scene.scene.terrain, event.observations);
      if (kind == "zones") fieldobs::ReadZoneObservations(table, columns, event.observations);
    }
    if (event.observations.size() == before)
      Fail(path, t->get("file"), name + ".file", file + " holds no observation");
    event.needs_episodes = event.needs_episodes || kind == "impacts" || kind == "scars";
    for (const std::string& input : {file, omega_file})
      if (!input.empty() &&
          std::find(event.inputs.begin(), event.inputs.end(), input) == event.inputs.end())
        event.inputs.push_back(input);
  }

  // Every observation's run must be a run of the scene.
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

  for (const std::string& input : event.scene.inputs) event.inputs.push_back(input);
  // The hash covers the event file, the observation tables and the scene's own hash.
  std::uint64_t h = 1469598103934665603ULL;
  const auto mix = [&](const std::string& bytes) {
    for (unsigned char c : bytes) {
      h ^= c;
      h *= 1099511628211ULL;
    }
  };
  for (std::size_t k = 0; k < event.inputs.size() - event.scene.inputs.size(); ++k) {
    std::ifstream in(event.inputs[k], std::ios::binary);
    mix(std::string(std::istreambuf_iterator<char>(in), {}));
  }
  mix(event.scene.inputs_hash);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  event.inputs_hash = hex;
  return event;
}

}  // namespace talus::io
