#include "io/report_html.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/format.hpp"
#include "common/statistics.hpp"
#include "io/html_page.hpp"
#include "io/quicklook.hpp"
#include "io/svg_plot.hpp"

namespace talus::io {
namespace {

using html::Cell;
using html::Json;
using html::kEnergyUnit;
using html::kJoulesPerEnergyUnit;
using html::Number;
using html::NumberOf;
using svg::Add;
using svg::Escape;

}  // namespace

ColumnSource RockColumns(const std::string& rocks_csv) {
  std::array<std::size_t, kRockColumnCount> at{};
  {
    const CsvReader in(rocks_csv);
    at[kRunoutColumn] = in.Column("runout_m");
    at[kEnergyColumn] = in.Column("max_kinetic_energy_j");
    at[kJumpHeightColumn] = in.Column("max_jump_height_m");
    at[kSpeedColumn] = in.Column("max_speed_m_s");
    at[kTravelAngleColumn] = in.Column("travel_angle_deg");
  }
  return [rocks_csv, at](const ColumnSink& emit) {
    CsvReader in(rocks_csv);
    std::vector<std::string> fields;
    while (in.Next(&fields)) {
      for (std::size_t k = 0; k < kRockColumnCount; ++k) {
        const std::string& text = fields[at[k]];
        double v = std::numeric_limits<double>::quiet_NaN();
        if (!text.empty())
          v = CsvFieldNumber(text, rocks_csv + ":" + std::to_string(in.line()), in.header()[at[k]]);
        emit(k, k == kEnergyColumn ? v / kJoulesPerEnergyUnit : v);
      }
    }
  };
}

namespace {

// Percentiles the report shows; the histograms' median and 95 % are among them.
const std::vector<double> kPercents = {50, 90, 95, 99, 100};
constexpr std::size_t kMedian = 0, kP95 = 2;

// A histogram of one column's finite values: `count` in equal bins from `lo` to `hi`.
struct Histogram {
  double lo = 0, hi = 1;
  std::vector<long> count;
};

// Histograms of the columns `which` of `source`, in `bins` bins from 0 (or the smallest value,
// when negative) to the largest, in one reading of the source.
std::vector<Histogram> HistogramsOf(const ColumnSource& source,
                                    const std::vector<ColumnStatistics>& statistics,
                                    const std::vector<std::size_t>& which, int bins) {
  std::vector<Histogram> out(which.size());
  std::vector<int> slot(statistics.size(), -1);
  for (std::size_t k = 0; k < which.size(); ++k) {
    const ColumnStatistics& s = statistics[which[k]];
    Histogram& h = out[k];
    h.lo = s.finite > 0 ? std::min(0.0, s.min) : 0;
    h.hi = s.finite > 0 ? std::max(0.0, s.max) : 0;
    if (!(h.hi > h.lo)) h.hi = h.lo + 1;
    h.count.assign(static_cast<std::size_t>(bins), 0);
    slot[which[k]] = static_cast<int>(k);
  }
  source([&](std::size_t column, double v) {
    if (column >= slot.size() || slot[column] < 0 || !std::isfinite(v)) return;
    Histogram& h = out[static_cast<std::size_t>(slot[column])];
    const int b = std::min(bins - 1, static_cast<int>((v - h.lo) / (h.hi - h.lo) * bins));
    ++h.count[static_cast<std::size_t>(b)];
  });
  return out;
}

std::string HistogramSvg(const std::string& title, const std::string& x_label, const Histogram& h,
                         const ColumnStatistics& s) {
  const int bins = static_cast<int>(h.count.size());
  const long top = std::max<long>(1, *std::max_element(h.count.begin(), h.count.end()));
  const svg::Axis x{h.lo, h.hi, svg::kLeft, svg::kWidth - svg::kRight};
  const svg::Axis y{0, static_cast<double>(top) * 1.1, svg::kHeight - svg::kBottom, svg::kTop};
  std::string out = svg::Frame(title, x_label, "rocks", x, y);
  for (int b = 0; b < bins; ++b) {
    const double left = h.lo + (h.hi - h.lo) * b / bins,
                 right = h.lo + (h.hi - h.lo) * (b + 1) / bins;
    const double height = static_cast<double>(h.count[static_cast<std::size_t>(b)]);
    Add(out, "<rect x=\"", svg::F(x(left)), "\" y=\"", svg::F(y(height)), "\" width=\"",
        svg::F(x(right) - x(left)), "\" height=\"", svg::F(y(0) - y(height)),
        "\" fill=\"#1f5fbf\" fill-opacity=\"0.75\" stroke=\"white\"/>\n");
  }
  const std::string stats = "n = " + std::to_string(s.finite) + ", median " +
                            Number(s.percentiles[kMedian]) + ", 95 % " +
                            Number(s.percentiles[kP95]) + ", largest " + Number(s.max);
  Add(out, "<text x=\"", svg::F(svg::kWidth - svg::kRight - 6), "\" y=\"", svg::F(svg::kTop + 14),
      "\" text-anchor=\"end\">", stats, "</text>\n");
  return out + "</svg>\n";
}

}  // namespace

std::string HistogramSvg(const std::string& title, const std::string& x_label,
                         const std::vector<double>& values, int bins) {
  const ColumnSource source = [&values](const ColumnSink& emit) {
    for (double v : values) emit(0, v);
  };
  const std::vector<ColumnStatistics> s = SummarizeColumns(source, 1, kPercents);
  return HistogramSvg(title, x_label, HistogramsOf(source, s, {0}, bins)[0], s[0]);
}

namespace {

// The page's head and "What ran": scene, version, inputs hash, the summary's settings, the rock.
std::string WhatRanSection(const Json& summary) {
  const auto get = [&](const char* key) { return summary.contains(key) ? summary[key] : Json(); };
  const std::string scene = get("scene").is_string() ? get("scene").get<std::string>() : "";
  std::string html = html::Begin(
      "Talus run: " + scene,
      "Talus " + Cell(get("talus_version")) + ", inputs hash (SHA-256) " +
          Cell(get("inputs_sha256")) +
          ". Everything here is also in summary.json, rocks.csv and the GeoTIFFs next to this "
          "file.");
  html += html::Warnings(get("warnings"));

  html += "<h2>What ran</h2>\n";
  html += html::KeyValueTable(
      summary,
      {"ends", "raised_at_release", "stayed_at_release", "steps", "unconverged_steps", "threads",
       "wall_time_s", "trajectories_per_s", "outputs", "blocks", "talus_version", "inputs_sha256",
       "evaluation_lines", "barriers", "forest", "warnings"});
  if (summary.contains("rock") && summary["rock"].is_object()) {
    html += "<h3>Rock</h3>\n";
    html += html::KeyValueTable(summary["rock"]);
  }
  return html;
}

// "How the rocks ended": each ending's count and share, and the steps.
std::string EndingsSection(const Json& summary) {
  const auto get = [&](const char* key) { return summary.contains(key) ? summary[key] : Json(); };
  std::string html = "<h2>How the rocks ended</h2>\n<table>\n";
  const long rocks = get("rocks").is_number() ? get("rocks").get<long>() : 0;
  const auto count_row = [&](const std::string& label, const Json& value) {
    const double n = value.is_number() ? value.get<double>() : 0;
    Add(html, "<tr><th>", label, "</th><td>", Cell(value), "</td><td>",
        rocks > 0 ? Number(100 * n / rocks, "%.1f") + " %" : "", "</td></tr>\n");
  };
  if (summary.contains("ends"))
    for (const auto& [ending, n] : summary["ends"].items())
      count_row(Escape(html::HumanLabel(ending)), n);
  count_row("raised at release", get("raised_at_release"));
  count_row("stayed at release", get("stayed_at_release"));
  html += "</table>\n";
  Add(html, "<p class=\"note\">", Cell(get("steps")), " steps, ", Cell(get("unconverged_steps")),
      " of them with a contact solve that did not converge.</p>\n");
  return html;
}

// "Maps": the run's main rasters on the hillshade, with their legends ("" without rasters).
std::string MapsSection(const RunReportInput& input) {
  std::vector<const ensemble::RasterLayer*> maps;
  if (input.layers && input.dem) {
    for (const char* name : {"reach_probability", "energy_max", "speed_max", "jump_height_max"})
      for (const ensemble::RasterLayer& layer : *input.layers)
        if (layer.name == name) maps.push_back(&layer);
    if (maps.empty())
      if (const ensemble::RasterLayer* layer = QuickLookLayer(*input.layers)) maps.push_back(layer);
  }
  if (maps.empty()) return "";
  std::string html = "<h2>Maps</h2>\n";
  const ensemble::RasterLayer* quicklook =
      input.quicklook_png.empty() ? nullptr : QuickLookLayer(*input.layers);
  for (const ensemble::RasterLayer* layer : maps) {
    const std::string png = layer == quicklook
                                ? input.quicklook_png
                                : QuickLookPngOf(*input.dem, layer, input.paths, {}, input.lines);
    html +=
        html::PngFigure(png, layer->name, LegendOf(*layer).title + " (" + layer->name + ".tif)");
  }
  return html;
}

// "Distributions over the rocks": histograms and a table of statistics.
std::string DistributionsSection(const ColumnSource& rocks, std::size_t budget_bytes) {
  const ColumnSource none = [](const ColumnSink&) {};
  const ColumnSource& source = rocks ? rocks : none;
  const std::vector<ColumnStatistics> s =
      SummarizeColumns(source, kRockColumnCount, kPercents, budget_bytes);
  const std::vector<Histogram> h =
      HistogramsOf(source, s, {kRunoutColumn, kEnergyColumn, kJumpHeightColumn}, 20);
  std::string html = "<h2>Distributions over the rocks</h2>\n<div class=\"plots\">\n";
  html += HistogramSvg("Runout", "runout (m)", h[0], s[kRunoutColumn]);
  html += HistogramSvg("Largest kinetic energy", std::string("energy (") + kEnergyUnit + ")", h[1],
                       s[kEnergyColumn]);
  html += HistogramSvg("Largest jump height", "jump height: centre of mass, along the normal (m)",
                       h[2], s[kJumpHeightColumn]);
  html +=
      "</div>\n<table>\n<tr><th></th><th>mean</th><th>median</th><th>90 %</th><th>95 %</th>"
      "<th>99 %</th><th>largest</th></tr>\n";
  const auto stats_row = [&](const std::string& label, const ColumnStatistics& c) {
    Add(html, "<tr><th>", label, "</th><td>", Number(c.mean()), "</td>");
    for (double p : c.percentiles) Add(html, "<td>", Number(p), "</td>");
    html += "</tr>\n";
  };
  stats_row("runout (m)", s[kRunoutColumn]);
  stats_row("largest speed (m/s)", s[kSpeedColumn]);
  stats_row(std::string("largest kinetic energy (") + kEnergyUnit + ")", s[kEnergyColumn]);
  stats_row("largest jump height, along the normal (m)", s[kJumpHeightColumn]);
  stats_row("travel angle (&deg;)", s[kTravelAngleColumn]);
  html +=
      "</table>\n<p class=\"note\">Percentiles are nearest-rank, over the rocks (one value per "
      "rock).</p>\n";
  return html;
}

// "Evaluation lines": who crossed, and the design numbers at the crossing ("" without lines).
std::string EvaluationLinesSection(const Json& summary) {
  if (!summary.contains("evaluation_lines") || !summary["evaluation_lines"].is_array()) return "";
  const Json& lines = summary["evaluation_lines"];
  std::string html =
      "<h2>Evaluation lines</h2>\n<table>\n<tr><th>line</th><th>length (m)</th>"
      "<th>rocks</th><th>crossed</th><th>passing probability</th></tr>\n";
  for (const Json& line : lines) {
    const double p = line["passing_probability"].is_number()
                         ? line["passing_probability"].get<double>()
                         : std::numeric_limits<double>::quiet_NaN();
    Add(html, "<tr><th>", Cell(line["name"]), "</th><td>", Cell(line["length_m"]), "</td><td>",
        Cell(line["rocks"]), "</td><td>", Cell(line["crossed"]), "</td><td>",
        Number(100 * p, "%.1f"), " %</td></tr>\n");
  }
  html += "</table>\n";
  const std::pair<const char*, const char*> quantities[] = {
      {"speed_m_s", "speed (m/s)"},
      {"energy_J", "kinetic energy"},
      {"com_height_m", "height of the centre of mass (m)"},
      {"bounce_height_m", "bounce height (m)"}};
  for (const Json& line : lines) {
    Add(html, "<h3>", Cell(line["name"]),
        "</h3>\n<table>\n<tr><th></th><th>mean</th>"
        "<th>median</th><th>90 %</th><th>95 %</th><th>99 %</th><th>largest</th></tr>\n");
    for (const auto& [key, label] : quantities) {
      const bool energy = std::string(key) == "energy_J";
      const double scale = energy ? 1 / kJoulesPerEnergyUnit : 1.0;
      Add(html, "<tr><th>", label, energy ? std::string(" (") + kEnergyUnit + ")" : "", "</th>");
      for (const char* statistic : {"mean", "p50", "p90", "p95", "p99", "max"}) {
        const Json& v = line[key][statistic];
        Add(html, "<td>",
            Number(v.is_number() ? scale * v.get<double>()
                                 : std::numeric_limits<double>::quiet_NaN()),
            "</td>");
      }
      html += "</tr>\n";
    }
    html += "</table>\n";
  }
  html +=
      "<p class=\"note\">Over the rocks that crossed each line, at the first crossing of the "
      "centre of mass (evaluation_lines.csv); heights are vertical, above the terrain (unlike "
      "the jump height, along the normal); the bounce height is that of the rock's lowest point. "
      "Percentiles are nearest-rank.</p>\n";
  return html;
}

// "Barriers": what each barrier did to the rocks that reached it, and the energies and heights
// there ("" without barriers).
std::string BarriersSection(const Json& summary) {
  if (!summary.contains("barriers") || !summary["barriers"].is_array()) return "";
  const Json& barriers = summary["barriers"];
  const auto number = [](const Json& v) {
    return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
  };
  std::string html =
      "<h2>Barriers</h2>\n<table>\n<tr><th>barrier</th><th>type</th><th>height (m)</th>"
      "<th>capacity (" +
      std::string(kEnergyUnit) +
      ")</th><th>rocks</th><th>reached</th><th>stopped</th><th>overtopped</th>"
      "<th>broke through</th><th>passing probability</th></tr>\n";
  for (const Json& b : barriers)
    Add(html, "<tr><th>", Cell(b["name"]), "</th><td>", Cell(b["type"]), "</td><td>",
        Cell(b["height_m"]), "</td><td>",
        Number(number(b["capacity_J"]) / kJoulesPerEnergyUnit, "%.0f"), "</td><td>",
        Cell(b["rocks"]), "</td><td>", Cell(b["reached"]), "</td><td>", Cell(b["stopped"]),
        "</td><td>", Cell(b["overtopped"]), "</td><td>", Cell(b["broke_through"]), "</td><td>",
        Number(100 * number(b["passing_probability"]), "%.1f"), " %</td></tr>\n");
  html += "</table>\n";
  const std::pair<const char*, const char*> quantities[] = {
      {"impact_energy_J", "kinetic energy at the barrier"},
      {"passing_height_m", "passing height (m)"},
      {"passing_energy_J", "kinetic energy of the rocks that passed, after it"}};
  for (const Json& b : barriers) {
    Add(html, "<h3>", Cell(b["name"]),
        "</h3>\n<table>\n<tr><th></th><th>mean</th>"
        "<th>median</th><th>90 %</th><th>95 %</th><th>99 %</th><th>largest</th></tr>\n");
    for (const auto& [key, label] : quantities) {
      const bool energy = std::string(key) != "passing_height_m";
      const double scale = energy ? 1 / kJoulesPerEnergyUnit : 1.0;
      Add(html, "<tr><th>", label, energy ? std::string(" (") + kEnergyUnit + ")" : "", "</th>");
      for (const char* statistic : {"mean", "p50", "p90", "p95", "p99", "max"})
        Add(html, "<td>", Number(scale * number(b[key][statistic])), "</td>");
      html += "</tr>\n";
    }
    html += "</table>\n";
  }
  html +=
      "<p class=\"note\">Over the rocks that reached each barrier (barriers.csv), at the first "
      "crossing of its line by the centre of mass: a rock whose lowest point passed higher than "
      "the barrier overtopped it; one with at most the capacity's kinetic energy was stopped; "
      "the others broke through with their energy less the capacity (docs/model.md, "
      "\"Barriers\"). Percentiles are nearest-rank.</p>\n";
  return html;
}

// "Forest": the model, the stands and trees it was given, and -- explicit trees -- what the
// rocks did to them (tree_impacts.csv's summary). Absent without a forest.
std::string ForestSection(const Json& summary) {
  if (!summary.contains("forest") || !summary["forest"].is_object()) return "";
  const Json& f = summary["forest"];
  const bool trees = f.value("model", std::string()) == "trees";
  std::string html = "<h2>Forest</h2>\n<table>\n";
  const auto row = [&html](const std::string& label, const std::string& value) {
    Add(html, "<tr><th>", label, "</th><td>", value, "</td></tr>\n");
  };
  row("model", trees ? "explicit trees (stems a rock's hull can hit)"
                     : "drag layer (a drag from stem density and diameter)");
  if (trees) row("trees", Cell(f["trees"]));
  if (f.contains("stands") && f["stands"].is_array() && !f["stands"].empty()) {
    std::string stands;
    for (const Json& s : f["stands"]) {
      Add(stands, stands.empty() ? "" : "; ", Number(NumberOf(s["stems_per_ha"]), "%.0f"),
          " stems/ha of DBH ", Number(NumberOf(s["dbh_cm"]), "%.0f"), " cm on ",
          Number(NumberOf(s["area_m2"]) / 1e4, "%.2f"), " ha");
      if (const std::string species = s.value("species", std::string()); !species.empty())
        Add(stands, " (", Escape(species), ")");
    }
    row("stands", stands);
  }
  row("stem height (m)", Cell(f["stem_height_m"]));
  if (f.contains("breaking_energy"))
    row("energy a stem absorbs before it breaks",
        Escape(f["breaking_energy"].value("law", std::string())) + ", coefficient " +
            Cell(f["breaking_energy"]["coefficient_J"]) + " J, exponent " +
            Cell(f["breaking_energy"]["exponent"]));
  // Each species' law (the user's, docs/model.md "Forest"): factor x coefficient x DBH^exponent.
  if (f.contains("species") && f["species"].is_array() && !f["species"].empty()) {
    std::string species;
    for (const Json& s : f["species"])
      Add(species, species.empty() ? "" : "; ", Escape(s.value("name", std::string())), ": ",
          Cell(s["factor"]), " &times; ", Cell(s["coefficient_J"]), " J &times; DBH[cm]<sup>",
          Cell(s["exponent"]), "</sup>, ",
          Number(NumberOf(s["e_max_30cm_J"]) / kJoulesPerEnergyUnit, "%.0f"), " ", kEnergyUnit,
          " at 30 cm");
    row("breaking energy by species (the scene's laws)", species);
  }
  if (f.contains("impacts")) {
    const Json& i = f["impacts"];
    row("rocks that hit a stem", Cell(i["rocks_hitting"]));
    row("impacts", Cell(i["impacts"]));
    row("stems hit", Cell(i["stems_hit"]));
    row("stems broken", Cell(i["breakages"]));
    row("rocks that broke a stem", Cell(i["rocks_breaking"]));
    row(std::string("energy the stems absorbed (") + kEnergyUnit + ")",
        Number(NumberOf(i["absorbed_J"]) / kJoulesPerEnergyUnit));
  }
  html += "</table>\n";
  if (trees)
    html +=
        "<p class=\"note\">Per rock and stem: tree_impacts.csv; hits per cell: "
        "tree_hits.tif when asked for (docs/scenes.md, \"[forest]\").</p>\n";
  return html;
}

// The ground table, the solver options and the files, as summary.json has them; the page's end.
std::string SettingsSection(const Json& summary) {
  std::string html;
  if (summary.contains("ground")) {
    html += "<h2>Ground table</h2>\n";
    html += html::RowsTable(summary["ground"], "category");
  }
  if (summary.contains("solver")) {
    html += "<h2>Solver options</h2>\n";
    html += html::KeyValueTable(summary["solver"]);
  }
  if (summary.contains("outputs")) {
    html += "<h2>Files</h2>\n<p>";
    html += Cell(summary["outputs"]);
    html += "</p>\n";
  }
  return html + html::End();
}

}  // namespace

std::string RunReportHtml(const RunReportInput& input) {
  const Json summary = Json::parse(input.summary_json);
  return WhatRanSection(summary) + EndingsSection(summary) + MapsSection(input) +
         DistributionsSection(input.rocks, input.statistics_budget_bytes) +
         EvaluationLinesSection(summary) + BarriersSection(summary) + ForestSection(summary) +
         SettingsSection(summary);
}

}  // namespace talus::io
