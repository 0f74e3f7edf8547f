// report.html of `talus simulate`, `talus validate` and `talus calibrate` opened in a real browser
// (headless Chromium): each page loads, its maps (embedded PNGs) decode and its plots (inline
// SVG) are laid out.

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "run_talus.hpp"

namespace {

namespace fs = std::filesystem;
using talus::app::testing::FreshDir;
using talus::app::testing::RunCommand;
using talus::app::testing::Slurp;
using talus::app::testing::Write;

const std::string kScene = talus::app::testing::SmallSlopeScene(
    3, R"(rasters = ["speed", "energy", "jump_height", "passages", "reach_probability"]
)");

// What the check script put on <body>: data-<name>="<number>", or -1 when absent.
int BodyNumber(const std::string& dom, const std::string& name) {
  std::smatch match;
  if (!std::regex_search(dom, match, std::regex("data-" + name + "=\"([0-9]+)\""))) return -1;
  return std::stoi(match[1]);
}

// Opens a copy of `page` with a check script in headless Chromium; the DOM it dumped. The check
// counts the images, those decoded, the inline SVG plots, those laid out with their ticks and
// marks, and the tables, onto <body>.
std::string OpenInBrowser(const fs::path& page_path) {
  const std::string page = Slurp(page_path);
  if (page.empty() || page.rfind("</body>") == std::string::npos) return "";
  const std::string check = R"(<script>
window.addEventListener('load', () => {
  const images = [...document.images];
  document.body.dataset.images = images.length;
  document.body.dataset.imagesDecoded =
      images.filter(i => i.complete && i.naturalWidth > 300 && i.naturalHeight > 300).length;
  const plots = [...document.querySelectorAll('body > div svg, body > svg')];
  document.body.dataset.plots = plots.length;
  document.body.dataset.plotsDrawn = plots.filter(
      s => s.getBoundingClientRect().width > 100 && s.querySelectorAll('text').length >= 6 &&
           s.querySelectorAll('rect, circle, polyline, line').length >= 3).length;
  document.body.dataset.tables = document.querySelectorAll('table').length;
});
</script>
</body>)";
  std::string checked = page;
  checked.replace(checked.rfind("</body>"), 7, check);
  const fs::path copy = page_path.parent_path() / "checked.html";
  Write(copy, checked);
  const std::string browser = std::string(TALUS_CHROMIUM) +
                              " --headless --no-sandbox --disable-gpu --virtual-time-budget=10000"
                              " --dump-dom file://" +
                              copy.string() + " 2>/dev/null";
  std::string dom;
  if (RunCommand(browser, &dom) != 0) return "";
  return dom;
}

TEST(ReportInABrowser, LoadsWithEveryMapDecodedAndEveryHistogramDrawn) {
  const fs::path dir = FreshDir("talus_report_tests", "browser");
  Write(dir / "scene.toml", kScene);
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "scene.toml").string() +
                           " --out " + (dir / "out").string(),
                       &output),
            0)
      << output;
  const std::string page = Slurp(dir / "out" / "report.html");
  ASSERT_FALSE(page.empty());
  // The check runs in a copy: the report itself carries no script.
  EXPECT_EQ(page.find("<script"), std::string::npos);
  const std::string dom = OpenInBrowser(dir / "out" / "report.html");
  ASSERT_FALSE(dom.empty());
  // The scene asks for reach probability, energy, speed and jump height: four maps.
  EXPECT_EQ(BodyNumber(dom, "images"), 4) << dom.substr(0, 400);
  EXPECT_EQ(BodyNumber(dom, "images-decoded"), 4);
  EXPECT_EQ(BodyNumber(dom, "plots"), 3);  // runout, energy, jump height
  EXPECT_EQ(BodyNumber(dom, "plots-drawn"), 3);
  EXPECT_GE(BodyNumber(dom, "tables"), 5);  // what ran, rock, endings, statistics, ground, solver
  EXPECT_NE(dom.find("How the rocks ended"), std::string::npos);
}

// report.html of `talus validate` on the small event: the deposits map decodes, and the
// observed-vs-simulated panels (run-out, impact speed, impact energy ratio) and PIT histograms
// (the same three kinds) are laid out.
TEST(ReportInABrowser, ValidationReportLoadsWithItsMapAndPlots) {
  const fs::path dir = FreshDir("talus_report_tests", "browser_validate");
  talus::app::testing::WriteSmallEvent(dir);
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " validate " + (dir / "event.toml").string() +
                           " --out " + (dir / "out").string(),
                       &output),
            0)
      << output;
  const std::string page = Slurp(dir / "out" / "report.html");
  EXPECT_EQ(page.find("<script"), std::string::npos);
  const std::string dom = OpenInBrowser(dir / "out" / "report.html");
  ASSERT_FALSE(dom.empty());
  EXPECT_EQ(BodyNumber(dom, "images"), 1) << dom.substr(0, 400);
  EXPECT_EQ(BodyNumber(dom, "images-decoded"), 1);
  EXPECT_EQ(BodyNumber(dom, "plots"), 6);
  EXPECT_EQ(BodyNumber(dom, "plots-drawn"), 6);
  EXPECT_GE(BodyNumber(dom, "tables"), 4);  // scores, per run, endings, what ran
  EXPECT_NE(dom.find("Scores per kind"), std::string::npos);
}

// report.html of `talus calibrate` on the small event's run-outs (one parameter, 4 evaluations,
// no covariance: seconds): the convergence, the profile and the observed-vs-simulated plot are
// laid out.
TEST(ReportInABrowser, CalibrationReportLoadsWithItsPlots) {
  const fs::path dir = FreshDir("talus_report_tests", "browser_calibrate");
  talus::app::testing::WriteSmallEvent(dir);
  Write(dir / "event.toml",
        "scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
        "file = \"observed.csv\"\n");
  Write(dir / "cal.toml", R"(event = "event.toml"
[[parameters]]
category = "medium_soft"
field = "mu_min"
lower = 0.1
upper = 0.9
[optimizer]
algorithm = "bobyqa"
max_evaluations = 4
[roughness]
steps = [1e-2]
seeds = 1
profile_points = 3
[uncertainty]
enabled = false
)");
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " calibrate " + (dir / "cal.toml").string() +
                           " --out " + (dir / "out").string() + " --threads 2",
                       &output),
            0)
      << output;
  const std::string dom = OpenInBrowser(dir / "out" / "report.html");
  ASSERT_FALSE(dom.empty());
  EXPECT_EQ(BodyNumber(dom, "images"), 0);
  // Convergence, one profile, observed vs simulated run-out.
  EXPECT_EQ(BodyNumber(dom, "plots"), 3) << dom.substr(0, 400);
  EXPECT_EQ(BodyNumber(dom, "plots-drawn"), 3);
  EXPECT_GE(BodyNumber(dom, "tables"), 3);  // fitted parameters, objective, what ran
  EXPECT_NE(dom.find("Fitted parameters"), std::string::npos);
}

}  // namespace
