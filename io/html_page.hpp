#pragma once
// The pieces every report.html is made of (talus simulate, validate and calibrate): one
// self-contained page (no script, nothing fetched) with one style, tables whose rows carry human
// labels instead of JSON keys, numbers with a fixed number of digits, the warnings first, and
// energies in one unit (kEnergyUnit). The plots come from svg_plot.hpp.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace talus::io::html {

using Json = nlohmann::ordered_json;

// Energies in every report are shown in kJ (the files hold J: docs/glossary.md).
inline constexpr const char* kEnergyUnit = "kJ";
inline constexpr double kJoulesPerEnergyUnit = 1000;

// The page's head (title, style) and its <h1>, then `note` as a small paragraph (HTML, "" for
// none). `title` is plain text.
std::string Begin(const std::string& title, const std::string& note_html);
// Closes the page.
std::string End();

// A number with `format` ("%.4g"), or "&ndash;" for NaN and infinities.
std::string Number(double v, const char* format = "%.4g");
// A JSON value for a table cell: numbers with up to 6 significant digits, null as "&ndash;",
// arrays joined by ", ", text escaped.
std::string Cell(const Json& value);
// A number of a JSON value (NaN when it is not one).
double NumberOf(const Json& value);

// " (m)" after a label for a unit, "" for a dimensionless one ("" or "1"); the unit escaped.
std::string UnitSuffix(const std::string& unit);
// A JSON key or a column name as people read it: "max_speed_m_s" -> "max speed (m/s)",
// "dt_s" -> "time step (s)", "mu_min" -> "μ_min"; a few keys have their own label.
std::string HumanLabel(const std::string& key);

// A two-column table of the scalar members of `object` (nested objects and `skip` left out), the
// keys as HumanLabel shows them.
std::string KeyValueTable(const Json& object, const std::vector<std::string>& skip = {});
// One row per member of `object` (each an object), one column per key any of them has.
std::string RowsTable(const Json& object, const std::string& first_column);
// A table with a header row; cells are HTML (escape text with svg::Escape). A row's first cell
// is a header cell.
std::string Table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows);
// The per-block biases of scores.json or calibration.json ("blocks": block, kind, unit, scored,
// mean_bias, bias_standard_error, mean_score) as a table; "" when there are none.
std::string BlockBiasTable(const Json& blocks);

// "<h2>Warnings</h2>" and a list of the strings of `warnings` (a JSON array); "" when there are
// none.
std::string Warnings(const Json& warnings);
// "<h2>Warnings</h2>" with "none" when there are none: for the pages that promise to say so.
std::string WarningsOrNone(const Json& warnings);

// An embedded PNG (its bytes) in a figure with a caption (plain text).
std::string PngFigure(const std::string& png, const std::string& alt, const std::string& caption);
// Inline SVG plots side by side.
std::string Plots(const std::vector<std::string>& svgs);

}  // namespace talus::io::html
