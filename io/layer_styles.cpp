#include "io/layer_styles.hpp"

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "common/format.hpp"

namespace talus::io {
namespace {

std::string Colour(const std::array<unsigned char, 3>& rgb, double opacity) {
  return std::to_string(rgb[0]) + "," + std::to_string(rgb[1]) + "," + std::to_string(rgb[2]) +
         "," + std::to_string(static_cast<int>(opacity * 255 + 0.5));
}

std::string Number(double value) { return FormatDouble(value, "%.10g"); }

// A class bound, exactly (the largest double for the top class's open end).
std::string Bound(double value) { return FormatDouble(value, "%.17g"); }

// A symbol layer's properties, both as the Option map QGIS 3.26 and later read and as the prop
// elements of older versions.
std::string Properties(const std::vector<std::pair<std::string, std::string>>& properties) {
  std::string options = "<Option type=\"Map\">", props;
  for (const auto& [key, value] : properties) {
    options +=
        "<Option name=\"" + key + "\" type=\"QString\" value=\"" + XmlEscaped(value) + "\"/>";
    props += "<prop k=\"" + key + "\" v=\"" + XmlEscaped(value) + "\"/>";
  }
  return options + "</Option>" + props;
}

std::string SymbolLayer(const char* type,
                        const std::vector<std::pair<std::string, std::string>>& p) {
  return std::string("<layer class=\"") + type + "\" enabled=\"1\" locked=\"0\" pass=\"0\">" +
         Properties(p) + "</layer>";
}

// The symbol `name` of a renderer.
std::string Symbol(const std::string& name, const SingleSymbol& s) {
  const char* types[] = {"marker", "line", "fill"};
  std::string layers;
  const std::string colour = Colour(s.rgb, s.opacity), width = Number(s.width_mm);
  if (s.kind == SymbolKind::kMarker) {
    layers = SymbolLayer("SimpleMarker", {{"name", "circle"},
                                          {"color", colour},
                                          {"outline_color", "50,50,50,255"},
                                          {"outline_style", "solid"},
                                          {"outline_width", "0.1"},
                                          {"size", width},
                                          {"size_unit", "MM"}});
  } else if (s.kind == SymbolKind::kLine) {
    if (s.halo)
      layers = SymbolLayer("SimpleLine", {{"line_color", "255,255,255,255"},
                                          {"line_style", "solid"},
                                          {"line_width", Number(2 * s.width_mm)},
                                          {"line_width_unit", "MM"},
                                          {"capstyle", "round"},
                                          {"joinstyle", "round"}});
    layers += SymbolLayer("SimpleLine", {{"line_color", colour},
                                         {"line_style", "solid"},
                                         {"line_width", width},
                                         {"line_width_unit", "MM"},
                                         {"capstyle", "round"},
                                         {"joinstyle", "round"}});
  } else {
    layers = SymbolLayer("SimpleFill", {{"color", colour},
                                        {"style", "solid"},
                                        {"outline_color", Colour(s.rgb, 1)},
                                        {"outline_style", "solid"},
                                        {"outline_width", width},
                                        {"outline_width_unit", "MM"}});
  }
  return "<symbol name=\"" + name + "\" type=\"" + types[static_cast<int>(s.kind)] +
         "\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">" + layers + "</symbol>";
}

std::string Document(const std::string& renderer) {
  return "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
         "<qgis version=\"3.28.0\" styleCategories=\"Symbology\">\n" +
         renderer + "\n</qgis>\n";
}

}  // namespace

std::string SingleSymbolQml(const SingleSymbol& symbol) {
  return Document(
      "<renderer-v2 type=\"singleSymbol\" symbollevels=\"0\" enableorderby=\"0\" "
      "forceraster=\"0\"><symbols>" +
      Symbol("0", symbol) + "</symbols></renderer-v2>");
}

std::string GraduatedMarkerQml(const std::string& field, const QuickLookLegend& legend) {
  std::string ranges, symbols;
  for (std::size_t k = 0; k < legend.classes.size(); ++k) {
    const ColourClass& c = legend.classes[k];
    const double upper = k + 1 < legend.classes.size() ? legend.classes[k + 1].lower
                                                       : std::numeric_limits<double>::max();
    const std::string name = std::to_string(k);
    ranges += "<range lower=\"" + Bound(c.lower) + "\" upper=\"" + Bound(upper) + "\" symbol=\"" +
              name + "\" label=\"" + XmlEscaped(c.label) + "\" render=\"true\"/>";
    symbols += Symbol(name, {SymbolKind::kMarker, c.rgb, 1, 2.2, false});
  }
  return Document("<renderer-v2 type=\"graduatedSymbol\" attr=\"" + XmlEscaped(field) +
                  "\" graduatedMethod=\"GraduatedColor\" symbollevels=\"0\" enableorderby=\"0\" "
                  "forceraster=\"0\"><ranges>" +
                  ranges + "</ranges><symbols>" + symbols + "</symbols></renderer-v2>");
}

}  // namespace talus::io
