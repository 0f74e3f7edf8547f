#include "io/html_page.hpp"

#include <gtest/gtest.h>

#include <string>

namespace talus::io::html {
namespace {

TEST(HtmlPage, KeysReadAsWordsWithTheirUnits) {
  EXPECT_EQ(HumanLabel("max_speed_m_s"), "max speed (m/s)");
  EXPECT_EQ(HumanLabel("max_kinetic_energy_j"), "max kinetic energy (J)");
  EXPECT_EQ(HumanLabel("density_kg_m3"), "density (kg/m³)");
  EXPECT_EQ(HumanLabel("runout_m"), "runout (m)");
  EXPECT_EQ(HumanLabel("rocks_per_run"), "rocks per run");
  EXPECT_EQ(HumanLabel("dt_s"), "time step (s)");
  EXPECT_EQ(HumanLabel("left_domain"), "left the DEM");
  EXPECT_EQ(HumanLabel("kappa"), "κ (1/m)");
  EXPECT_EQ(HumanLabel("runout"), "run-out");
  EXPECT_EQ(HumanLabel("steps"), "steps");  // a plural is not a unit
}

TEST(HtmlPage, TablesShowLabelsAndCellsShowMissingValuesAsADash) {
  const Json object = Json::parse(R"({"dt_s": 0.002, "note": "a<b", "x": null, "on": true,
                                      "nested": {"skipped": 1}, "hidden": 3})");
  const std::string table = KeyValueTable(object, {"hidden"});
  EXPECT_NE(table.find("<th>time step (s)</th><td>0.002</td>"), std::string::npos) << table;
  EXPECT_NE(table.find("<td>a&lt;b</td>"), std::string::npos);
  EXPECT_NE(table.find("<th>x</th><td>&ndash;</td>"), std::string::npos);
  EXPECT_NE(table.find("<th>on</th><td>yes</td>"), std::string::npos);
  EXPECT_EQ(table.find("skipped"), std::string::npos);
  EXPECT_EQ(table.find("hidden"), std::string::npos);
  EXPECT_EQ(Number(NAN), "&ndash;");
  EXPECT_EQ(Number(1.0 / 3), "0.3333");
}

TEST(HtmlPage, WarningsComeAsAListOrNothing) {
  EXPECT_EQ(Warnings(Json::array()), "");
  EXPECT_EQ(Warnings(Json()), "");
  EXPECT_NE(WarningsOrNone(Json::array()).find("None."), std::string::npos);
  const std::string list = Warnings(Json::array({"3 rocks <left>"}));
  EXPECT_NE(list.find("<li>3 rocks &lt;left&gt;</li>"), std::string::npos) << list;
}

TEST(HtmlPage, APageIsOneDocumentWithoutScripts) {
  const std::string page = Begin("Talus <run>", "note") + End();
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(page.find("<h1>Talus &lt;run&gt;</h1>"), std::string::npos);
  EXPECT_NE(page.find("<p class=\"note\">note</p>"), std::string::npos);
  EXPECT_EQ(page.find("<script"), std::string::npos);
  EXPECT_EQ(page.substr(page.size() - 8), "</html>\n");
  // Every report points at the one place its quantities are defined.
  EXPECT_NE(page.find("docs/glossary.md"), std::string::npos);
}

}  // namespace
}  // namespace talus::io::html
