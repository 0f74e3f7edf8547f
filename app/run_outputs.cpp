#include "app/run_outputs.hpp"

#include <cpl_error.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/console.hpp"
#include "app/interrupt.hpp"
#include "common/error.hpp"
#include "io/barriers_csv.hpp"
#include "io/evaluation_lines_csv.hpp"
#include "io/geopackage.hpp"
#include "io/quicklook.hpp"
#include "io/raster.hpp"
#include "io/report_html.hpp"
#include "io/rocks_csv.hpp"
#include "io/summary.hpp"
#include "io/trajectory_file.hpp"
#include "io/tree_impacts_csv.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

namespace fs = std::filesystem;

// Streams each finished rock to rocks.csv, trajectories.h5, evaluation_lines.csv, barriers.csv
// and tree_impacts.csv. Keeps the horizontal paths of the quick-look's sample rocks.
class FileSink : public ensemble::RockSink {
 public:
  FileSink(io::RocksCsvWriter& csv, io::TrajectoryWriter* trajectories,
           io::EvaluationLinesCsvWriter* lines, io::BarriersCsvWriter* barriers,
           io::TreeImpactsCsvWriter* trees, std::function<bool(long)> sample)
      : csv_(csv),
        trajectories_(trajectories),
        lines_(lines),
        barriers_(barriers),
        trees_(trees),
        sample_(std::move(sample)) {}
  void OnRock(const ensemble::RockOutcome& rock) override {
    ThrowIfInterrupted();
    csv_.Write(rock);
    if (trajectories_) trajectories_->Write(rock);
    if (lines_) lines_->Write(rock);
    if (barriers_) barriers_->Write(rock);
    if (trees_) trees_->Write(rock);
    if (sample_ && sample_(rock.rock)) {
      io::SamplePath& path = paths.emplace_back();
      path.rock = rock.rock;
      for (const ensemble::TrajectorySample& s : rock.trajectory)
        path.xy_m.push_back(s.position_m.head<2>());
    }
  }
  std::vector<io::SamplePath> paths;

 private:
  io::RocksCsvWriter& csv_;
  io::TrajectoryWriter* trajectories_;
  io::EvaluationLinesCsvWriter* lines_;
  io::BarriersCsvWriter* barriers_;
  io::TreeImpactsCsvWriter* trees_;
  std::function<bool(long)> sample_;
};

// Keeps GDAL's error messages off stderr while alive (on this thread); they stay readable through
// CPLGetLastErrorMsg, which the raster writers put in their exceptions.
class QuietGdal {
 public:
  QuietGdal() { CPLPushErrorHandler(CPLQuietErrorHandler); }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

// Writes the rasters, the quick-look and summary.json of a whole ensemble after `outputs`;
// returns all files in commit order (summary.json last: it is there only with its outputs).
// `progress`, when given, hears the files written of those that take time (rasters, quick-look,
// GeoPackage, report, summary).
std::vector<std::string> WriteSummaryOutputs(
    const io::SceneFile& scene, const ensemble::EnsembleReport& report,
    const std::vector<ensemble::RasterLayer>& layers, const std::vector<io::SamplePath>& paths,
    const StagingDirectory& staging, std::vector<std::string> outputs,
    const ensemble::SelfCheckReport* self_check, const MergeProgress& progress = {}) {
  const GridGeometry& dem = scene.scene.terrain.heights().grid;
  // GDAL would print every failed write of a full disk; the writers throw with its last message.
  const QuietGdal quiet_gdal;
  const std::string ground = io::GroundTableJson(scene.scene.ground);
  const long files = static_cast<long>(layers.size()) + (scene.output.quicklook ? 1 : 0) +
                     (scene.output.geopackage ? 1 : 0) + (scene.output.report ? 1 : 0) + 1;
  long written = 0;
  const auto wrote = [&](long n) {
    written += n;
    if (progress) progress("Writing the outputs", written, files, "files");
  };
  wrote(0);
  for (const ensemble::RasterLayer& layer : layers) {
    ThrowIfInterrupted();
    // What the raster is and which run made it; nothing that depends on the time or the split.
    const io::RasterMetadata metadata{layer.description,
                                      layer.unit,
                                      {{"TALUS_VERSION", kVersion},
                                       {"TALUS_INPUTS_SHA256", scene.inputs_hash},
                                       {"TALUS_QUANTITY", layer.quantity},
                                       {"TALUS_STATISTIC", layer.statistic},
                                       {"TALUS_ROCKS", std::to_string(report.rocks)},
                                       {"TALUS_SEED", std::to_string(scene.release.seed)},
                                       {"TALUS_GROUND", ground}}};
    // Counts as Int32 (exact for any number of rocks, classified as integers by GIS), the
    // others as Float32.
    if (!layer.counts.empty())
      io::WriteGeoTiff(staging.path(layer.name + ".tif"), dem, scene.crs_wkt, layer.counts, true,
                       ensemble::RasterLayer::kNoData, metadata, scene.output.raster_format);
    else
      io::WriteGeoTiff(staging.path(layer.name + ".tif"), dem, scene.crs_wkt, layer.values, true,
                       ensemble::RasterLayer::kNoData, metadata, scene.output.raster_format);
    outputs.push_back(layer.name + ".tif");
    wrote(1);
  }
  ThrowIfInterrupted();
  // Evaluation lines: summarised from the complete evaluation_lines.csv.
  std::vector<io::EvaluationLineSummary> lines;
  if (!scene.evaluation_lines.empty()) {
    lines = io::SummarizeEvaluationLines(staging.path("evaluation_lines.csv"),
                                         scene.evaluation_lines, report.rocks);
    WriteFileAtomically(staging.path("evaluation_lines_summary.csv"),
                        io::EvaluationLinesSummaryCsv(lines));
    outputs.push_back("evaluation_lines_summary.csv");
  }
  // Barriers: summarised from the complete barriers.csv.
  std::vector<io::BarrierSummary> barriers;
  if (!scene.scene.barriers.empty()) {
    barriers =
        io::SummarizeBarriers(staging.path("barriers.csv"), scene.scene.barriers, report.rocks);
    WriteFileAtomically(staging.path("barriers_summary.csv"), io::BarriersSummaryCsv(barriers));
    outputs.push_back("barriers_summary.csv");
  }
  // Forest: summarised from the complete tree_impacts.csv.
  std::optional<io::TreeImpactSummary> trees;
  if (scene.has_forest) trees = io::SummarizeTreeImpacts(staging.path("tree_impacts.csv"));
  std::vector<io::MapLine> map_lines;
  for (const ensemble::EvaluationLine& line : scene.evaluation_lines)
    map_lines.push_back({line.name, line.vertices_m});
  for (const Barrier& barrier : scene.scene.barriers)
    map_lines.push_back({barrier.name, barrier.vertices_m});
  // The paths, drawn once for the quick-look and the report's maps.
  io::MapPaths map_paths;
  if (scene.output.quicklook || (scene.output.report && !layers.empty())) {
    std::vector<std::vector<Eigen::Vector2d>> xy;
    for (const io::SamplePath& p : paths) xy.push_back(p.xy_m);
    map_paths = io::MapPaths(scene.scene.terrain.heights().grid, xy);
  }
  std::string quicklook_png;
  if (scene.output.quicklook) {
    quicklook_png = io::QuickLookPngOf(scene.scene.terrain.heights(), io::QuickLookLayer(layers),
                                       map_paths, {}, map_lines);
    WriteFileAtomically(staging.path("quicklook.png"), quicklook_png);
    outputs.push_back("quicklook.png");
    wrote(1);
  }
  if (scene.output.geopackage) {
    ThrowIfInterrupted();
    io::WriteRocksGeoPackage(
        staging.path("rocks.gpkg"), staging.path("rocks.csv"),
        scene.output.trajectories ? staging.path("trajectories.h5") : std::string(), scene.crs_wkt,
        scene.evaluation_lines.empty() ? std::string() : staging.path("evaluation_lines.csv"),
        scene.scene.barriers.empty() ? std::string() : staging.path("barriers.csv"),
        io::GeoPackageScene{&scene.release, &scene.evaluation_lines, &scene.scene.barriers,
                            &scene.scene.forest,
                            scene.has_forest ? staging.path("tree_impacts.csv") : std::string()});
    outputs.push_back("rocks.gpkg");
    wrote(1);
  }
  if (scene.output.report) outputs.push_back("report.html");
  const std::string summary = io::SummaryJson(scene, report, kVersion, outputs, lines, self_check,
                                              barriers, trees ? &*trees : nullptr, layers);
  if (scene.output.report) {
    ThrowIfInterrupted();
    io::RunReportInput page;
    page.summary_json = summary;
    page.dem = &scene.scene.terrain.heights();
    page.layers = &layers;
    page.paths = std::move(map_paths);
    page.lines = std::move(map_lines);
    page.quicklook_png = std::move(quicklook_png);
    page.rocks = io::RockColumns(staging.path("rocks.csv"));
    WriteFileAtomically(staging.path("report.html"), io::RunReportHtml(page));
    wrote(1);
  }
  WriteFileAtomically(staging.path("summary.json"), summary);
  ThrowIfInterrupted();
  outputs.push_back("summary.json");
  wrote(1);
  return outputs;
}

// Copies `from` to `out`, without its first line when `skip_header`; that line must be `header`.
void AppendCsv(const std::string& from, bool skip_header, const std::string& header,
               std::ofstream& out) {
  std::ifstream in(from, std::ios::binary);
  std::string first;
  if (!in || !std::getline(in, first)) throw std::runtime_error("cannot read " + from);
  if (first != header)
    throw std::runtime_error(from + " does not start with the header of " +
                             fs::path(from).filename().string());
  if (!skip_header) out << first << '\n';
  if (in.peek() != std::ifstream::traits_type::eof()) out << in.rdbuf();
  if (in.bad()) throw std::runtime_error("cannot read " + from);
}

}  // namespace

bool QuickLookSample(const ensemble::ReleaseSpec& release, long rock) {
  constexpr long kPaths = 40, kReleases = 100;
  const long releases = release.release_count();
  const long stride = (releases + kReleases - 1) / kReleases;  // draw every stride-th release
  const long drawn = (releases + stride - 1) / stride;
  const int which = release.ReleaseOf(rock);
  const long per_release =
      std::clamp<long>((kPaths + drawn - 1) / drawn, 1, release.RocksOf(which));
  return which % stride == 0 && rock - release.FirstRockOf(which) < per_release;
}

std::vector<std::string> TalusOutputNames() {
  std::vector<std::string> names = {"rocks.csv",
                                    "trajectories.h5",
                                    "summary.json",
                                    "quicklook.png",
                                    "passages.tif",
                                    "deposits.tif",
                                    "reach_probability.tif",
                                    "partial.json",
                                    "partial.bin",
                                    "report.html",
                                    "rocks.gpkg",
                                    "evaluation_lines.csv",
                                    "evaluation_lines_summary.csv",
                                    "barriers.csv",
                                    "barriers_summary.csv",
                                    "tree_impacts.csv",
                                    "tree_hits.tif",
                                    kRunLog};
  for (const char* quantity : {"speed", "energy", "jump_height"}) {
    for (const char* statistic : {"max", "mean"})
      names.push_back(std::string(quantity) + "_" + statistic + ".tif");
    for (int percent = 1; percent <= 99; ++percent)  // every percentile [output] may ask for
      names.push_back(std::string(quantity) + "_p" + std::to_string(percent) + ".tif");
  }
  return names;
}

std::vector<std::string> RunIntoStaging(const io::SceneFile& scene, int threads, long first_rock,
                                        long end_rock, bool part, const StagingDirectory& staging,
                                        std::function<void(long, long)> progress,
                                        ensemble::EnsembleReport* report,
                                        const ensemble::SelfCheckReport* self_check) {
  ensemble::EnsembleOptions options;
  options.threads = threads;
  options.first_rock = first_rock;
  options.end_rock = end_rock;
  options.trajectories = scene.output.trajectories;
  options.trajectory_interval_s = scene.output.trajectory_interval_s;
  if (scene.output.quicklook || scene.output.report) {
    const ensemble::ReleaseSpec& release = scene.release;
    options.sample_trajectories = [&release](long rock) { return QuickLookSample(release, rock); };
  }
  options.rasters = scene.output.Request(scene.scene.terrain.heights().grid);
  options.keep_raster_state = part;
  // The values behind the percentile rasters, in the staging directory: never committed, removed
  // with the accumulator or, at the latest, with the staging directory.
  options.raster_spill.dir = staging.path("raster_spill");
  options.progress = std::move(progress);
  if (!scene.evaluation_lines.empty())
    options.evaluation_lines =
        std::make_shared<const std::vector<ensemble::EvaluationLine>>(scene.evaluation_lines);

  std::vector<std::string> outputs = {"rocks.csv"};
  io::RocksCsvWriter csv(staging.path("rocks.csv"), scene.scene, scene.release);
  std::unique_ptr<io::TrajectoryWriter> trajectories;
  if (scene.output.trajectories) {
    trajectories = std::make_unique<io::TrajectoryWriter>(staging.path("trajectories.h5"),
                                                          scene.scene.rock, scene.crs_wkt);
    outputs.push_back("trajectories.h5");
  }
  std::unique_ptr<io::EvaluationLinesCsvWriter> lines;
  if (!scene.evaluation_lines.empty()) {
    lines = std::make_unique<io::EvaluationLinesCsvWriter>(staging.path("evaluation_lines.csv"),
                                                           scene.evaluation_lines, scene.release);
    outputs.push_back("evaluation_lines.csv");
  }
  std::unique_ptr<io::BarriersCsvWriter> barriers;
  if (!scene.scene.barriers.empty()) {
    barriers = std::make_unique<io::BarriersCsvWriter>(staging.path("barriers.csv"),
                                                       scene.scene.barriers, scene.release);
    outputs.push_back("barriers.csv");
  }
  std::unique_ptr<io::TreeImpactsCsvWriter> trees;
  if (scene.has_forest) {
    trees = std::make_unique<io::TreeImpactsCsvWriter>(staging.path("tree_impacts.csv"),
                                                       scene.scene.forest, scene.release);
    outputs.push_back("tree_impacts.csv");
  }
  FileSink sink(csv, trajectories.get(), lines.get(), barriers.get(), trees.get(),
                options.sample_trajectories);
  *report = ensemble::RunEnsemble(scene.scene, scene.release, options, &sink);
  ThrowIfInterrupted();
  csv.Commit();
  if (trajectories) trajectories->Commit();
  if (lines) lines->Commit();
  if (barriers) barriers->Commit();
  if (trees) trees->Commit();
  if (!part)
    return WriteSummaryOutputs(scene, *report, report->rasters, sink.paths, staging, outputs,
                               self_check);
  io::WritePartialState(staging.path("partial.bin"), *report, sink.paths);
  report->raster_state.reset();  // its spill is in partial.bin now
  outputs.push_back("partial.bin");
  std::vector<std::string> files;  // sizes and checksums in partial.json
  for (const std::string& name : outputs) files.push_back(staging.path(name));
  WriteFileAtomically(staging.path("partial.json"),
                      io::PartialJson(scene, kVersion, first_rock, end_rock, *report, files));
  outputs.push_back("partial.json");  // last: a complete part is one with a partial.json
  return outputs;
}

std::vector<std::string> MergeIntoStaging(const io::SceneFile& scene,
                                          const std::vector<io::PartialInfo>& parts, int threads,
                                          double wall_time_s, const StagingDirectory& staging,
                                          ensemble::EnsembleReport* report,
                                          const MergeProgress& progress) {
  const auto show = [&](const std::string& phase, long done, long total, const char* unit) {
    if (progress) progress(phase, done, total, unit);
  };
  const long n_parts = static_cast<long>(parts.size());
  *report = ensemble::EnsembleReport{};
  std::vector<std::string> outputs;
  // A CSV file of every part, appended in the parts' order under one header.
  const auto merge_csv = [&](const std::string& name, const std::string& header) {
    std::ofstream csv(staging.path(name), std::ios::binary);
    for (long k = 0; k < n_parts; ++k) {
      ThrowIfInterrupted();
      show("Merging " + name, k, n_parts, "parts");
      AppendCsv((fs::path(parts[k].dir) / name).string(), k > 0, header, csv);
    }
    csv.close();
    if (!csv) throw std::runtime_error("cannot write " + staging.path(name));
    show("Merging " + name, n_parts, n_parts, "parts");
    outputs.push_back(name);
  };
  merge_csv("rocks.csv", io::RocksCsvWriter::Header());
  if (scene.output.trajectories) {
    io::TrajectoryWriter out(staging.path("trajectories.h5"), scene.scene.rock, scene.crs_wkt);
    long total = 0, done = 0;
    for (const io::PartialInfo& part : parts) total += part.end_rock - part.first_rock;
    for (const io::PartialInfo& part : parts) {
      const io::TrajectoryReader in((fs::path(part.dir) / "trajectories.h5").string());
      for (long rock = part.first_rock; rock < part.end_rock; ++rock) {
        if ((rock & 255) == 0) ThrowIfInterrupted();
        out.Write(rock, in.Read(rock));
        show("Merging trajectories.h5", ++done, total, "rocks");
      }
    }
    out.Commit();
    outputs.push_back("trajectories.h5");
  }
  if (!scene.evaluation_lines.empty())
    merge_csv("evaluation_lines.csv", io::EvaluationLinesCsvWriter::Header());
  if (!scene.scene.barriers.empty()) merge_csv("barriers.csv", io::BarriersCsvWriter::Header());
  if (scene.has_forest) merge_csv("tree_impacts.csv", io::TreeImpactsCsvWriter::Header());
  const ensemble::RasterRequest request = scene.output.Request(scene.scene.terrain.heights().grid);
  std::optional<ensemble::RasterAccumulator> rasters;
  ensemble::RasterSpillOptions spill;
  spill.dir = staging.path("raster_spill");
  std::vector<io::SamplePath> paths;
  for (long k = 0; k < n_parts; ++k) {
    ThrowIfInterrupted();
    show("Merging the rasters (partial.bin)", k, n_parts, "parts");
    io::ReadPartialState(parts[k], request, spill, &rasters, &paths);
    report->AddCounts(parts[k].counts);
  }
  show("Merging the rasters (partial.bin)", n_parts, n_parts, "parts");
  report->threads = threads;
  report->wall_time_s = wall_time_s;
  const std::vector<ensemble::RasterLayer> layers =
      rasters ? rasters->Finish(scene.scene.terrain.heights())
              : std::vector<ensemble::RasterLayer>{};
  return WriteSummaryOutputs(scene, *report, layers, paths, staging, outputs, nullptr, progress);
}

PhaseProgress::PhaseProgress() : enabled_(ShowsProgress()) {}

void PhaseProgress::operator()(const std::string& phase, long done, long total, const char* unit) {
  if (!enabled_ || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (phase != phase_) {
    phase_ = phase;
    start_ = now;
  } else if (done < total && now - shown_ < std::chrono::milliseconds(100)) {
    return;
  }
  shown_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  if (std::string(unit) == "bytes")
    Status(ProgressLine(phase, double(done) / 1e6, double(total) / 1e6, "MB", 1, elapsed_s));
  else
    Status(ProgressLine(phase, double(done), double(total), unit, 0, elapsed_s));
}

void PhaseProgress::Break() {
  if (enabled_) EndStatus();
}

std::vector<io::PartialInfo> ReadParts(const std::vector<std::string>& dirs,
                                       const MergeProgress& progress) {
  std::vector<io::PartialInfo> parts;
  for (const std::string& dir : dirs) parts.push_back(io::ReadPartialInfo(dir));
  parts = io::CheckPartials(std::move(parts));
  // Every byte of every part is read for its checksum: the progress counts them.
  long total = 0;
  for (const io::PartialInfo& part : parts)
    for (const auto& [name, file] : part.files) total += static_cast<long>(file.bytes);
  long done = 0;
  const auto on_bytes = [&](std::uint64_t n) {
    done += static_cast<long>(n);
    if (progress) progress("Checking the parts", done, total, "bytes");
  };
  for (const io::PartialInfo& part : parts) io::CheckPartFiles(part, on_bytes);
  return parts;
}

namespace {

// The names a manifest lists that talus may have written there: a file it finds that is neither
// gives it no licence to remove anything.
std::vector<std::string> ReadManifest(const fs::path& path) {
  const std::vector<std::string> known = TalusOutputNames();
  std::vector<std::string> names;
  std::ifstream in(path);
  for (std::string name; std::getline(in, name);)
    if (std::find(known.begin(), known.end(), name) != known.end() &&
        std::find(names.begin(), names.end(), name) == names.end())
      names.push_back(name);
  return names;
}

std::string ManifestText(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += name + "\n";
  return text;
}

}  // namespace

void CommitOutputs(StagingDirectory& staging, const std::vector<std::string>& files,
                   const std::string& dir) {
  const fs::path manifest = fs::path(dir) / kOutputManifest;
  const std::vector<std::string> earlier = ReadManifest(manifest);
  // Until the files are in, the manifest lists the earlier run's and this one's: an interruption
  // in between leaves no file of either unlisted.
  // The run log is listed too: written after the outputs by the verb that succeeded (WriteRunLog),
  // it is this run's, never staged, and never removed here.
  std::vector<std::string> listed = files;
  listed.push_back(kRunLog);
  std::vector<std::string> both = earlier;
  for (const std::string& name : listed)
    if (std::find(both.begin(), both.end(), name) == both.end()) both.push_back(name);
  WriteFileAtomically(manifest.string(), ManifestText(both));
  staging.Commit(files);
  // An earlier run's outputs that this run did not replace must not pass for this run's; only
  // what that run's manifest lists is removed, never a file of the same name the user made.
  int stale = 0;
  for (const std::string& name : earlier) {
    if (std::find(listed.begin(), listed.end(), name) != listed.end()) continue;
    std::error_code error;
    stale += fs::remove(fs::path(dir) / name, error) ? 1 : 0;
  }
  WriteFileAtomically(manifest.string(), ManifestText(listed));
  if (stale > 0) Say("Removed %d outputs of an earlier run from %s\n", stale, dir.c_str());
}

io::SceneFile LoadSceneOfPart(const io::PartialInfo& part) {
  io::SceneFile scene = io::LoadScene(part.scene_file);
  if (scene.inputs_hash != part.inputs_hash)
    throw InputError(part.dir + ": the scene " + part.scene_file +
                     " or its data files changed since this part was run (inputs hash " +
                     scene.inputs_hash + ", was " + part.inputs_hash + ")");
  scene.path = part.scene;
  scene.inputs = part.inputs;
  // A part run with --rocks has that many rocks per release (0: the scene's counts).
  if (part.rocks_per_release > 0) scene.release.SetRocksPerRelease(part.rocks_per_release);
  scene.release.seed = part.seed;
  SolverPreset preset = SolverPreset::kDefault;
  if (!ParseSolverPreset(part.solver_preset, &preset))
    throw InputError(part.dir + ": unknown solver preset '" + part.solver_preset + "'");
  if (part.solver_preset_from_command_line) io::UseSolverPreset(scene, preset);
  if (scene.release.total_rocks() != part.total_rocks)
    throw InputError(part.dir + ": the scene gives " + std::to_string(scene.release.total_rocks()) +
                     " rocks, the part " + std::to_string(part.total_rocks));
  return scene;
}

std::pair<long, long> ParseRockRange(const std::string& text) {
  const std::size_t colon = text.find(':');
  long first = -1, end = -1;
  const auto number = [](const std::string& s, long* value) {
    const auto [at, error] = std::from_chars(s.data(), s.data() + s.size(), *value);
    return !s.empty() && error == std::errc() && at == s.data() + s.size() && *value >= 0;
  };
  if (colon == std::string::npos || !number(text.substr(0, colon), &first) ||
      !number(text.substr(colon + 1), &end))
    throw InputError("--rock-range: expected A:B (rocks A .. B - 1, 0 <= A < B), got '" + text +
                     "'");
  if (end <= first)
    throw InputError("--rock-range " + text + ": the range is empty (B must be greater than A)");
  return {first, end};
}

}  // namespace talus::app
