#include "io/validation_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "io/quicklook.hpp"
#include "io/rocks_csv.hpp"
#include "io/svg_plot.hpp"

namespace talus::io {
namespace {

// NaN and infinities are null in JSON.
nlohmann::ordered_json Num(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

// "%.10g", or an empty field for NaN (a value that does not exist).
std::string Csv(double v) { return FormatOrMissing(v, "%.10g", ""); }

std::string Fmt(double v, const char* format = "%.3g") { return FormatDouble(v, format); }

}  // namespace

nlohmann::ordered_json BlockBiasJson(const std::vector<fieldobs::BlockBias>& biases) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const fieldobs::BlockBias& b : biases)
    out.push_back({{"block", b.block},
                   {"kind", b.kind},
                   {"unit", b.unit},
                   {"scored", b.scored},
                   {"mean_bias", Num(b.mean_bias)},
                   {"mean_score", Num(b.mean_score)}});
  return out;
}

std::string ScoresJson(const EventFile& event, const fieldobs::ValidationReport& report,
                       const ValidationRun& run) {
  nlohmann::ordered_json j;
  j["talus_version"] = run.version;
  j["event"] = event.path;
  j["scene"] = event.scene.path;
  j["inputs"] = event.inputs;
  j["inputs_hash_fnv1a64"] = event.inputs_hash;
  j["rocks_per_run"] = run.rocks_per_run;
  j["runs"] = event.scene.release.release_count();
  j["seed"] = run.seed;
  j["reference"] = {{"parameters", event.reference},
                    {"simulated", run.reference_run},
                    {"note", run.reference_run || event.reference == "none"
                                 ? ""
                                 : "the scene's ground table is the reference: skill 0"}};
  j["ends"] = {{"rest", run.ensemble.count(EndReason::kRest)},
               {"left_domain", run.ensemble.count(EndReason::kLeftDomain)},
               {"max_time", run.ensemble.count(EndReason::kMaxTime)},
               {"failed", run.ensemble.count(EndReason::kFailed)}};
  if (!event.scene.scene.barriers.empty())
    j["ends"]["barrier"] = run.ensemble.count(EndReason::kBarrier);
  j["observations"] = report.observations.size();
  j["observations_scored"] = report.observations_scored;
  j["not_scored"] = event.not_scored;  // observed values without a simulated counterpart
  j["overall"] = {{"skill_vs_reference", Num(report.skill_vs_reference)},
                  {"skill_vs_climatology", Num(report.skill_vs_climatology)}};
  nlohmann::ordered_json kinds = nlohmann::ordered_json::object();
  for (const fieldobs::KindSummary& k : report.kinds) {
    nlohmann::ordered_json kind;
    kind["unit"] = k.unit;
    kind["score"] = k.kind == "deposit" ? "energy_score" : "crps";
    kind["observations"] = k.observations;
    kind["scored"] = k.scored;
    kind["mean_score"] = Num(k.mean_score);
    kind["mean_reference_score"] = Num(k.mean_reference_score);
    kind["mean_climatology_score"] = Num(k.mean_climatology_score);
    kind["skill_vs_reference"] = Num(k.skill_vs_reference);
    kind["skill_vs_climatology"] = Num(k.skill_vs_climatology);
    kind["inside_90_fraction"] = Num(k.inside_90_fraction);
    kind["mean_bias"] = Num(k.mean_bias);
    kind["mean_sd"] = Num(k.mean_sd);
    if (!k.pit.counts.empty())
      kind["pit"] = {{"counts", k.pit.counts},
                     {"chi_square", Num(k.pit.chi_square)},
                     {"degrees_of_freedom", k.pit.degrees_of_freedom},
                     {"p_value", Num(k.pit.p_value)}};
    kinds[k.kind] = kind;
  }
  j["kinds"] = kinds;
  j["blocks"] = BlockBiasJson(fieldobs::BiasByBlock(report.observations, event.scene.release));
  j["warnings"] = event.scene.warnings;
  nlohmann::ordered_json mismatches = nlohmann::ordered_json::array();
  for (const GroundMismatch& m : event.scene.ground_mismatches)
    mismatches.push_back({{"run", m.run},
                          {"where", m.where},
                          {"dem_z_m", m.dem_z_m},
                          {"surveyed_ground_z_m", m.surveyed_z_m}});
  j["start_ground_mismatch"] = mismatches;
  j["wall_time_s"] = run.wall_time_s;
  j["threads"] = run.threads;
  return j.dump(2) + "\n";
}

std::string ObservationsCsv(const fieldobs::ValidationReport& report) {
  std::string out =
      "kind,run,unit,observed,observed_x_m,observed_y_m,scored,members,score,pit,mean,median,sd,"
      "q05,q95,inside_90,bias,reference_score,climatology_score,source,note\n";
  for (const fieldobs::ObservationScore& s : report.observations) {
    out += CsvField(s.kind) + "," + CsvField(s.run) + "," + s.unit + "," + Csv(s.observed) + "," +
           Csv(s.observed_xy_m.x()) + "," + Csv(s.observed_xy_m.y()) + "," +
           (s.scored ? "1" : "0") + "," + std::to_string(s.members) + "," + Csv(s.score) + "," +
           Csv(s.pit) + "," + Csv(s.mean) + "," + Csv(s.median) + "," + Csv(s.sd) + "," +
           Csv(s.q05) + "," + Csv(s.q95) + "," + (s.scored ? (s.inside_90 ? "1" : "0") : "") + "," +
           Csv(s.bias) + "," + Csv(s.reference_score) + "," + Csv(s.climatology_score) + "," +
           CsvField(s.where) + "," + CsvField(s.not_scored) + "\n";
  }
  return out;
}

std::string ObservedVsSimulatedSvg(const fieldobs::ValidationReport& report) {
  // One panel per scalar kind: observations sorted by observed value along x; for each, the
  // simulated 5-95 % band (grey bar), median (blue tick) and the observed value (red dot).
  const int width = 720, panel = 260, margin = 50;
  std::vector<const fieldobs::KindSummary*> kinds;
  for (const auto& k : report.kinds)
    if (k.kind != "deposit" && k.scored > 0) kinds.push_back(&k);
  const int height = std::max(1, static_cast<int>(kinds.size())) * (panel + 30) + 20;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
         "fill=\"white\"/>\n";
  if (kinds.empty()) svg << "<text x=\"20\" y=\"20\">no scalar observation was scored</text>\n";
  int top = 20;
  for (const fieldobs::KindSummary* k : kinds) {
    std::vector<const fieldobs::ObservationScore*> obs;
    for (const auto& s : report.observations)
      if (s.kind == k->kind && s.scored) obs.push_back(&s);
    std::sort(obs.begin(), obs.end(), [](auto* a, auto* b) { return a->observed < b->observed; });
    double lo = obs.front()->observed, hi = lo;
    for (const auto* s : obs) {
      lo = std::min({lo, s->observed, s->q05});
      hi = std::max({hi, s->observed, s->q95});
    }
    if (hi <= lo) hi = lo + 1;
    const double pad = 0.05 * (hi - lo);
    lo -= pad;
    hi += pad;
    const int x0 = margin + 10, x1 = width - 20, y0 = top + 20, y1 = top + panel;
    auto y = [&](double v) { return y1 - (v - lo) / (hi - lo) * (y1 - y0); };
    svg << "<text x=\"" << x0 << "\" y=\"" << top + 12 << "\" font-weight=\"bold\">"
        << svg::Escape(k->kind) << " (" << svg::Escape(k->unit)
        << "): observed (red) vs simulated 5-95 % band "
        << "and median (blue); mean CRPS " << Fmt(k->mean_score) << "</text>\n";
    svg << "<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << x1 - x0 << "\" height=\""
        << y1 - y0 << "\" fill=\"none\" stroke=\"#888\"/>\n";
    for (int t = 0; t <= 4; ++t) {
      const double v = lo + (hi - lo) * t / 4;
      svg << "<text x=\"" << x0 - 4 << "\" y=\"" << y(v) + 4 << "\" text-anchor=\"end\">" << Fmt(v)
          << "</text>\n";
    }
    const double step = double(x1 - x0) / double(obs.size());
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const double x = x0 + (double(i) + 0.5) * step;
      const auto* s = obs[i];
      svg << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"" << y(s->q05) << "\" y2=\""
          << y(s->q95) << "\" stroke=\"#bbb\" stroke-width=\"" << std::max(1.0, 0.6 * step)
          << "\"><title>" << svg::Escape(s->run) << "</title></line>\n";
      svg << "<line x1=\"" << x - 0.4 * step << "\" x2=\"" << x + 0.4 * step << "\" y1=\""
          << y(s->median) << "\" y2=\"" << y(s->median) << "\" stroke=\"#1f4fbf\" "
          << "stroke-width=\"2\"/>\n";
      svg << "<circle cx=\"" << x << "\" cy=\"" << y(s->observed)
          << "\" r=\"3\" fill=\"#d7191c\"/>\n";
    }
    top += panel + 30;
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string PitSvg(const fieldobs::ValidationReport& report) {
  // One histogram per scalar kind; a calibrated ensemble gives flat bars (dashed line).
  std::vector<const fieldobs::KindSummary*> kinds;
  for (const auto& k : report.kinds)
    if (!k.pit.counts.empty()) kinds.push_back(&k);
  const int w = 320, h = 220;
  const int width = std::max(1, static_cast<int>(kinds.size())) * w;
  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << h
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
         "fill=\"white\"/>\n";
  if (kinds.empty()) svg << "<text x=\"20\" y=\"20\">no PIT histogram (too few scalars)</text>\n";
  for (std::size_t p = 0; p < kinds.size(); ++p) {
    const fieldobs::PitHistogram& pit = kinds[p]->pit;
    const int left = static_cast<int>(p) * w + 30, bottom = h - 30, top = 40;
    int total = 0, most = 1;
    for (int c : pit.counts) {
      total += c;
      most = std::max(most, c);
    }
    const double expected = double(total) / double(pit.counts.size());
    const double top_value = std::max(double(most), 1.5 * expected);
    const double bar = double(w - 50) / double(pit.counts.size());
    svg << "<text x=\"" << left
        << "\" y=\"16\" font-weight=\"bold\">PIT: " << svg::Escape(kinds[p]->kind)
        << "</text>\n<text x=\"" << left
        << "\" y=\"32\">chi-square p = " << Fmt(pit.p_value, "%.2g") << " (" << total
        << " observations)</text>\n";
    for (std::size_t b = 0; b < pit.counts.size(); ++b) {
      const double height = (bottom - top) * pit.counts[b] / top_value;
      svg << "<rect x=\"" << left + b * bar << "\" y=\"" << bottom - height << "\" width=\""
          << bar - 2 << "\" height=\"" << height << "\" fill=\"#6a8fd0\"/>\n";
    }
    const double ey = bottom - (bottom - top) * expected / top_value;
    svg << "<line x1=\"" << left << "\" x2=\"" << left + (w - 50) << "\" y1=\"" << ey << "\" y2=\""
        << ey << "\" stroke=\"black\" stroke-dasharray=\"4 3\"/>\n";
    svg << "<text x=\"" << left << "\" y=\"" << bottom + 14 << "\">0</text><text x=\""
        << left + (w - 50) << "\" y=\"" << bottom + 14 << "\" text-anchor=\"end\">1</text>\n";
  }
  svg << "</svg>\n";
  return svg.str();
}

void WriteTextFile(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  std::FILE* out = std::fopen(file.temp_path().c_str(), "w");
  if (!out) throw std::runtime_error("cannot create " + file.temp_path());
  const bool ok = std::fwrite(text.data(), 1, text.size(), out) == text.size();
  if (std::fclose(out) != 0 || !ok) throw std::runtime_error("cannot write " + path);
  file.Commit();
}

void WriteDepositsPng(const std::string& path, const EventFile& event,
                      const fieldobs::EnsembleSamples& simulated) {
  std::vector<MapMarker> markers;
  for (const Eigen::Vector2d& end : simulated.EndPositions(""))
    markers.push_back({end, {40, 90, 220}, 1, "simulated rest position"});
  for (const fieldobs::DepositObservation& d : event.observations.deposits)
    markers.push_back({d.xy_m, {215, 25, 28}, 3, "observed rest position"});
  WriteQuickLookPng(path, event.scene.scene.terrain.heights(), nullptr, {}, markers);
}

}  // namespace talus::io
