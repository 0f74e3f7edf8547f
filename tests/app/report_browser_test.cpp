// report.html of `talus simulate` opened in a real browser (headless Chromium): the page loads,
// its maps (embedded PNGs) decode and its histograms (inline SVG) are laid out.

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
  const std::string check = R"(<script>
window.addEventListener('load', () => {
  const images = [...document.images];
  document.body.dataset.images = images.length;
  document.body.dataset.imagesDecoded =
      images.filter(i => i.complete && i.naturalWidth > 300 && i.naturalHeight > 300).length;
  const plots = [...document.querySelectorAll('svg')];
  document.body.dataset.plots = plots.length;
  document.body.dataset.plotsDrawn = plots.filter(
      s => s.getBoundingClientRect().width > 100 && s.querySelectorAll('rect').length > 10).length;
  document.body.dataset.tables = document.querySelectorAll('table').length;
});
</script>
</body>)";
  std::string checked = page;
  checked.replace(checked.rfind("</body>"), 7, check);
  Write(dir / "out" / "checked.html", checked);
  const std::string browser = std::string(TALUS_CHROMIUM) +
                              " --headless --no-sandbox --disable-gpu --virtual-time-budget=10000"
                              " --dump-dom file://" + (dir / "out" / "checked.html").string() +
                              " 2>/dev/null";
  std::string dom;
  ASSERT_EQ(RunCommand(browser, &dom), 0) << dom;
  // The scene asks for reach probability, energy, speed and jump height: four maps.
  EXPECT_EQ(BodyNumber(dom, "images"), 4) << dom.substr(0, 400);
  EXPECT_EQ(BodyNumber(dom, "images-decoded"), 4);
  EXPECT_EQ(BodyNumber(dom, "plots"), 3);  // runout, energy, jump height
  EXPECT_EQ(BodyNumber(dom, "plots-drawn"), 3);
  EXPECT_GE(BodyNumber(dom, "tables"), 5);  // what ran, rock, endings, statistics, ground, solver
  EXPECT_NE(dom.find("How the rocks ended"), std::string::npos);
}

}  // namespace
