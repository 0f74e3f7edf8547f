#include "io/html_page.hpp"

#include <cpl_conv.h>
#include <cpl_string.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "common/format.hpp"
#include "io/svg_plot.hpp"

namespace talus::io::html {
namespace {

using svg::Add;
using svg::Escape;

constexpr const char* kStyle =
    R"(body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ccc;padding:.2em .6em;text-align:left}
td{font-variant-numeric:tabular-nums}figure{display:inline-block;margin:.5em 1em .5em 0;vertical-align:top}
figure img{width:520px;max-width:100%;border:1px solid #ccc}figure{max-width:520px}figcaption{font-size:.9em;color:#555}
.plots svg{margin:.3em;border:1px solid #ddd}.note{color:#555;font-size:.9em}
.warnings li{color:#8a4b00})";

// Unit suffixes of keys, longest first, and how they are written.
const std::pair<const char*, const char*> kUnits[] = {
    {"_kg_m3", "kg/m³"}, {"_rad_s", "rad/s"}, {"_m_s", "m/s"}, {"_kn_m2", "kN/m²"},
    {"_deg", "°"},       {"_m3", "m³"},       {"_kg", "kg"},   {"_m", "m"},
    {"_s", "s"},         {"_j", "J"},         {"_J", "J"},     {"_hz", "Hz"}};

// Keys whose label is not their words.
const std::map<std::string, std::string>& Labels() {
  static const std::map<std::string, std::string> labels = {
      {"dt_s", "time step (s)"},
      {"mu_min", "μ_min"},
      {"mu_max", "μ_max"},
      {"beta", "β (1/s)"},
      {"kappa", "κ (1/m)"},
      {"nu", "ν (1/s)"},
      {"talus_version", "Talus version"},
      {"inputs_sha256", "inputs hash (SHA-256)"},
      {"rocks_per_run", "rocks per run"},
      {"rocks_per_release", "rocks per release"},
      {"crs", "coordinate reference system"},
      {"runout", "run-out"},
      {"crps", "CRPS"},
      {"energy_score", "energy score"},
      {"left_domain", "left the DEM"},
      {"max_time", "still moving at max_time"},
      {"rest", "at rest"},
      {"failed", "failed (non-finite state)"},
      {"tolerance_m_s", "contact solve tolerance (m/s)"},
      {"max_time_s", "largest simulated time (s)"},
      {"normal_restitution", "normal restitution ε_N"},
  };
  return labels;
}

}  // namespace

std::string Begin(const std::string& title, const std::string& note_html) {
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  Add(html, "<title>", Escape(title), "</title>\n<style>\n", kStyle,
      "\n</style>\n</head>\n<body>\n<h1>", Escape(title), "</h1>\n");
  if (!note_html.empty()) Add(html, "<p class=\"note\">", note_html, "</p>\n");
  return html;
}

std::string End() {
  return "<p class=\"note\">Names, units, heights and percentiles are defined once in the "
         "glossary (docs/glossary.md).</p>\n</body>\n</html>\n";
}

std::string Number(double v, const char* format) {
  return std::isfinite(v) ? FormatDouble(v, format) : "&ndash;";
}

std::string Cell(const Json& value) {
  if (value.is_number_float()) return FormatDouble(value.get<double>(), "%.6g");
  if (value.is_string()) return Escape(value.get<std::string>());
  if (value.is_null()) return "&ndash;";
  if (value.is_boolean()) return value.get<bool>() ? "yes" : "no";
  if (value.is_array()) {
    std::string out;
    for (const Json& v : value) Add(out, out.empty() ? "" : ", ", Cell(v));
    return out;
  }
  return Escape(value.dump());
}

double NumberOf(const Json& value) { return value.is_number() ? value.get<double>() : NAN; }

std::string UnitSuffix(const std::string& unit) {
  return unit.empty() || unit == "1" ? "" : " (" + Escape(unit) + ")";
}

std::string HumanLabel(const std::string& key) {
  if (const auto it = Labels().find(key); it != Labels().end()) return it->second;
  std::string words = key, unit;
  for (const auto& [suffix, written] : kUnits) {
    const std::string s = suffix;
    if (words.size() > s.size() && words.compare(words.size() - s.size(), s.size(), s) == 0) {
      words.erase(words.size() - s.size());
      unit = written;
      break;
    }
  }
  std::replace(words.begin(), words.end(), '_', ' ');
  return unit.empty() ? words : words + " (" + unit + ")";
}

std::string KeyValueTable(const Json& object, const std::vector<std::string>& skip) {
  std::string out = "<table>\n";
  for (const auto& [key, value] : object.items()) {
    if (value.is_object() || std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
    Add(out, "<tr><th>", Escape(HumanLabel(key)), "</th><td>", Cell(value), "</td></tr>\n");
  }
  return out + "</table>\n";
}

std::string RowsTable(const Json& object, const std::string& first_column) {
  std::vector<std::string> columns;
  for (const auto& [name, row] : object.items())
    for (const auto& [key, value] : row.items())
      if (std::find(columns.begin(), columns.end(), key) == columns.end()) columns.push_back(key);
  std::string out = "<table>\n<tr><th>" + Escape(first_column) + "</th>";
  for (const std::string& c : columns) Add(out, "<th>", Escape(HumanLabel(c)), "</th>");
  out += "</tr>\n";
  for (const auto& [name, row] : object.items()) {
    Add(out, "<tr><th>", Escape(name), "</th>");
    for (const std::string& c : columns)
      Add(out, "<td>", row.contains(c) ? Cell(row[c]) : "", "</td>");
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::string Table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows) {
  std::string out = "<table>\n<tr>";
  for (const std::string& h : header) Add(out, "<th>", h, "</th>");
  out += "</tr>\n";
  for (const auto& row : rows) {
    out += "<tr>";
    for (std::size_t k = 0; k < row.size(); ++k)
      Add(out, k == 0 ? "<th>" : "<td>", row[k], k == 0 ? "</th>" : "</td>");
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::string BlockBiasTable(const Json& blocks) {
  // Nothing to compare without blocks: a scene's single rock ("[rock]") alone is no table.
  if (!blocks.is_array() || std::none_of(blocks.begin(), blocks.end(), [](const Json& b) {
        return b.value("block", std::string()) != "[rock]";
      }))
    return "";
  std::vector<std::vector<std::string>> rows;
  for (const Json& b : blocks)
    rows.push_back({svg::Escape(b.value("block", std::string())),
                    svg::Escape(HumanLabel(b.value("kind", std::string()))) +
                        UnitSuffix(b.value("unit", std::string())),
                    Cell(b.value("runs", Json())), Cell(b.value("scored", Json())),
                    Number(NumberOf(b.value("mean_bias", Json()))),
                    Number(NumberOf(b.value("bias_standard_error", Json()))),
                    Number(NumberOf(b.value("mean_score", Json())))});
  return Table({"block", "kind (unit)", "runs", "observations", "mean bias", "its standard error",
                "mean score"},
               rows) +
         "<p class=\"note\">Bias = simulated mean - observed, over the block's observations; its "
         "standard error is over the block's runs (observations of one run share its rocks). "
         "Biases of opposite sign per block point at the blocks' shapes (docs/calibration.md, "
         "\"Shape parameters\").</p>\n";
}

std::string Warnings(const Json& warnings) {
  if (!warnings.is_array() || warnings.empty()) return "";
  std::string html = "<h2>Warnings</h2>\n<ul class=\"warnings\">\n";
  for (const Json& w : warnings)
    if (w.is_string()) Add(html, "<li>", Escape(w.get<std::string>()), "</li>\n");
  return html + "</ul>\n";
}

std::string WarningsOrNone(const Json& warnings) {
  const std::string list = Warnings(warnings);
  return list.empty() ? "<h2>Warnings</h2>\n<p>None.</p>\n" : list;
}

std::string PngFigure(const std::string& png, const std::string& alt, const std::string& caption) {
  char* encoded =
      CPLBase64Encode(static_cast<int>(png.size()), reinterpret_cast<const GByte*>(png.data()));
  const std::string base64 = encoded ? encoded : "";
  CPLFree(encoded);
  std::string html;
  Add(html, "<figure><img alt=\"", Escape(alt), "\" src=\"data:image/png;base64,", base64,
      "\"><figcaption>", Escape(caption), "</figcaption></figure>\n");
  return html;
}

std::string Plots(const std::vector<std::string>& svgs) {
  std::string html = "<div class=\"plots\">\n";
  for (const std::string& s : svgs) html += s;
  return html + "</div>\n";
}

}  // namespace talus::io::html
