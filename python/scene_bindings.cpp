// talus.Scene: a scene file loaded and validated as talus simulate loads it, its ground table,
// release and solver options changed from Python, and its rocks run -- one with its trajectory,
// or an ensemble with per-rock results and rasters -- by the same library calls as the program,
// so the numbers are the program's to the bit.

#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>

#include "common/error.hpp"
#include "ensemble/run_warnings.hpp"
#include "ensemble/runner.hpp"
#include "io/raster.hpp"
#include "io/rocks_csv.hpp"
#include "io/scene_file.hpp"
#include "io/summary.hpp"
#include "python/common.hpp"

namespace talus::python {
namespace {

// A Python value as a TOML node: bool, int, float, str, list (of tables: an array of tables) and
// dict (a table). `key` names it in errors.
toml::table TableOf(const py::dict& values, const std::string& where);

void Insert(toml::array& array, const py::handle& value, const std::string& where);

template <class Put>
void PutValue(const py::handle& value, const std::string& where, Put&& put) {
  if (py::isinstance<py::bool_>(value)) {
    put(toml::value<bool>(value.cast<bool>()));
  } else if (py::isinstance<py::int_>(value)) {
    put(toml::value<std::int64_t>(value.cast<std::int64_t>()));
  } else if (py::isinstance<py::float_>(value)) {
    put(toml::value<double>(value.cast<double>()));
  } else if (py::isinstance<py::str>(value)) {
    put(toml::value<std::string>(value.cast<std::string>()));
  } else if (py::isinstance<py::dict>(value)) {
    put(TableOf(value.cast<py::dict>(), where));
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    toml::array array;
    for (const py::handle item : value) Insert(array, item, where);
    put(std::move(array));
  } else if (py::hasattr(value, "__fspath__")) {
    put(toml::value<std::string>(py::str(value.attr("__fspath__")()).cast<std::string>()));
  } else if (py::hasattr(value, "item")) {  // a NumPy scalar
    PutValue(value.attr("item")(), where, put);
  } else {
    throw InputError(where + ": a value of type " +
                     py::str(value.get_type().attr("__name__")).cast<std::string>() +
                     " has no TOML form (bool, int, float, str, list or dict)");
  }
}

void Insert(toml::array& array, const py::handle& value, const std::string& where) {
  PutValue(value, where, [&array](auto&& node) { array.push_back(std::move(node)); });
}

toml::table TableOf(const py::dict& values, const std::string& where) {
  toml::table table;
  for (const auto& [key, value] : values) {
    if (!py::isinstance<py::str>(key)) throw InputError(where + ": keys must be str");
    const std::string name = key.cast<std::string>();
    const std::string here = where.empty() ? name : where + "." + name;
    PutValue(value, here, [&](auto&& node) { table.insert_or_assign(name, std::move(node)); });
  }
  return table;
}

std::string PathText(const py::object& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

// Keeps the scene valid after an edit: on failure the edit is undone and `what` raised.
template <class Edit>
void EditScene(io::SceneFile& file, const std::string& what, Edit&& edit) {
  const io::SceneFile before = file;
  try {
    edit(file);
    std::string why;
    if (!file.scene.IsValid(&why)) throw InputError(what + ": " + why);
    if (!file.release.IsValid(&why)) throw InputError(what + ": " + why);
  } catch (...) {
    file = before;
    throw;
  }
}

void SetGround(io::SceneFile& file, const std::string& category, const py::kwargs& fields) {
  GroundTable& table = file.scene.ground;
  const int index = table.IndexOfName(category);
  if (index < 0) {
    std::string known;
    for (int k = 0; k < table.size(); ++k)
      known += (k ? ", " : "") + table.category(k).name;
    throw InputError("set_ground: no ground category '" + category + "' in the scene; known: " +
                     known);
  }
  EditScene(file, "set_ground", [&](io::SceneFile& f) {
    GroundParams& params = f.scene.ground.mutable_params(index);
    for (const auto& [key, value] : fields) {
      const std::string name = key.cast<std::string>();
      const GroundFieldInfo* field = FindGroundField(name);
      if (!field) {
        std::string known;
        for (const GroundFieldInfo& info : kGroundFields)
          known += (known.empty() ? "" : ", ") + std::string(info.key);
        throw InputError("set_ground: " + category + "." + name + ": no such field; known: " + known);
      }
      const double v = value.cast<double>();
      if (!std::isfinite(v))
        throw InputError("set_ground: " + category + "." + name + ": not a finite number");
      params.*(field->member) = v;
    }
    std::string why;
    if (!f.scene.ground.IsValid(&why)) throw InputError("set_ground: " + why);
  });
}

py::dict SolverDict(const SolverOptions& o) {
  py::dict d;
  d["dt_s"] = o.dt_s;
  d["max_time_s"] = o.max_time_s;
  d["tolerance_m_s"] = o.tolerance_m_s;
  d["max_iterations"] = o.max_iterations;
  return d;
}

void SetSolver(io::SceneFile& file, const py::kwargs& options) {
  EditScene(file, "set_solver", [&](io::SceneFile& f) {
    SolverOptions& o = f.scene.options;
    for (const auto& [key, value] : options) {
      const std::string name = key.cast<std::string>();
      if (name == "dt_s") {
        o.dt_s = value.cast<double>();
      } else if (name == "max_time_s") {
        o.max_time_s = value.cast<double>();
      } else if (name == "tolerance_m_s") {
        o.tolerance_m_s = value.cast<double>();
      } else if (name == "max_iterations") {
        o.max_iterations = value.cast<int>();
      } else {
        throw InputError("set_solver: " + name +
                         ": not a solver option here (dt_s, max_time_s, tolerance_m_s, "
                         "max_iterations; the scene file's [solver] takes the others)");
      }
    }
  });
}

// The trajectory of one rock as arrays.
py::dict TrajectoryDict(const std::vector<ensemble::TrajectorySample>& samples) {
  const auto n = static_cast<py::ssize_t>(samples.size());
  py::array_t<double> t(n), scar(n);
  py::array_t<double> position({n, py::ssize_t{3}}), velocity({n, py::ssize_t{3}}),
      angular({n, py::ssize_t{3}}), quaternion({n, py::ssize_t{4}});
  py::array_t<bool> contact(n);
  auto tt = t.mutable_unchecked<1>();
  auto ss = scar.mutable_unchecked<1>();
  auto pp = position.mutable_unchecked<2>();
  auto vv = velocity.mutable_unchecked<2>();
  auto ww = angular.mutable_unchecked<2>();
  auto qq = quaternion.mutable_unchecked<2>();
  auto cc = contact.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const ensemble::TrajectorySample& s = samples[static_cast<std::size_t>(i)];
    tt(i) = s.t_s;
    ss(i) = s.scar_m;
    cc(i) = s.contact;
    for (py::ssize_t k = 0; k < 3; ++k) {
      pp(i, k) = s.position_m[k];
      vv(i, k) = s.velocity_m_s[k];
      ww(i, k) = s.angular_velocity_rad_s[k];
    }
    qq(i, 0) = s.orientation.w();
    qq(i, 1) = s.orientation.x();
    qq(i, 2) = s.orientation.y();
    qq(i, 3) = s.orientation.z();
  }
  py::dict d;
  d["t"] = t;
  d["position"] = position;
  d["quaternion"] = quaternion;
  d["velocity"] = velocity;
  d["angular_velocity"] = angular;
  d["contact"] = contact;
  d["scar"] = scar;
  return d;
}

// Collects what the Python call returns, rock by rock in rock order (on the calling thread).
class CollectingSink : public ensemble::RockSink {
 public:
  CollectingSink(const io::SceneFile& file, bool trajectories)
      : file_(file), trajectories_(trajectories) {}
  void OnRock(const ensemble::RockOutcome& outcome) override {
    rows.push_back(io::RockRowOf(outcome, file_.scene, file_.release));
    if (trajectories_) samples.push_back(outcome.trajectory);
    for (const BarrierEvent& e : outcome.result.barrier_events) barriers.emplace_back(outcome.rock, e);
    for (const ensemble::LineCrossing& c : outcome.line_crossings)
      crossings.emplace_back(outcome.rock, c);
  }
  std::vector<std::pair<long, ensemble::LineCrossing>> crossings;  // (rock, crossing) in rock order
  std::vector<io::RockRow> rows;
  std::vector<std::pair<long, BarrierEvent>> barriers;  // (rock, event) in rock order
  std::vector<std::vector<ensemble::TrajectorySample>> samples;

 private:
  const io::SceneFile& file_;
  bool trajectories_;
};

// The rows as a dict of arrays under rocks.csv's column names.
py::dict RowsDict(const std::vector<io::RockRow>& rows) {
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::array_t<std::int64_t> rock(n), release(n);
  py::array_t<std::uint64_t> seed(n);
  std::vector<std::string> run, end, block, end_ground, end_barrier;
  struct Column {
    const char* name;
    double io::RockRow::*member;
  };
  static constexpr Column kColumns[] = {
      {"x_end", &io::RockRow::x_end},
      {"y_end", &io::RockRow::y_end},
      {"z_end", &io::RockRow::z_end},
      {"runout_m", &io::RockRow::runout_m},
      {"path_length_m", &io::RockRow::path_length_m},
      {"travel_time_s", &io::RockRow::travel_time_s},
      {"max_speed_m_s", &io::RockRow::max_speed_m_s},
      {"max_kinetic_energy_j", &io::RockRow::max_kinetic_energy_j},
      {"max_jump_height_m", &io::RockRow::max_jump_height_m},
      {"max_angular_speed_rad_s", &io::RockRow::max_angular_speed_rad_s},
      {"max_scar_m", &io::RockRow::max_scar_m},
      {"mass_kg", &io::RockRow::mass_kg},
      {"x_start", &io::RockRow::x_start},
      {"y_start", &io::RockRow::y_start},
      {"z_start", &io::RockRow::z_start},
      {"travel_angle_deg", &io::RockRow::travel_angle_deg},
  };
  std::vector<py::array_t<double>> columns;
  for (std::size_t c = 0; c < std::size(kColumns); ++c) columns.emplace_back(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const io::RockRow& r = rows[static_cast<std::size_t>(i)];
    rock.mutable_at(i) = r.rock;
    release.mutable_at(i) = r.release;
    seed.mutable_at(i) = r.seed;
    run.push_back(r.run);
    end.push_back(r.end);
    block.push_back(r.block);
    end_ground.push_back(r.end_ground);
    end_barrier.push_back(r.end_barrier);
    for (std::size_t c = 0; c < std::size(kColumns); ++c)
      columns[c].mutable_at(i) = r.*(kColumns[c].member);
  }
  // In rocks.csv's column order.
  py::dict d;
  d["rock"] = rock;
  d["release"] = release;
  d["run"] = StringArray(run);
  d["seed"] = seed;
  d["end"] = StringArray(end);
  for (std::size_t c = 0; c < 11; ++c) d[kColumns[c].name] = columns[c];
  d["block"] = StringArray(block);
  for (std::size_t c = 11; c < std::size(kColumns); ++c) d[kColumns[c].name] = columns[c];
  d["end_ground"] = StringArray(end_ground);
  d["end_barrier"] = StringArray(end_barrier);
  return d;
}

// What each rock did at each barrier it reached, as barriers.csv lists it: one entry per (rock,
// barrier) in rock order.
py::dict BarriersDict(const io::SceneFile& file,
                      const std::vector<std::pair<long, BarrierEvent>>& events) {
  const auto n = static_cast<py::ssize_t>(events.size());
  py::array_t<std::int64_t> rock(n);
  py::array_t<double> t(n), speed(n), energy(n), after(n), height(n);
  py::array_t<double> position({n, py::ssize_t{3}});
  std::vector<std::string> barrier, outcome;
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& [r, e] = events[static_cast<std::size_t>(i)];
    rock.mutable_at(i) = r;
    barrier.push_back(file.scene.barriers[static_cast<std::size_t>(e.barrier)].name);
    outcome.push_back(ToString(e.outcome));
    t.mutable_at(i) = e.t_s;
    for (py::ssize_t k = 0; k < 3; ++k) position.mutable_at(i, k) = e.position_m[k];
    speed.mutable_at(i) = e.speed_m_s;
    energy.mutable_at(i) = e.energy_J();
    after.mutable_at(i) = e.energy_after_J;
    height.mutable_at(i) = e.passing_height_m;
  }
  py::dict d;
  d["rock"] = rock;
  d["barrier"] = StringArray(barrier);
  d["outcome"] = StringArray(outcome);
  d["t_s"] = t;
  d["position_m"] = position;
  d["speed_m_s"] = speed;
  d["energy_J"] = energy;
  d["energy_after_J"] = after;
  d["passing_height_m"] = height;
  return d;
}

// Each rock's first crossing of each evaluation line, as evaluation_lines.csv lists them: one entry
// per (rock, line crossed) in rock order, lines in order within a rock.
py::dict CrossingsDict(const io::SceneFile& file,
                       const std::vector<std::pair<long, ensemble::LineCrossing>>& crossings) {
  const auto n = static_cast<py::ssize_t>(crossings.size());
  py::array_t<std::int64_t> rock(n), count(n);
  py::array_t<double> t(n), speed(n), translational(n), rotational(n), energy(n), com(n), bounce(n);
  py::array_t<double> position({n, py::ssize_t{3}});
  std::vector<std::string> line;
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& [r, c] = crossings[static_cast<std::size_t>(i)];
    rock.mutable_at(i) = r;
    line.push_back(file.evaluation_lines[static_cast<std::size_t>(c.line)].name);
    t.mutable_at(i) = c.t_s;
    for (py::ssize_t k = 0; k < 3; ++k) position.mutable_at(i, k) = c.position_m[k];
    speed.mutable_at(i) = c.speed_m_s;
    translational.mutable_at(i) = c.translational_energy_J;
    rotational.mutable_at(i) = c.rotational_energy_J;
    energy.mutable_at(i) = c.energy_J();
    com.mutable_at(i) = c.com_height_m;
    bounce.mutable_at(i) = c.bounce_height_m;
    count.mutable_at(i) = c.crossings;
  }
  py::dict d;
  d["line"] = StringArray(line);
  d["rock"] = rock;
  d["t_s"] = t;
  d["position_m"] = position;
  d["speed_m_s"] = speed;
  d["translational_energy_J"] = translational;
  d["rotational_energy_J"] = rotational;
  d["energy_J"] = energy;
  d["com_height_m"] = com;
  d["bounce_height_m"] = bounce;
  d["crossings"] = count;
  return d;
}

py::dict CountsDict(const ensemble::EnsembleReport& r) {
  py::dict ends;
  for (int k = 0; k < kEndReasons; ++k) ends[ToString(static_cast<EndReason>(k))] = r.by_end[k];
  py::dict d;
  d["rocks"] = r.rocks;
  d["ends"] = ends;
  d["raised"] = r.raised;
  d["stayed_at_release"] = r.stayed_at_release;
  d["steps"] = r.steps;
  d["unconverged_steps"] = r.unconverged_steps;
  d["threads"] = r.threads;
  d["wall_time_s"] = r.wall_time_s;
  return d;
}

// The rasters as the GeoTIFFs of talus simulate hold them: north-up rows (ny, nx) of float32 (int32
// for counts), RasterLayer::kNoData where no rock passed, with the grid's GDAL geotransform and CRS.
py::dict RastersDict(const io::SceneFile& file, const std::vector<ensemble::RasterLayer>& layers) {
  const GridGeometry& grid = file.scene.terrain.heights().grid;
  py::dict out;
  const auto north_up = [&grid](const auto& cells) {
    using T = typename std::decay_t<decltype(cells)>::value_type;
    py::array_t<T> values({static_cast<py::ssize_t>(grid.ny), static_cast<py::ssize_t>(grid.nx)});
    auto v = values.template mutable_unchecked<2>();
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i)
        v(grid.ny - 1 - j, i) = cells[static_cast<std::size_t>(j) * grid.nx + i];
    return values;
  };
  for (const ensemble::RasterLayer& layer : layers) {
    py::dict d;
    // Counts as int32, as the GeoTIFF holds them.
    if (!layer.counts.empty())
      d["values"] = north_up(layer.counts);
    else
      d["values"] = north_up(layer.values);
    d["unit"] = layer.unit;
    d["quantity"] = layer.quantity;
    d["statistic"] = layer.statistic;
    d["description"] = layer.description;
    out[py::str(layer.name)] = d;
  }
  return out;
}

py::tuple GeoTransform(const io::SceneFile& file) {
  const std::array<double, 6> gt = io::GeoTransformOf(file.scene.terrain.heights().grid);
  return py::make_tuple(gt[0], gt[1], gt[2], gt[3], gt[4], gt[5]);
}

// The rocks [first, end) of the scene's release.
std::pair<long, long> RockRange(const io::SceneFile& file, const py::object& rocks) {
  const long total = file.release.total_rocks();
  if (rocks.is_none()) return {0, total};
  const py::slice slice = py::isinstance<py::slice>(rocks)
                              ? rocks.cast<py::slice>()
                              : py::slice(rocks.cast<long>(), rocks.cast<long>() + 1, 1);
  py::ssize_t start = 0, stop = 0, step = 0, length = 0;
  if (!slice.compute(total, &start, &stop, &step, &length) || step != 1 || length <= 0)
    throw InputError("rocks: " + py::repr(rocks).cast<std::string>() +
                     " is not a non-empty range of consecutive rocks of the ensemble's " +
                     std::to_string(total));
  return {static_cast<long>(start), static_cast<long>(stop)};
}

py::dict Simulate(const io::SceneFile& file, int threads, const py::object& rocks,
                  bool trajectories, double interval_s, bool rasters) {
  if (threads < 0) throw InputError("threads: " + std::to_string(threads) + " must be >= 0");
  const auto [first, end] = RockRange(file, rocks);
  ensemble::EnsembleOptions options;
  options.threads = threads;
  options.first_rock = first;
  options.end_rock = end;
  options.trajectories = trajectories;
  options.trajectory_interval_s = interval_s > 0 ? interval_s : file.output.trajectory_interval_s;
  if (rasters) options.rasters = file.output.Request(file.scene.terrain.heights().grid);
  options.progress = SignalCheck();
  if (!file.evaluation_lines.empty())
    options.evaluation_lines =
        std::make_shared<const std::vector<ensemble::EvaluationLine>>(file.evaluation_lines);
  CollectingSink sink(file, trajectories);
  const ensemble::EnsembleReport report = WithoutGil(
      [&] { return ensemble::RunEnsemble(file.scene, file.release, options, &sink); });
  py::dict out;
  out["rocks"] = RowsDict(sink.rows);
  out["counts"] = CountsDict(report);
  out["warnings"] = ensemble::RunWarnings(report, file.scene.options);
  if (!file.scene.barriers.empty()) out["barriers"] = BarriersDict(file, sink.barriers);
  if (!file.evaluation_lines.empty()) out["lines"] = CrossingsDict(file, sink.crossings);
  py::dict raster_dict = RastersDict(file, report.rasters);
  out["rasters"] = raster_dict;
  out["geotransform"] = GeoTransform(file);
  out["crs_wkt"] = file.crs_wkt;
  out["nodata"] = ensemble::RasterLayer::kNoData;
  if (trajectories) {
    py::list list;
    for (const auto& samples : sink.samples) list.append(TrajectoryDict(samples));
    out["trajectories"] = list;
  }
  return out;
}

py::dict RunRock(const io::SceneFile& file, long rock, int threads, double interval_s) {
  const long total = file.release.total_rocks();
  if (rock < 0 || rock >= total)
    throw InputError("rock " + std::to_string(rock) + ": the ensemble has rocks 0 .. " +
                     std::to_string(total - 1));
  py::dict all = Simulate(file, threads, py::int_(rock), true, interval_s, false);
  py::dict one = all["trajectories"].cast<py::list>()[0].cast<py::dict>();
  py::dict row;
  for (const auto& [key, column] : all["rocks"].cast<py::dict>())
    row[key] = column.attr("__getitem__")(0).attr("item")();
  one["result"] = row;
  return one;
}

}  // namespace

static std::shared_ptr<io::SceneFile> LoadSceneFromPython(const py::object& path) {
  const std::string text = PathText(path);
  return std::make_shared<io::SceneFile>(WithoutGil([&] { return io::LoadScene(text); }));
}

void BindScene(py::module_& m) {
  py::class_<io::SceneFile, std::shared_ptr<io::SceneFile>>(
      m, "Scene",
      "A scene file (docs/scenes.md), loaded and validated as talus simulate loads it. Edits "
      "(set_ground, set_solver, rocks, seed) are checked as the scene file's keys are and leave "
      "the scene as it was when they fail.")
      .def_static("load", &LoadSceneFromPython, py::arg("path"),
                  "Loads a scene file; raises talus.InputError naming the file, line and key.")
      .def_static(
          "from_dict",
          [](const py::dict& values, const py::object& path) {
            const std::string name = PathText(path);
            std::ostringstream text;
            text << TableOf(values, "");
            const std::string toml = text.str();
            return std::make_shared<io::SceneFile>(
                WithoutGil([&] { return io::LoadSceneText(toml, name); }));
          },
          py::arg("values"), py::arg("path") = "scene.toml",
          "A scene from Python values: a dict laid out as a scene file's tables (e.g. "
          "{'terrain': {'dem': 'dem.tif'}, 'release': {...}, 'rock': {...}}). `path` names it in "
          "errors, and files it names are found relative to its folder.")
      .def(
          "copy", [](const io::SceneFile& f) { return std::make_shared<io::SceneFile>(f); },
          "An independent copy (terrain and shapes are shared, immutable).")
      .def_readonly("path", &io::SceneFile::path)
      .def_readonly("crs_wkt", &io::SceneFile::crs_wkt, "The DEM's CRS as WKT; '' for none.")
      .def_readonly("terrain_description", &io::SceneFile::terrain_description)
      .def_readonly("rock_description", &io::SceneFile::rock_description)
      .def_readonly("warnings", &io::SceneFile::warnings)
      .def_readonly("inputs", &io::SceneFile::inputs)
      .def_readonly("inputs_hash", &io::SceneFile::inputs_hash,
                    "SHA-256 (hex) of the scene and every file it read: summary.json's "
                    "inputs_sha256.")
      .def_property_readonly(
          "ground",
          [](const io::SceneFile& f) { return FromJson(io::GroundTableJson(f.scene.ground)); },
          "The ground table: {category: {code, model, mu_min, mu_max, beta, kappa, nu, ...}} as "
          "summary.json lists it.")
      .def("set_ground", &SetGround, py::arg("category"),
           "Sets fields of a ground category by their scene keys, e.g. "
           "set_ground('medium', mu_min=0.3, kappa=2.5).")
      .def_property_readonly("solver",
                             [](const io::SceneFile& f) { return SolverDict(f.scene.options); })
      .def("set_solver", &SetSolver,
           "Sets dt_s, max_time_s, tolerance_m_s or max_iterations, e.g. set_solver(dt_s=0.001).")
      .def_property(
          "rocks", [](const io::SceneFile& f) { return f.release.rocks_per_release; },
          [](io::SceneFile& f, long rocks) {
            if (rocks < 1) throw InputError("rocks: " + std::to_string(rocks) + " must be >= 1");
            EditScene(f, "rocks", [rocks](io::SceneFile& s) { s.release.SetRocksPerRelease(rocks); });
          },
          "Rocks per release (a run of a run table), as talus simulate --rocks sets it.")
      .def_property(
          "seed", [](const io::SceneFile& f) { return f.release.seed; },
          [](io::SceneFile& f, std::int64_t seed) {
            if (seed < 0) throw InputError("seed: " + std::to_string(seed) + " must be >= 0");
            f.release.seed = static_cast<std::uint64_t>(seed);
          },
          "The release's random seed, as talus simulate --seed sets it.")
      .def_property_readonly("total_rocks",
                             [](const io::SceneFile& f) { return f.release.total_rocks(); })
      .def_property_readonly(
          "releases",
          [](const io::SceneFile& f) {
            std::vector<std::string> names;
            for (long r = 0; r < f.release.release_count(); ++r)
              names.push_back(f.release.ReleaseName(static_cast<int>(r)));
            return names;
          },
          "The name of every release geometry or run, in order.")
      .def_property_readonly(
          "geotransform", &GeoTransform,
          "GDAL geotransform of the rasters (north-up, DEM nodes at cell centres).")
      .def("simulate", &Simulate, py::arg("threads") = 0, py::arg("rocks") = py::none(),
           py::arg("trajectories") = false, py::arg("trajectory_interval_s") = 0.0,
           py::arg("rasters") = true,
           "Runs the ensemble (or the rocks of a slice) as talus simulate does, with the GIL "
           "released. Returns {'rocks': per-rock arrays under rocks.csv's column names, "
           "'counts', 'warnings', 'rasters': {name: {'values': float32 (ny, nx) north-up, unit, "
           "...}}, 'geotransform', 'crs_wkt', 'nodata'}, with evaluation lines 'lines' (each "
           "rock's first crossing of each line, as evaluation_lines.csv), with barriers "
           "'barriers' (one entry per rock and barrier it reached, as barriers.csv) and, with "
           "trajectories=True, "
           "'trajectories': one dict of arrays per rock.")
      .def("run_rock", &RunRock, py::arg("rock") = 0, py::arg("threads") = 1,
           py::arg("trajectory_interval_s") = 0.0,
           "Runs one rock of the ensemble: its trajectory samples as arrays (t, position, "
           "quaternion w x y z, velocity, angular_velocity, contact, scar) and 'result', its "
           "rocks.csv row.")
      .def("__repr__", [](const io::SceneFile& f) {
        return "<talus.Scene " + f.path + ": " + f.terrain_description + ", " +
               std::to_string(f.release.total_rocks()) + " rocks>";
      });
}

}  // namespace talus::python
