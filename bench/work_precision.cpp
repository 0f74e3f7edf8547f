// Benchmark: the work-precision map of every accuracy knob on one scene. The scene is loaded once
// through the library; each knob setting runs the scene's ensemble in-process on one thread for
// several seeds (settings alternate within each seed, so a busy machine slows all of them alike),
// and its ensemble statistics are compared with those of the knob's tightest setting under the same
// seed: runout median and 95th percentile, the reach-probability raster, and the 95th percentile of
// the energy at each evaluation line. The differences between seeds of the reference are the
// sampling noise. Prints the machine, the command and markdown tables, which
// bench/plot_work_precision.py turns into plots.

#include <gdal_priv.h>
#include <gdal_utils.h>
#include <toml++/toml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "common/error.hpp"
#include "common/statistics.hpp"
#include "ensemble/rasters.hpp"
#include "ensemble/runner.hpp"
#include "io/raster.hpp"
#include "io/report_html.hpp"
#include "io/scene_file.hpp"
#include "pointclouds/rock_source.hpp"

namespace {

using talus::ensemble::EvaluationLine;
using talus::ensemble::RockOutcome;

// ---- Knobs and settings -------------------------------------------------------------------------

// One setting of the accuracy knobs (the solver's three replace the scene's).
struct Knobs {
  double dt_s = 0;
  double tolerance_m_s = 0;
  int sweeps = 0;
  int hull_vertices = -1;  // -1: the scene's rock; 0: the many-point rock, full hull; else at most
  double cell_m = 0;       // DEM cell size; 0: the scene's DEM as it is
};

struct Setting {
  std::string label;
  Knobs knobs;
  talus::Scene scene;
  int rock_vertices = 0;  // hull vertices of the rock it runs
};

// A knob: its settings (indices into the settings), the first of them the tightest, which is the
// reference of the others; `value` is the knob's value of each, for the tables.
struct Family {
  std::string knob;
  std::vector<int> settings;
  std::vector<std::string> values;
};

// ---- What one run gives -------------------------------------------------------------------------

// Per rock: runout, the comparison-grid cells it passed, its energy at each evaluation line (NaN
// when it did not cross).
struct RockRecord {
  double runout_m = 0;
  std::vector<int> cells;
  std::vector<double> line_energy_kj;
};

struct Run {
  double cpu_s = 0;  // process CPU time of the ensemble (one worker thread)
  std::vector<RockRecord> rocks;
};

class RecordSink : public talus::ensemble::RockSink {
 public:
  RecordSink(std::size_t lines, std::vector<RockRecord>* out) : lines_(lines), out_(out) {}
  void OnRock(const RockOutcome& outcome) override {
    RockRecord record;
    record.runout_m = outcome.result.runout_m;
    record.cells = outcome.footprint.cells;
    record.line_energy_kj.assign(lines_, std::nan(""));
    for (const auto& crossing : outcome.line_crossings)
      record.line_energy_kj[static_cast<std::size_t>(crossing.line)] = crossing.energy_J() / 1000;
    out_->push_back(std::move(record));
  }

 private:
  std::size_t lines_;
  std::vector<RockRecord>* out_;
};

double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The study's fixed inputs: the release, the evaluation lines and the grid reach probability is
// compared on (the scene's own DEM grid, whatever the DEM a setting runs on).
struct Study {
  talus::io::SceneFile file;
  std::shared_ptr<const std::vector<EvaluationLine>> lines;
  talus::ensemble::RasterRequest reach;
};

Run RunSetting(const Study& study, const talus::Scene& scene, std::uint64_t seed, long rocks) {
  talus::ensemble::ReleaseSpec release = study.file.release;
  release.seed = seed;
  release.SetRocksPerRelease(rocks);
  talus::ensemble::EnsembleOptions options;
  options.threads = 1;
  options.evaluation_lines = study.lines;
  const talus::ensemble::RasterRequest& reach = study.reach;
  options.extra_recorders.push_back([&reach, &scene] {
    return std::make_unique<talus::ensemble::FootprintRecorder>(reach, scene.terrain);
  });
  Run run;
  RecordSink sink(study.lines->size(), &run.rocks);
  const double start = CpuSeconds();
  talus::ensemble::RunEnsemble(scene, release, options, &sink);
  run.cpu_s = CpuSeconds() - start;
  return run;
}

// ---- Statistics and their differences -----------------------------------------------------------

// Scalar statistics (runout median and 95th percentile, the 95th percentile of the energy at each
// evaluation line) with their bootstrap standard errors, and the reach probability per cell of
// the comparison grid.
struct Statistics {
  std::vector<double> scalars, standard_errors;
  std::vector<double> reach;  // per comparison cell, fraction of rocks
};

// The scalars of the rocks `picks` (nearest-rank percentiles, as talus simulate's; NaN for a line
// no picked rock crossed).
std::vector<double> Scalars(const std::vector<RockRecord>& rocks,
                            const std::vector<std::size_t>& picks, std::size_t lines) {
  std::vector<double> runouts;
  std::vector<std::vector<double>> energies(lines);
  for (std::size_t k : picks) {
    runouts.push_back(rocks[k].runout_m);
    for (std::size_t l = 0; l < lines; ++l)
      if (std::isfinite(rocks[k].line_energy_kj[l]))
        energies[l].push_back(rocks[k].line_energy_kj[l]);
  }
  std::vector<double> out = {talus::NearestRankPercentile(runouts, 50),
                             talus::NearestRankPercentile(runouts, 95)};
  for (const auto& e : energies) out.push_back(talus::NearestRankPercentile(e, 95));
  return out;
}

// Bootstrap standard errors of the scalars: 200 resamples of the rocks with replacement, drawn
// from a fixed stream, so that the same run gives the same errors.
std::vector<double> BootstrapErrors(const std::vector<RockRecord>& rocks,
                                    const std::vector<std::size_t>& picks, std::size_t lines) {
  constexpr int kResamples = 200;
  std::mt19937_64 random(20261125);
  std::vector<std::vector<double>> draws;
  std::vector<std::size_t> resample(picks.size());
  for (int b = 0; b < kResamples; ++b) {
    for (std::size_t& k : resample) k = picks[random() % picks.size()];
    draws.push_back(Scalars(rocks, resample, lines));
  }
  std::vector<double> errors;
  for (std::size_t q = 0; q < draws.front().size(); ++q) {
    double sum = 0, sum2 = 0;
    int n = 0;
    for (const auto& d : draws) {
      if (!std::isfinite(d[q])) continue;
      sum += d[q];
      sum2 += d[q] * d[q];
      ++n;
    }
    errors.push_back(n > 1 ? std::sqrt(std::max(0.0, (sum2 - sum * sum / n) / (n - 1)))
                           : std::nan(""));
  }
  return errors;
}

// The statistics of the first `n` rocks of a run.
Statistics Summarise(const std::vector<RockRecord>& rocks, std::size_t n, std::size_t cells,
                     std::size_t lines) {
  std::vector<std::size_t> picks(n);
  for (std::size_t k = 0; k < n; ++k) picks[k] = k;
  Statistics s{Scalars(rocks, picks, lines), BootstrapErrors(rocks, picks, lines),
               std::vector<double>(cells, 0.0)};
  for (std::size_t k = 0; k < n; ++k)
    for (int cell : rocks[k].cells) s.reach[static_cast<std::size_t>(cell)] += 1.0 / double(n);
  return s;
}

// The compared quantities: signed differences of the scalars (in their order), then the reach
// probability's mean absolute difference over the cells reached in either run and its largest.
struct Quantity {
  std::string name, unit;
  bool signed_difference;
};

std::vector<Quantity> Quantities(const std::vector<EvaluationLine>& lines) {
  std::vector<Quantity> q = {{"runout median", "m", true}, {"runout p95", "m", true}};
  for (const auto& line : lines) q.push_back({"energy p95 at " + line.name, "kJ", true});
  q.push_back({"reach prob. mean abs. diff.", "", false});
  q.push_back({"reach prob. largest diff.", "", false});
  return q;
}

std::vector<double> Differences(const Statistics& a, const Statistics& b) {
  std::vector<double> out;
  for (std::size_t q = 0; q < a.scalars.size(); ++q) out.push_back(a.scalars[q] - b.scalars[q]);
  double sum = 0, largest = 0;
  long reached = 0;
  for (std::size_t c = 0; c < a.reach.size(); ++c) {
    if (a.reach[c] == 0 && b.reach[c] == 0) continue;
    const double d = std::abs(a.reach[c] - b.reach[c]);
    sum += d;
    largest = std::max(largest, d);
    ++reached;
  }
  out.push_back(reached ? sum / double(reached) : 0.0);
  out.push_back(largest);
  return out;
}

// ---- Building the settings' scenes --------------------------------------------------------------

talus::GridGeometry GridOfRaster(GDALDataset& dataset) {
  double gt[6];
  dataset.GetGeoTransform(gt);
  talus::GridGeometry grid;
  grid.nx = dataset.GetRasterXSize();
  grid.ny = dataset.GetRasterYSize();
  grid.dx_m = gt[1];
  grid.dy_m = -gt[5];
  grid.x0_m = gt[0] + 0.5 * gt[1];
  grid.y0_m = gt[3] + (grid.ny - 0.5) * gt[5];
  return grid;
}

// The DEM resampled to cells of `cell_m` over the same extent, as `gdalwarp -tr cell cell -r
// average` (coarser) or `-r bilinear` (finer) would, in memory.
talus::Heightfield ResampleDem(const talus::Heightfield& dem, double cell_m) {
  talus::io::RegisterGdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  const talus::GridGeometry& g = dem.grid;
  std::unique_ptr<GDALDataset> source(mem->Create("", g.nx, g.ny, 1, GDT_Float64, nullptr));
  auto gt = talus::io::GeoTransformOf(g);
  source->SetGeoTransform(gt.data());
  GDALRasterBand* band = source->GetRasterBand(1);
  band->SetNoDataValue(std::nan(""));
  for (int j = 0; j < g.ny; ++j) {  // GDAL rows run north to south
    std::vector<double> row(dem.z_m.begin() + std::ptrdiff_t(j) * g.nx,
                            dem.z_m.begin() + std::ptrdiff_t(j + 1) * g.nx);
    if (band->RasterIO(GF_Write, 0, g.ny - 1 - j, g.nx, 1, row.data(), g.nx, 1, GDT_Float64, 0,
                       0) != CE_None)
      throw std::runtime_error("cannot fill the in-memory DEM");
  }
  const std::string res = std::to_string(cell_m);
  const char* method = cell_m > std::min(g.dx_m, g.dy_m) ? "average" : "bilinear";
  const char* argv[] = {"-of", "MEM", "-tr", res.c_str(), res.c_str(), "-r", method, nullptr};
  GDALWarpAppOptions* options = GDALWarpAppOptionsNew(const_cast<char**>(argv), nullptr);
  GDALDatasetH handle = GDALDataset::ToHandle(source.get());
  std::unique_ptr<GDALDataset> out(
      GDALDataset::FromHandle(GDALWarp("", nullptr, 1, &handle, options, nullptr)));
  GDALWarpAppOptionsFree(options);
  if (!out) throw std::runtime_error("GDALWarp failed to resample the DEM");
  talus::Heightfield result;
  result.grid = GridOfRaster(*out);
  const talus::GridGeometry& r = result.grid;
  result.z_m.resize(std::size_t(r.nx) * r.ny);
  int has_nodata = 0;
  GDALRasterBand* out_band = out->GetRasterBand(1);
  const double nodata = out_band->GetNoDataValue(&has_nodata);
  for (int j = 0; j < r.ny; ++j)
    if (out_band->RasterIO(GF_Read, 0, r.ny - 1 - j, r.nx, 1, &result.z_m[std::size_t(j) * r.nx],
                           r.nx, 1, GDT_Float64, 0, 0) != CE_None)
      throw std::runtime_error("cannot read the resampled DEM");
  if (has_nodata && !std::isnan(nodata))
    for (double& z : result.z_m)
      if (z == nodata) z = std::nan("");
  return result;
}

// The scene's [terrain] plane, when it has one (then a cell size is the plane's own parameter).
std::optional<talus::PlaneSpec> PlaneOf(const std::string& scene_path) {
  const toml::table scene = toml::parse_file(scene_path);
  const toml::table* plane = scene["terrain"]["plane"].as_table();
  if (!plane) return std::nullopt;
  talus::PlaneSpec spec;
  spec.slope_deg = (*plane)["slope_deg"].value_or(spec.slope_deg);
  spec.slope_length_m = (*plane)["slope_length_m"].value_or(spec.slope_length_m);
  spec.runout_m = (*plane)["runout_m"].value_or(spec.runout_m);
  spec.width_m = (*plane)["width_m"].value_or(spec.width_m);
  spec.cell_m = (*plane)["cell_m"].value_or(spec.cell_m);
  return spec;
}

// The scene's terrain with its DEM at `cell_m`: the plane rebuilt with that cell size, or the DEM
// resampled by GDAL; the ground grid keeps its own geometry.
talus::Terrain TerrainAt(const talus::Terrain& terrain,
                         const std::optional<talus::PlaneSpec>& plane, double cell_m) {
  talus::Heightfield heights;
  if (plane) {
    talus::PlaneSpec spec = *plane;
    spec.cell_m = cell_m;
    heights = talus::MakePlaneHeightfield(spec);
  } else {
    heights = ResampleDem(terrain.heights(), cell_m);
  }
  talus::Terrain out(std::move(heights), terrain.default_ground());
  if (terrain.has_ground_grid()) out.SetGroundGrid(terrain.ground_grid());
  return out;
}

// A rock with many hull vertices, of the size and mass of `like`: the built-in `rock` (the hull
// of `points` random points on the ellipsoid of like's extents, roughness 0.15, shape seed 1),
// simplified to at most max_vertices (0: the full hull).
talus::RockShape ManyPointRock(const talus::RockShape& like, int points, int max_vertices,
                               int* hull_vertices) {
  Eigen::Vector3d lo = like.vertices_m.front(), hi = lo;
  for (const Eigen::Vector3d& v : like.vertices_m) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  talus::pointclouds::RockSpec spec;
  spec.builtin = "rock";
  spec.points = points;
  spec.shape_seed = 1;
  spec.dimensions_m = {hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()};
  spec.mass_kg = like.mass_kg;
  spec.max_vertices = max_vertices;
  talus::pointclouds::RockReport report;
  talus::RockShape rock = talus::pointclouds::MakeRock(spec, &report);
  *hull_vertices = report.hull_vertices;
  return rock;
}

struct StudyOptions {
  std::vector<double> dt_ms = {0.5, 1, 2, 4, 8};
  std::vector<double> tolerances_m_s = {1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1};
  std::vector<int> sweeps = {1000, 200, 50, 20, 10, 5};
  std::vector<int> hull_vertices = {0, 64, 32, 16, 8};  // 0: full
  int hull_points = 200;
  std::vector<double> cells_m;  // the first is the reference; empty: no DEM knob
  std::vector<std::string> knobs = {"dt", "tolerance", "sweeps", "hull", "dem", "rocks"};
  bool Has(const std::string& knob) const {
    return std::find(knobs.begin(), knobs.end(), knob) != knobs.end();
  }
};

// The base setting: the solver's defaults (dt 2 ms, tolerance 1e-3 m/s, 200 sweeps), the scene's
// rock and DEM. The study's tables in bench/README.md were measured with the default of then,
// 1e-7 m/s, as base.
Knobs BaseKnobs() {
  const talus::SolverOptions defaults;
  return {defaults.dt_s, defaults.tolerance_m_s, defaults.max_iterations, -1, 0};
}

bool SameKnobs(const Knobs& a, const Knobs& b) {
  return a.dt_s == b.dt_s && a.tolerance_m_s == b.tolerance_m_s && a.sweeps == b.sweeps &&
         a.hull_vertices == b.hull_vertices && a.cell_m == b.cell_m;
}

class SettingBuilder {
 public:
  SettingBuilder(const Study& study, const StudyOptions& options)
      : study_(study), options_(options), plane_(PlaneOf(study.file.path)) {}

  // The index of the setting with these knobs, built on first use.
  int Add(const Knobs& knobs, const std::string& label) {
    for (std::size_t k = 0; k < settings_.size(); ++k)
      if (SameKnobs(settings_[k].knobs, knobs)) return static_cast<int>(k);
    Setting s{label, knobs, study_.file.scene, 0};
    s.scene.options.dt_s = knobs.dt_s;
    s.scene.options.tolerance_m_s = knobs.tolerance_m_s;
    s.scene.options.max_iterations = knobs.sweeps;
    if (knobs.hull_vertices >= 0)
      s.scene.rock = ManyPointRock(study_.file.scene.rock, options_.hull_points,
                                   knobs.hull_vertices, &s.rock_vertices);
    else
      s.rock_vertices = static_cast<int>(s.scene.rock.vertices_m.size());
    if (knobs.cell_m > 0)
      s.scene.terrain = TerrainAt(study_.file.scene.terrain, plane_, knobs.cell_m);
    std::string why;
    if (!s.scene.IsValid(&why)) throw talus::InputError(label + ": " + why);
    settings_.push_back(std::move(s));
    return static_cast<int>(settings_.size() - 1);
  }
  std::vector<Setting> Take() { return std::move(settings_); }

 private:
  const Study& study_;
  const StudyOptions& options_;
  std::optional<talus::PlaneSpec> plane_;
  std::vector<Setting> settings_;
};

std::string Format(const char* format, double v) {
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

// The knob families, each led by its tightest setting.
std::vector<Family> BuildFamilies(const StudyOptions& o, double native_cell_m,
                                  SettingBuilder& builder) {
  const Knobs base = BaseKnobs();
  builder.Add(base, "base");
  std::vector<Family> families;
  auto family = [&](const std::string& knob, auto values, auto set, auto describe) {
    if (!o.Has(knob)) return;
    Family f{knob, {}, {}};
    for (const auto& v : values) {
      Knobs k = base;
      set(k, v);
      f.values.push_back(describe(v));
      f.settings.push_back(builder.Add(k, knob + " " + f.values.back()));
    }
    families.push_back(std::move(f));
  };
  family(
      "dt", o.dt_ms, [](Knobs& k, double v) { k.dt_s = v / 1000; },
      [](double v) { return Format("%g ms", v); });
  family(
      "tolerance", o.tolerances_m_s, [](Knobs& k, double v) { k.tolerance_m_s = v; },
      [](double v) { return Format("%.0e m/s", v); });
  family(
      "sweeps", o.sweeps, [](Knobs& k, int v) { k.sweeps = v; },
      [](int v) { return std::to_string(v); });
  family(
      "hull", o.hull_vertices, [](Knobs& k, int v) { k.hull_vertices = v; },
      [](int v) { return v ? "at most " + std::to_string(v) : std::string("full"); });
  // The scene's own cell size is the base setting's DEM, not a resampling of it.
  family(
      "dem", o.cells_m,
      [native_cell_m](Knobs& k, double v) { k.cell_m = v == native_cell_m ? 0 : v; },
      [](double v) { return Format("%g m", v); });
  return families;
}

// ---- The study ----------------------------------------------------------------------------------

// Every setting's run for every seed: runs[setting][seed].
using Runs = std::vector<std::vector<Run>>;

Runs RunAll(const Study& study, const std::vector<Setting>& settings,
            const std::vector<std::uint64_t>& seeds, long rocks) {
  Runs runs(settings.size(), std::vector<Run>(seeds.size()));
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    for (std::size_t k = 0; k < settings.size(); ++k) {
      runs[k][s] = RunSetting(study, settings[k].scene, seeds[s], rocks);
      std::fprintf(stderr, "seed %llu, %s: %.2f s CPU\n", static_cast<unsigned long long>(seeds[s]),
                   settings[k].label.c_str(), runs[k][s].cpu_s);
    }
  }
  return runs;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// How far one setting's statistics are from its reference's, quantity by quantity, over the
// seeds: mean signed difference and mean absolute difference.
struct Departure {
  std::vector<double> mean, mean_abs;
};

Departure Accumulate(const std::vector<std::vector<double>>& differences) {
  const std::size_t q = differences.front().size();
  Departure d{std::vector<double>(q, 0.0), std::vector<double>(q, 0.0)};
  for (std::size_t k = 0; k < q; ++k) {
    int n = 0;
    for (const auto& row : differences) {
      if (!std::isfinite(row[k])) continue;
      d.mean[k] += row[k];
      d.mean_abs[k] += std::abs(row[k]);
      ++n;
    }
    d.mean[k] = n ? d.mean[k] / n : std::nan("");
    d.mean_abs[k] = n ? d.mean_abs[k] / n : std::nan("");
  }
  return d;
}

// The sampling noise of a reference: differences between its seeds (every pair once). rms is the
// standard deviation of the difference between two independent ensembles; sd_abs that of the
// absolute differences (for the raster, whose difference is never negative).
struct Noise {
  std::vector<double> mean_abs, rms, sd_abs;
};

Noise NoiseOf(const std::vector<Statistics>& reference) {
  std::vector<std::vector<double>> pairs;
  for (std::size_t a = 0; a < reference.size(); ++a)
    for (std::size_t b = a + 1; b < reference.size(); ++b)
      pairs.push_back(Differences(reference[a], reference[b]));
  const std::size_t q = pairs.front().size();
  Noise noise{Accumulate(pairs).mean_abs, std::vector<double>(q, 0.0), std::vector<double>(q, 0.0)};
  for (std::size_t k = 0; k < q; ++k) {
    int n = 0;
    for (const auto& row : pairs) {
      if (!std::isfinite(row[k])) continue;
      noise.rms[k] += row[k] * row[k];
      noise.sd_abs[k] += std::pow(std::abs(row[k]) - noise.mean_abs[k], 2);
      ++n;
    }
    noise.rms[k] = std::sqrt(noise.rms[k] / std::max(n, 1));
    noise.sd_abs[k] = std::sqrt(noise.sd_abs[k] / std::max(n - 1, 1));
  }
  return noise;
}

// The standard error of a setting's mean difference from its reference over the seeds, per
// scalar: sqrt(sum over seeds of both runs' bootstrap variances) / seeds (the runs' errors taken as
// independent, which bounds it when they are correlated, as same-seed runs are).
std::vector<double> ErrorOfMeanDifference(const std::vector<Statistics>& setting,
                                          const std::vector<Statistics>& reference) {
  std::vector<double> out;
  for (std::size_t q = 0; q < reference.front().standard_errors.size(); ++q) {
    double variance = 0;
    for (std::size_t s = 0; s < reference.size(); ++s)
      variance +=
          std::pow(setting[s].standard_errors[q], 2) + std::pow(reference[s].standard_errors[q], 2);
    out.push_back(std::sqrt(variance) / double(reference.size()));
  }
  return out;
}

// Equal within standard errors: a scalar's mean difference over the seeds within two standard
// errors of it; the raster's mean absolute difference from the reference of the same seed no
// larger than two ensembles of the same setting differ (between seeds, of the setting and of the
// reference pooled) plus two standard errors of that mean.
bool Within(const Quantity& q, std::size_t k, const Departure& d, double error_of_mean,
            const Noise& setting_noise, const Noise& reference_noise, int seeds) {
  if (!std::isfinite(d.mean[k])) return true;
  if (q.signed_difference) return std::abs(d.mean[k]) <= 2 * error_of_mean;
  const double mean = 0.5 * (setting_noise.mean_abs[k] + reference_noise.mean_abs[k]);
  const double sd = std::hypot(setting_noise.sd_abs[k], reference_noise.sd_abs[k]) / std::sqrt(2.0);
  return d.mean_abs[k] <= mean + 2 * sd / std::sqrt(double(seeds));
}

struct Context {
  const Study& study;
  const std::vector<Setting>& settings;
  const Runs& runs;
  std::vector<std::vector<Statistics>> stats;  // [setting][seed]
  std::vector<Quantity> quantities;
  long rocks;
  int seeds;
};

double CpuPerRockS(const Context& c, int setting, int seed) {
  return c.runs[std::size_t(setting)][std::size_t(seed)].cpu_s / double(c.rocks);
}

std::string Cell(double v, const char* format) {
  return std::isfinite(v) ? Format(format, v) : std::string("–");
}

void PrintHeader(const Context& c, const char* first) {
  std::printf(
      "| %s | hull vertices | CPU ms per trajectory | trajectories/s | speed-up (vs base, or the "
      "reference) |",
      first);
  for (const Quantity& q : c.quantities)
    std::printf(" %s%s |", q.name.c_str(), q.unit.empty() ? "" : (" (" + q.unit + ")").c_str());
  std::printf("\n|---|---|---|---|---|");
  for (std::size_t k = 0; k < c.quantities.size(); ++k) std::printf("---|");
  std::printf("\n");
}

// The noise rows under a knob's table: how two seeds of the reference differ, and the scalars'
// values and bootstrap standard errors (means over the seeds).
void PrintNoise(const Context& c, int ref, const Noise& noise) {
  std::printf("| between seeds of the reference: mean abs. diff. | | | | |");
  for (std::size_t q = 0; q < c.quantities.size(); ++q)
    std::printf(
        " %s |",
        Cell(noise.mean_abs[q], c.quantities[q].signed_difference ? "%.2f" : "%.4f").c_str());
  const std::vector<Statistics>& stats = c.stats[std::size_t(ref)];
  std::printf("\n| reference: the statistic (mean over seeds) | | | | |");
  for (std::size_t q = 0; q < c.quantities.size(); ++q) {
    if (!c.quantities[q].signed_difference) {
      std::printf(" |");
      continue;
    }
    double sum = 0;
    for (const Statistics& s : stats) sum += s.scalars[q];
    std::printf(" %s |", Cell(sum / double(stats.size()), "%.2f").c_str());
  }
  std::printf("\n| reference: bootstrap standard error of the statistic | | | | |");
  for (std::size_t q = 0; q < c.quantities.size(); ++q) {
    if (!c.quantities[q].signed_difference) {
      std::printf(" |");
      continue;
    }
    double sum = 0;
    for (const Statistics& s : stats) sum += s.standard_errors[q];
    std::printf(" %s |", Cell(sum / double(stats.size()), "%.2f").c_str());
  }
  std::printf("\n");
}

// The table of one knob. Scalars: mean difference from the reference
// of the same seed ± its standard error; the raster: mean over the seeds of the mean absolute
// difference. **≠** marks a departure beyond the standard errors (Within).
void ReportFamily(const Context& c, const Family& f, int base) {
  const int ref = f.settings.front();
  const Noise noise = NoiseOf(c.stats[std::size_t(ref)]);
  // Speed-up against the base setting, or against the reference when the knob never runs the base
  // (the many-point rock).
  const bool has_base = std::find(f.settings.begin(), f.settings.end(), base) != f.settings.end();
  const int yardstick = has_base ? base : ref;
  std::printf("\n#### Knob: %s (reference: %s)\n\n", f.knob.c_str(), f.values.front().c_str());
  PrintHeader(c, f.knob.c_str());
  for (std::size_t i = 0; i < f.settings.size(); ++i) {
    const int k = f.settings[i];
    std::vector<double> times, speedups;
    std::vector<std::vector<double>> differences;
    for (int s = 0; s < c.seeds; ++s) {
      times.push_back(CpuPerRockS(c, k, s));
      speedups.push_back(CpuPerRockS(c, yardstick, s) / CpuPerRockS(c, k, s));
      differences.push_back(Differences(c.stats[std::size_t(k)][std::size_t(s)],
                                        c.stats[std::size_t(ref)][std::size_t(s)]));
    }
    const Departure d = Accumulate(differences);
    const std::vector<double> errors =
        ErrorOfMeanDifference(c.stats[std::size_t(k)], c.stats[std::size_t(ref)]);
    const Noise own_noise = NoiseOf(c.stats[std::size_t(k)]);
    const double t = Median(times);
    std::printf("| %s%s | %d | %.2f | %.1f | %.2f |", f.values[i].c_str(),
                k == base ? " (base)" : "", c.settings[std::size_t(k)].rock_vertices, 1000 * t,
                1 / t, Median(speedups));
    for (std::size_t q = 0; q < c.quantities.size(); ++q) {
      const Quantity& quantity = c.quantities[q];
      std::string text = i == 0 ? "0"
                         : quantity.signed_difference
                             ? Cell(d.mean[q], "%+.2f") + " ± " + Cell(errors[q], "%.2f")
                             : Cell(d.mean_abs[q], "%.4f");
      if (i > 0 &&
          !Within(quantity, q, d, q < errors.size() ? errors[q] : 0, own_noise, noise, c.seeds))
        text += " **≠**";
      std::printf(" %s |", text.c_str());
    }
    std::printf("\n");
  }
  PrintNoise(c, ref, noise);
}

// The rocks knob: the first n rocks of the base run of one seed against all rocks of the base
// run of every other seed (at n = all rocks, that is the noise itself).
void ReportRocks(const Context& c, int base) {
  const std::vector<Statistics>& full = c.stats[std::size_t(base)];
  std::vector<double> times;
  for (int s = 0; s < c.seeds; ++s) times.push_back(CpuPerRockS(c, base, s));
  const double t = Median(times);
  std::printf(
      "\n#### Knob: rocks per release (reference: %ld; error against the other seeds' %ld)\n\n",
      c.rocks, c.rocks);
  std::printf("| rocks | ensemble CPU s |");
  for (const Quantity& q : c.quantities) std::printf(" %s, mean abs. diff. |", q.name.c_str());
  std::printf("\n|---|---|");
  for (std::size_t k = 0; k < c.quantities.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (long n : {c.rocks / 8, c.rocks / 4, c.rocks / 2, c.rocks}) {
    std::vector<std::vector<double>> differences;
    for (int a = 0; a < c.seeds; ++a) {
      const auto& run = c.runs[std::size_t(base)][std::size_t(a)];
      const Statistics part =
          Summarise(run.rocks, std::size_t(n), full[0].reach.size(), c.study.lines->size());
      for (int b = 0; b < c.seeds; ++b)
        if (b != a) differences.push_back(Differences(part, full[std::size_t(b)]));
    }
    const Departure d = Accumulate(differences);
    std::printf("| %ld | %.2f |", n, t * double(n));
    for (std::size_t q = 0; q < c.quantities.size(); ++q)
      std::printf(" %s |",
                  Cell(d.mean_abs[q], c.quantities[q].signed_difference ? "%.2f" : "%.4f").c_str());
    std::printf("\n");
  }
}

// ---- Machine and study inputs -------------------------------------------------------------------

// For a plane without evaluation lines: two lines across it, at mid-slope and at the foot.
std::vector<EvaluationLine> LinesOf(const talus::io::SceneFile& file) {
  if (!file.evaluation_lines.empty()) return file.evaluation_lines;
  const std::optional<talus::PlaneSpec> plane = PlaneOf(file.path);
  if (!plane) return {};
  const double half = plane->width_m / 2, mid = plane->slope_length_m / 2,
               foot = plane->slope_length_m;
  return {{Format("mid-slope x = %g m", mid), {{mid, -half}, {mid, half}}},
          {Format("slope foot x = %g m", foot), {{foot, -half}, {foot, half}}}};
}

Study LoadStudy(const std::string& path) {
  Study study;
  study.file = talus::io::LoadScene(path);
  study.lines = std::make_shared<const std::vector<EvaluationLine>>(LinesOf(study.file));
  study.reach.grid = study.file.scene.terrain.heights().grid;
  study.reach.reach_probability = true;
  return study;
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Work against precision of every accuracy knob on one scene (one core)"};
  std::string scene_path;
  long rocks = 200;
  int seeds = 3;
  StudyOptions o;
  app.add_option("scene", scene_path, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
  app.add_option("--rocks", rocks, "Rocks per release")->check(CLI::Range(8L, 100000L));
  app.add_option("--seeds", seeds, "Seeds 1 .. N")->check(CLI::Range(2, 100));
  app.add_option("--knobs", o.knobs, "Knobs to study")
      ->check(CLI::IsMember({"dt", "tolerance", "sweeps", "hull", "dem", "rocks"}));
  app.add_option("--dt-ms", o.dt_ms, "Time steps, ms, the tightest first");
  app.add_option("--tolerances", o.tolerances_m_s, "Solver tolerances, m/s, the tightest first");
  app.add_option("--sweeps", o.sweeps, "Most sweeps, the largest first");
  app.add_option("--hull-vertices", o.hull_vertices,
                 "max_vertices of the many-point rock, 0 (full) first");
  app.add_option("--hull-points", o.hull_points, "Points of the many-point rock")
      ->check(CLI::Range(8, 100000));
  app.add_option("--cells", o.cells_m, "DEM cell sizes, m, the finest first (default: none)");
  CLI11_PARSE(app, argc, argv);

  try {
    PrintMachine(argc, argv);
    const Study study = LoadStudy(scene_path);
    SettingBuilder builder(study, o);
    const std::vector<Family> families =
        BuildFamilies(o, study.file.scene.terrain.heights().grid.dx_m, builder);
    const std::vector<Setting> settings = builder.Take();
    std::vector<std::uint64_t> seed_list;
    for (int s = 1; s <= seeds; ++s) seed_list.push_back(std::uint64_t(s));
    std::printf(
        "scene: %s (%s; %s); %ld rocks per release x %d seeds, one worker thread; "
        "%zu settings\n",
        scene_path.c_str(), study.file.terrain_description.c_str(),
        study.file.rock_description.c_str(), rocks, seeds, settings.size());

    const Runs runs = RunAll(study, settings, seed_list, rocks);
    Context c{study, settings, runs, {}, Quantities(*study.lines), rocks, seeds};
    for (const auto& per_seed : runs) {
      c.stats.emplace_back();
      for (const Run& run : per_seed)
        c.stats.back().push_back(Summarise(run.rocks, run.rocks.size(),
                                           study.reach.grid.nx * std::size_t(study.reach.grid.ny),
                                           study.lines->size()));
    }
    std::printf("load average at the end: %s\n", FirstLine("/proc/loadavg", "").c_str());
    for (const Family& f : families) ReportFamily(c, f, 0);
    if (o.Has("rocks")) ReportRocks(c, 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "work_precision: %s\n", e.what());
    return 1;
  }
  return 0;
}
