// The QGIS styles of rocks.gpkg (io/layer_styles.hpp): well-formed QML whose classes are those of
// the quick-look (bounds, labels, colours), and single symbols with their halo.

#include "io/layer_styles.hpp"

#include <cpl_error.h>
#include <cpl_minixml.h>
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace talus::io {
namespace {

struct XmlDeleter {
  void operator()(CPLXMLNode* node) const { CPLDestroyXMLNode(node); }
};
using Xml = std::unique_ptr<CPLXMLNode, XmlDeleter>;

// The children of `parent` named `name`, in order.
std::vector<const CPLXMLNode*> Children(const CPLXMLNode* parent, const char* name) {
  std::vector<const CPLXMLNode*> found;
  for (const CPLXMLNode* c = parent ? parent->psChild : nullptr; c; c = c->psNext)
    if (c->eType == CXT_Element && std::string(c->pszValue) == name) found.push_back(c);
  return found;
}

// The value of the property `key` of a symbol layer (its Option map).
std::string Property(const CPLXMLNode* layer, const char* key) {
  for (const CPLXMLNode* option : Children(CPLGetXMLNode(layer, "Option"), "Option"))
    if (std::string(CPLGetXMLValue(option, "name", "")) == key)
      return CPLGetXMLValue(option, "value", "");
  return "";
}

std::string Rgba(const std::array<unsigned char, 3>& rgb, int alpha) {
  return std::to_string(rgb[0]) + "," + std::to_string(rgb[1]) + "," + std::to_string(rgb[2]) +
         "," + std::to_string(alpha);
}

TEST(LayerStyles, GraduatedMarkersHaveTheQuickLooksEnergyClasses) {
  const QuickLookLegend legend = EnergyLegend();
  ASSERT_EQ(legend.classes.size(), 5u);
  const Xml xml(CPLParseXMLString(GraduatedMarkerQml("energy_J", legend).c_str()));
  ASSERT_TRUE(xml) << CPLGetLastErrorMsg();
  const CPLXMLNode* renderer = CPLGetXMLNode(xml.get(), "=qgis.renderer-v2");
  ASSERT_NE(renderer, nullptr);
  EXPECT_STREQ(CPLGetXMLValue(renderer, "type", ""), "graduatedSymbol");
  EXPECT_STREQ(CPLGetXMLValue(renderer, "attr", ""), "energy_J");
  const auto ranges = Children(CPLGetXMLNode(renderer, "ranges"), "range");
  const auto symbols = Children(CPLGetXMLNode(renderer, "symbols"), "symbol");
  ASSERT_EQ(ranges.size(), legend.classes.size());
  ASSERT_EQ(symbols.size(), legend.classes.size());
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    const ColourClass& c = legend.classes[k];
    EXPECT_EQ(std::stod(CPLGetXMLValue(ranges[k], "lower", "")), c.lower) << k;
    const double upper = std::stod(CPLGetXMLValue(ranges[k], "upper", ""));
    if (k + 1 < ranges.size())
      EXPECT_EQ(upper, legend.classes[k + 1].lower) << k;
    else
      EXPECT_GT(upper, 1e300);  // the top class is open above
    EXPECT_EQ(CPLGetXMLValue(ranges[k], "label", ""), c.label) << k;
    EXPECT_EQ(CPLGetXMLValue(ranges[k], "symbol", ""), std::to_string(k));
    EXPECT_EQ(CPLGetXMLValue(symbols[k], "name", ""), std::to_string(k));
    EXPECT_EQ(Property(CPLGetXMLNode(symbols[k], "layer"), "color"), Rgba(c.rgb, 255)) << k;
  }
}

TEST(LayerStyles, ALineWithAHaloIsAWideWhiteLineUnderTheColouredOne) {
  const Xml xml(
      CPLParseXMLString(SingleSymbolQml({SymbolKind::kLine, {0, 0, 0}, 1, 0.6, true}).c_str()));
  ASSERT_TRUE(xml);
  const CPLXMLNode* renderer = CPLGetXMLNode(xml.get(), "=qgis.renderer-v2");
  ASSERT_NE(renderer, nullptr);
  EXPECT_STREQ(CPLGetXMLValue(renderer, "type", ""), "singleSymbol");
  const auto symbols = Children(CPLGetXMLNode(renderer, "symbols"), "symbol");
  ASSERT_EQ(symbols.size(), 1u);
  EXPECT_STREQ(CPLGetXMLValue(symbols[0], "type", ""), "line");
  const auto layers = Children(symbols[0], "layer");
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_EQ(Property(layers[0], "line_color"), "255,255,255,255");
  EXPECT_EQ(Property(layers[0], "line_width"), "1.2");
  EXPECT_EQ(Property(layers[1], "line_color"), "0,0,0,255");
  EXPECT_EQ(Property(layers[1], "line_width"), "0.6");
}

TEST(LayerStyles, OpacityAndMarkupInLabelsAreKept) {
  const std::string paths = SingleSymbolQml({SymbolKind::kLine, kPathRgb, kPathOpacity, 0.4});
  const Xml xml(CPLParseXMLString(paths.c_str()));
  ASSERT_TRUE(xml);
  const auto symbols = Children(CPLGetXMLNode(xml.get(), "=qgis.renderer-v2.symbols"), "symbol");
  ASSERT_EQ(symbols.size(), 1u);
  EXPECT_EQ(Property(CPLGetXMLNode(symbols[0], "layer"), "line_color"), Rgba(kPathRgb, 153));
  QuickLookLegend legend{"t", {{0, "a < b & \"c\"", {1, 2, 3}}}};
  const Xml labelled(CPLParseXMLString(GraduatedMarkerQml("f", legend).c_str()));
  ASSERT_TRUE(labelled);
  EXPECT_STREQ(CPLGetXMLValue(labelled.get(), "=qgis.renderer-v2.ranges.range.label", ""),
               "a < b & \"c\"");
}

}  // namespace
}  // namespace talus::io
