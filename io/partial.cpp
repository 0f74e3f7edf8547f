#include "io/partial.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/bytes.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/sha256.hpp"
#include "io/barriers_csv.hpp"
#include "io/evaluation_lines_csv.hpp"
#include "io/rocks_csv.hpp"
#include "io/tree_impacts_csv.hpp"

namespace talus::io {
namespace {

constexpr const char* kFormat = "talus partial result";
// 2: the files' sizes and checksums; 3: the ending "barrier", rocks.csv's end_barrier column and
// barriers.csv; 4: SHA-256 for the inputs' hash and the files' checksums instead of FNV-1a 64,
// and the cell summaries' level (bins capped at ValueSummary::kMaxBins); 5: partial.bin's head
// length first and the values behind the percentile rasters after it (raster_spill.hpp), the
// cell summaries without histograms.
constexpr int kFormatVersion = 5;
constexpr const char* kStateMagic = "talus partial state 2";

std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error("cannot read " + path);
  return s.str();
}

std::string Range(long first, long end) {
  return std::to_string(first) + ":" + std::to_string(end);
}

// Size and SHA-256 of a file, read in chunks; `on_bytes`, when given, hears each chunk's size.
PartialInfo::File FileEntry(const std::string& path,
                            const std::function<void(std::uint64_t)>& on_bytes = {}) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  Sha256 hash;
  PartialInfo::File f;
  std::string chunk(1 << 20, '\0');
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount());
    hash.Add(std::string_view(chunk.data(), n));
    f.bytes += n;
    if (on_bytes) on_bytes(n);
  }
  if (in.bad()) throw std::runtime_error("cannot read " + path);
  f.sha256 = hash.HexDigest();
  return f;
}

// The rock of each record of a CSV file of the part (column `rock`), checked by `check(rock, line)`
// which returns "" or what is wrong. Throws InputError "<path>:<line>: ..." naming the problem.
template <class Check>
void CheckRockColumn(const std::string& path, const std::string& header, Check check) {
  CsvReader in(path);
  std::string first;
  for (const std::string& c : in.header()) first += (first.empty() ? "" : ",") + c;
  if (first != header)
    throw InputError(path + ": not the header of talus's " +
                     std::filesystem::path(path).filename().string());
  const std::size_t column = in.Column("rock");
  std::vector<std::string> fields;
  while (in.Next(&fields)) {
    long rock = -1;
    const std::string& text = fields[column];
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), rock);
    if (error != std::errc() || end != text.data() + text.size())
      throw InputError(path + ":" + std::to_string(in.line()) + ": rock '" + text +
                       "' is not a rock number");
    if (const std::string why = check(rock); !why.empty())
      throw InputError(path + ":" + std::to_string(in.line()) + ": " + why);
  }
}

}  // namespace

std::string PartialJson(const SceneFile& scene, const std::string& version, long first_rock,
                        long end_rock, const ensemble::EnsembleReport& report,
                        const std::vector<std::string>& files) {
  nlohmann::ordered_json j;
  j["format"] = kFormat;
  j["format_version"] = kFormatVersion;
  j["talus_version"] = version;
  j["scene"] = scene.path;
  j["scene_file"] = std::filesystem::absolute(scene.path).lexically_normal().string();
  j["inputs"] = scene.inputs;
  j["inputs_sha256"] = scene.inputs_hash;
  j["seed"] = scene.release.seed;
  // 0 when the releases have rocks of their own (rocks_per_m2): the scene gives them.
  j["rocks_per_release"] =
      scene.release.release_first_rock.empty() ? scene.release.rocks_per_release : 0;
  j["solver_preset"] = ToString(scene.solver_preset);
  j["solver_preset_from_command_line"] = scene.solver_preset_from_command_line;
  j["total_rocks"] = scene.release.total_rocks();
  j["first_rock"] = first_rock;
  j["end_rock"] = end_rock;
  j["trajectories"] = scene.output.trajectories;
  j["rocks"] = report.rocks;
  j["ends"] = report.by_end;
  j["raised_at_release"] = report.raised;
  j["stayed_at_release"] = report.stayed_at_release;
  j["steps"] = report.steps;
  j["unconverged_steps"] = report.unconverged_steps;
  j["threads"] = report.threads;
  j["wall_time_s"] = report.wall_time_s;
  nlohmann::ordered_json entries = nlohmann::ordered_json::object();
  for (const std::string& path : files) {
    const PartialInfo::File f = FileEntry(path);
    entries[std::filesystem::path(path).filename().string()] = {{"bytes", f.bytes},
                                                                {"sha256", f.sha256}};
  }
  j["files"] = entries;
  return j.dump(2) + "\n";
}

void WritePartialState(const std::string& path, const ensemble::EnsembleReport& report,
                       const std::vector<SamplePath>& paths) {
  ByteWriter head;
  head.PutString(kStateMagic);
  head.Put<std::uint8_t>(report.raster_state ? 1 : 0);
  if (report.raster_state) report.raster_state->Serialize(head);
  head.Put<std::uint64_t>(paths.size());
  for (const SamplePath& p : paths) {
    head.Put<std::int64_t>(p.rock);
    std::vector<double> xy;
    for (const Eigen::Vector2d& v : p.xy_m) xy.insert(xy.end(), {v.x(), v.y()});
    head.PutVector(xy);
  }
  AtomicFile file(path);
  std::ofstream out(file.temp_path(), std::ios::binary);
  const std::uint64_t head_bytes = head.bytes().size();
  out.write(reinterpret_cast<const char*>(&head_bytes), sizeof head_bytes);
  out.write(head.bytes().data(), static_cast<std::streamsize>(head_bytes));
  if (report.raster_state) report.raster_state->WriteSpill(out);
  out.close();
  if (!out) throw std::runtime_error("cannot write " + path);
  file.Commit();
}

PartialInfo ReadPartialInfo(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "partial.json").string();
  if (!std::filesystem::is_regular_file(path))
    throw InputError(dir + ": not a complete partial result of talus simulate --rock-range (no " +
                     path + ")");
  PartialInfo p;
  p.dir = dir;
  try {
    const nlohmann::json j = nlohmann::json::parse(ReadWholeFile(path));
    if (j.at("format") != kFormat)
      throw InputError(path + ": not a partial result of talus simulate --rock-range (format " +
                       j.at("format").dump() + ")");
    if (const int version = j.at("format_version"); version != kFormatVersion) {
      // A part of another talus cannot be checked or merged: it is run again. Version 3 and
      // before summed the files up with FNV-1a 64, which this talus no longer computes.
      std::string again = "run the part again with this talus";
      const auto scene = j.find("scene");
      const auto first = j.find("first_rock"), end = j.find("end_rock");
      if (scene != j.end() && scene->is_string() && first != j.end() &&
          first->is_number_integer() && end != j.end() && end->is_number_integer())
        again += " (talus simulate " + scene->get<std::string>() + " --rock-range " +
                 Range(first->get<long>(), end->get<long>()) + " and the options it ran with)";
      throw InputError(
          path + ": a part written by " + (version < kFormatVersion ? "an older" : "a newer") +
          " talus (partial result format " + std::to_string(version) + ", this talus reads " +
          std::to_string(kFormatVersion) +
          (version < 4 ? "; its checksums are FNV-1a, this talus checks SHA-256" : "") +
          "): " + again);
    }
    p.version = j.at("talus_version");
    p.scene = j.at("scene");
    p.scene_file = j.at("scene_file");
    p.inputs = j.at("inputs").get<std::vector<std::string>>();
    p.inputs_hash = j.at("inputs_sha256");
    p.seed = j.at("seed");
    p.rocks_per_release = j.at("rocks_per_release");
    p.solver_preset = j.at("solver_preset");
    p.solver_preset_from_command_line = j.value("solver_preset_from_command_line", false);
    p.total_rocks = j.at("total_rocks");
    p.first_rock = j.at("first_rock");
    p.end_rock = j.at("end_rock");
    p.trajectories = j.at("trajectories");
    p.counts.rocks = j.at("rocks");
    p.counts.by_end = j.at("ends").get<decltype(p.counts.by_end)>();
    p.counts.raised = j.at("raised_at_release");
    p.counts.stayed_at_release = j.at("stayed_at_release");
    p.counts.steps = j.at("steps");
    p.counts.unconverged_steps = j.at("unconverged_steps");
    p.counts.threads = j.at("threads");
    p.counts.wall_time_s = j.at("wall_time_s");
    for (const auto& [name, f] : j.at("files").items()) {
      if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
        throw InputError(path + ": files: '" + name + "' is not a file name");
      p.files[name] = {f.at("bytes").get<std::uint64_t>(), f.at("sha256").get<std::string>()};
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path + ": not a valid partial.json: " + e.what());
  }
  if (p.first_rock < 0 || p.end_rock < p.first_rock || p.end_rock > p.total_rocks ||
      p.counts.rocks != p.end_rock - p.first_rock)
    throw InputError(path + ": inconsistent rock range " + Range(p.first_rock, p.end_rock));
  return p;
}

void CheckPartFiles(const PartialInfo& part, const std::function<void(std::uint64_t)>& on_bytes) {
  const std::string json = (std::filesystem::path(part.dir) / "partial.json").string();
  std::vector<std::string> required = {"rocks.csv", "partial.bin"};
  if (part.trajectories) required.push_back("trajectories.h5");
  for (const std::string& name : required)
    if (!part.files.count(name))
      throw InputError(json + ": files: no " + name + " (every part has it)");
  for (const auto& [name, want] : part.files) {
    const std::string path = (std::filesystem::path(part.dir) / name).string();
    if (!std::filesystem::is_regular_file(path))
      throw InputError(path + ": missing (partial.json lists it)");
    PartialInfo::File have;
    try {
      have = FileEntry(path, on_bytes);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
    if (have.bytes != want.bytes || have.sha256 != want.sha256)
      throw InputError(path + ": " + std::to_string(have.bytes) + " bytes with SHA-256 " +
                       have.sha256 + ", but partial.json says " + std::to_string(want.bytes) +
                       " bytes with " + want.sha256 +
                       ": changed or damaged since the part was run");
  }
  // The rows: rocks.csv has each rock of the part once, in order; evaluation_lines.csv and
  // barriers.csv only rocks of the part, in order.
  const std::string range = "the part holds rocks " + Range(part.first_rock, part.end_rock);
  const std::string rocks_csv = (std::filesystem::path(part.dir) / "rocks.csv").string();
  long next = part.first_rock;
  CheckRockColumn(rocks_csv, RocksCsvWriter::Header(), [&](long rock) -> std::string {
    if (rock != next)
      return "rock " + std::to_string(rock) + " where rock " + std::to_string(next) + " was due (" +
             range + ")";
    ++next;
    return "";
  });
  if (next != part.end_rock)
    throw InputError(rocks_csv + ": no row of rock " + std::to_string(next) + " or later (" +
                     range + ")");
  for (const auto& [name, header] :
       {std::pair{"evaluation_lines.csv", EvaluationLinesCsvWriter::Header()},
        std::pair{"barriers.csv", BarriersCsvWriter::Header()},
        std::pair{"tree_impacts.csv", TreeImpactsCsvWriter::Header()}}) {
    if (!part.files.count(name)) continue;
    long last = part.first_rock;
    CheckRockColumn((std::filesystem::path(part.dir) / name).string(), header,
                    [&](long rock) -> std::string {
                      if (rock < last || rock >= part.end_rock)
                        return "rock " + std::to_string(rock) +
                               " out of order or not of the part (" + range + ")";
                      last = rock;
                      return "";
                    });
  }
}

std::vector<PartialInfo> CheckPartials(std::vector<PartialInfo> parts) {
  if (parts.empty()) throw InputError("no partial results to merge");
  const PartialInfo& a = parts.front();
  for (const PartialInfo& b : parts) {
    const auto differ = [&](const std::string& what, const std::string& x, const std::string& y) {
      throw InputError(a.dir + " and " + b.dir + " are parts of different runs: " + what + " " + x +
                       " and " + y);
    };
    if (b.version != a.version) differ("talus versions", a.version, b.version);
    if (b.inputs_hash != a.inputs_hash)
      differ("scenes (inputs hash)", a.scene + " " + a.inputs_hash, b.scene + " " + b.inputs_hash);
    if (b.scene_file != a.scene_file) differ("scene files", a.scene_file, b.scene_file);
    if (b.seed != a.seed) differ("seeds", std::to_string(a.seed), std::to_string(b.seed));
    if (b.solver_preset != a.solver_preset)
      differ("solver presets", a.solver_preset, b.solver_preset);
    if (b.solver_preset_from_command_line != a.solver_preset_from_command_line)
      differ("solver presets", a.solver_preset_from_command_line ? "--preset" : "the scene's",
             b.solver_preset_from_command_line ? "--preset" : "the scene's");
    if (b.rocks_per_release != a.rocks_per_release || b.total_rocks != a.total_rocks)
      differ("rocks", std::to_string(a.total_rocks), std::to_string(b.total_rocks));
  }
  std::sort(parts.begin(), parts.end(), [](const PartialInfo& x, const PartialInfo& y) {
    return x.first_rock != y.first_rock ? x.first_rock < y.first_rock : x.end_rock < y.end_rock;
  });
  long covered = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const PartialInfo& p = parts[k];
    if (p.first_rock > covered)
      throw InputError("rocks " + Range(covered, p.first_rock) + " of " +
                       std::to_string(a.total_rocks) +
                       " are in no partial result (the next part, " + p.dir + ", starts at rock " +
                       std::to_string(p.first_rock) + ")");
    if (p.first_rock < covered)
      throw InputError("rocks " + Range(p.first_rock, p.end_rock) + " of " + p.dir +
                       " overlap rocks " + Range(parts[k - 1].first_rock, parts[k - 1].end_rock) +
                       " of " + parts[k - 1].dir);
    covered = p.end_rock;
  }
  if (covered < a.total_rocks)
    throw InputError("rocks " + Range(covered, a.total_rocks) + " of " +
                     std::to_string(a.total_rocks) + " are in no partial result");
  return parts;
}

void ReadPartialState(const PartialInfo& part, const ensemble::RasterRequest& request,
                      const ensemble::RasterSpillOptions& spill,
                      std::optional<ensemble::RasterAccumulator>* rasters,
                      std::vector<SamplePath>* paths) {
  const std::string path = (std::filesystem::path(part.dir) / "partial.bin").string();
  // The head in memory; the spilled values streamed into the accumulator's spill.
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot read " + path);
  std::uint64_t head_bytes = 0;
  std::string head;
  if (file.read(reinterpret_cast<char*>(&head_bytes), sizeof head_bytes) &&
      head_bytes <= std::filesystem::file_size(path)) {
    head.resize(head_bytes);
    file.read(head.data(), static_cast<std::streamsize>(head_bytes));
  }
  if (!file) throw std::runtime_error(path + " is truncated or damaged");
  ByteReader in(head, path);
  if (in.GetString() != kStateMagic) in.Fail("is not a partial state of this version of talus");
  const bool has_rasters = in.Get<std::uint8_t>() != 0;
  if (has_rasters != request.any()) in.Fail("holds other rasters than the scene asks for");
  if (has_rasters) {
    if (!rasters->has_value()) rasters->emplace(request, spill);
    const long before = (*rasters)->rocks();
    (*rasters)->MergeSerialized(in, file);
    if ((*rasters)->rocks() - before != part.counts.rocks)
      in.Fail("holds another number of rocks than partial.json");
  }
  const auto n = in.Get<std::uint64_t>();
  for (std::uint64_t k = 0; k < n; ++k) {
    SamplePath& p = paths->emplace_back();
    p.rock = static_cast<long>(in.Get<std::int64_t>());
    const auto xy = in.GetVector<double>();
    for (std::size_t i = 0; i + 1 < xy.size(); i += 2) p.xy_m.emplace_back(xy[i], xy[i + 1]);
  }
  if (!in.at_end() || file.peek() != std::ifstream::traits_type::eof()) in.Fail();
}

}  // namespace talus::io
