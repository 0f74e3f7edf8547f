// The SVG plots of talus calibrate (io/calibration_plots.hpp): one grey dot per feasible finite
// evaluation and a best-so-far line that never rises (in SVG, y grows downwards: never moves up);
// the observed-vs-simulated plot with one dot per scored observation of the kind (grey before,
// blue after) and each dot whose median equals its observation on the 1:1 line.

#include "io/calibration_plots.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace talus::io {
namespace {

struct Dot {
  double x, y;
  std::string fill;
};

std::vector<Dot> Circles(const std::string& svg) {
  std::vector<Dot> dots;
  const std::regex circle(
      R"re(<circle cx="([-0-9.]+)" cy="([-0-9.]+)" r="[0-9.]+" fill="(#[0-9a-f]+)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator();
       ++it)
    dots.push_back({std::stod((*it)[1]), std::stod((*it)[2]), (*it)[3]});
  return dots;
}

calibration::Evaluation Eval(double value, bool feasible = true) {
  calibration::Evaluation e;
  e.value = value;
  e.feasible = feasible;
  return e;
}

TEST(ConvergenceSvg, DotsForFeasibleEvaluationsAndANonRisingBestSoFarLine) {
  calibration::OptimizerSummary summary;
  summary.algorithm = "bobyqa";
  for (const calibration::Evaluation& e :
       {Eval(5.0), Eval(7.0), Eval(1e3, false), Eval(3.0), Eval(NAN), Eval(4.0), Eval(1.5)})
    summary.history.push_back(e);
  const std::string svg = ConvergenceSvg(summary);
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u);
  EXPECT_EQ(svg.substr(svg.size() - 7), "</svg>\n");
  EXPECT_NE(svg.find("Convergence (bobyqa)"), std::string::npos);
  const std::vector<Dot> dots = Circles(svg);
  ASSERT_EQ(dots.size(), 5u);  // the infeasible and the NaN evaluation are not drawn
  for (std::size_t k = 1; k < dots.size(); ++k) EXPECT_GT(dots[k].x, dots[k - 1].x) << k;
  // Values 5, 7, 3, 4, 1.5: a larger value is higher up (smaller y).
  EXPECT_LT(dots[1].y, dots[0].y);
  EXPECT_GT(dots[2].y, dots[3].y);
  EXPECT_GT(dots[4].y, dots[2].y);
  // The line: one point per drawn dot, at the dots' x, y never decreasing (best so far).
  const std::smatch line = [&] {
    std::smatch m;
    std::regex_search(svg, m, std::regex("<polyline points=\"([^\"]*)\""));
    return m;
  }();
  ASSERT_FALSE(line.empty());
  std::istringstream points(line[1].str());
  std::vector<std::pair<double, double>> xy;
  for (std::string p; points >> p;) {
    const auto comma = p.find(',');
    xy.emplace_back(std::stod(p.substr(0, comma)), std::stod(p.substr(comma + 1)));
  }
  ASSERT_EQ(xy.size(), dots.size());
  for (std::size_t k = 0; k < xy.size(); ++k) {
    EXPECT_NEAR(xy[k].first, dots[k].x, 1e-9);
    if (k > 0) {
      EXPECT_GE(xy[k].second, xy[k - 1].second) << k;
    }
  }
  EXPECT_NEAR(xy[1].second, dots[0].y, 1e-9);  // 7 after 5: the best is still 5
  EXPECT_NEAR(xy.back().second, dots.back().y, 1e-9);
  // No evaluation at all: still a complete SVG.
  const std::string empty = ConvergenceSvg(calibration::OptimizerSummary{});
  EXPECT_TRUE(Circles(empty).empty());
  EXPECT_EQ(empty.substr(empty.size() - 7), "</svg>\n");
}

fieldobs::ObservationScore Score(const std::string& kind, double observed, double median,
                                 bool scored = true) {
  fieldobs::ObservationScore s;
  s.kind = kind;
  s.unit = "m";
  s.observed = observed;
  s.median = median;
  s.scored = scored;
  return s;
}

TEST(ObservedSimulatedSvg, OneDotPerScoredObservationOfTheKindOnTheOneToOneLineWhenExact) {
  const std::vector<fieldobs::ObservationScore> before = {
      Score("runout", 100, 80), Score("runout", 150, 120), Score("runout", 90, 90, false),
      Score("impact_speed_out", 5, 6), Score("runout", 120, NAN)};
  const std::vector<fieldobs::ObservationScore> after = {
      Score("runout", 100, 100), Score("runout", 150, 140), Score("runout", 90, 95, false),
      Score("impact_speed_out", 5, 5), Score("runout", 120, 125)};
  const std::string svg = ObservedSimulatedSvg("runout", before, after);
  EXPECT_NE(svg.find("run-out: observed vs simulated median"), std::string::npos);
  EXPECT_NE(svg.find("observed (m)"), std::string::npos);
  const std::vector<Dot> dots = Circles(svg);
  ASSERT_EQ(dots.size(), 5u);  // before: 2 (unscored, other kind, NaN median left out); after: 3
  int grey = 0, blue = 0;
  for (const Dot& d : dots) (d.fill == "#999999" ? grey : blue) += 1;
  EXPECT_EQ(grey, 2);
  EXPECT_EQ(blue, 3);
  // The 1:1 line's ends, and the after-fit dot of observation 100 (median 100) on it.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      svg, m,
      std::regex(R"re(<line x1="([-0-9.]+)" y1="([-0-9.]+)" x2="([-0-9.]+)" y2="([-0-9.]+)")re"
                 R"re( stroke="black" stroke-dasharray)re")));
  const double x1 = std::stod(m[1]), y1 = std::stod(m[2]), x2 = std::stod(m[3]),
               y2 = std::stod(m[4]);
  const Dot& exact = dots[2];  // the first blue one
  ASSERT_EQ(exact.fill, "#1f5fbf");
  const double along_x = (exact.x - x1) / (x2 - x1), along_y = (exact.y - y1) / (y2 - y1);
  EXPECT_NEAR(along_x, along_y, 0.01 / std::abs(x2 - x1) + 0.01 / std::abs(y2 - y1));
  // A grey dot below the line (simulated 80 < observed 100): further down than the line there.
  const Dot& under = dots[0];
  EXPECT_GT(under.y, y1 + (under.x - x1) / (x2 - x1) * (y2 - y1));
}

}  // namespace
}  // namespace talus::io
