#include "io/svg_plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace talus::io::svg {
namespace {

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(SvgPlot, NumbersHaveFixedDigitsSoTheSameDataGiveTheSameBytes) {
  EXPECT_EQ(F(1.0 / 3), "0.33");
  EXPECT_EQ(F(-2.005), "-2.00");  // -2.00499... in binary
  EXPECT_EQ(F(480), "480.00");
  EXPECT_EQ(Label(1.0 / 3), "0.3333");
  EXPECT_EQ(Label(123456), "1.235e+05");
  EXPECT_EQ(Label(0), "0");
}

TEST(SvgPlot, AnAxisMapsItsEndsOntoItsPixelsAndMayRunBackwards) {
  const Axis x{10, 20, kLeft, kWidth - kRight};
  EXPECT_DOUBLE_EQ(x(10), kLeft);
  EXPECT_DOUBLE_EQ(x(20), kWidth - kRight);
  EXPECT_DOUBLE_EQ(x(15), (kLeft + kWidth - kRight) / 2);
  const Axis y{0, 1, kHeight - kBottom, kTop};  // values grow upwards, pixels downwards
  EXPECT_DOUBLE_EQ(y(0), kHeight - kBottom);
  EXPECT_DOUBLE_EQ(y(1), kTop);
}

TEST(SvgPlot, PadWidensByFivePercentOnEachSide) {
  double lo = 0, hi = 10;
  Pad(lo, hi);
  EXPECT_DOUBLE_EQ(lo, -0.5);
  EXPECT_DOUBLE_EQ(hi, 10.5);
}

TEST(SvgPlot, PadGivesAnEmptyOrReversedRangeAWidthBeforeWidening) {
  double lo = 5, hi = 5;  // one value: +-10 % of it, then 5 %
  Pad(lo, hi);
  EXPECT_DOUBLE_EQ(lo, 4.5 - 0.05);
  EXPECT_DOUBLE_EQ(hi, 5.5 + 0.05);
  double zlo = 0, zhi = 0;  // zero: a tiny range, never a division by zero on the axis
  Pad(zlo, zhi);
  EXPECT_LT(zlo, 0);
  EXPECT_GT(zhi, 0);
  const Axis a{zlo, zhi, 0, 100};
  EXPECT_DOUBLE_EQ(a(0), 50);
}

TEST(SvgPlot, EscapeReplacesTheFourMarkupCharactersAndNothingElse) {
  EXPECT_EQ(Escape("a < b && c > \"d\" 'e' μ"), "a &lt; b &amp;&amp; c &gt; &quot;d&quot; 'e' μ");
  EXPECT_EQ(Escape(""), "");
}

TEST(SvgPlot, TicksAreRoundNumbersInsideTheAxis) {
  // The report's histograms had ticks at 8.525 rocks and 434.4 m (a quarter of the range).
  EXPECT_EQ(NiceTicks(0, 434.4), (std::vector<double>{0, 100, 200, 300, 400}));
  EXPECT_EQ(NiceTicks(0, 8.525), (std::vector<double>{0, 2, 4, 6, 8}));
  EXPECT_EQ(NiceTicks(-1, 1), (std::vector<double>{-1, -0.5, 0, 0.5, 1}));
  EXPECT_EQ(NiceTicks(3.14, 3.35), (std::vector<double>{3.15, 3.2, 3.25, 3.3, 3.35}));
  // Multiples of 2.5 x a power of ten, and a narrow range still gets two ticks or more.
  EXPECT_EQ(NiceTicks(0, 11), (std::vector<double>{0, 2.5, 5, 7.5, 10}));
  EXPECT_GE(NiceTicks(0.999, 1.001).size(), 2u);
  for (double t : NiceTicks(-0.37, 0.52)) EXPECT_TRUE(t >= -0.37 && t <= 0.52) << t;
  EXPECT_EQ(NiceTicks(5, 5), std::vector<double>{5});  // no range: one tick, no endless loop
  // A range of two round-off units (an objective that differs only in its last digits): the tick
  // counter once grew past 2^53, where ++k no longer changes it, and never stopped. One tick.
  const double lo = 1234.5678, hi = std::nextafter(std::nextafter(lo, 2e3), 2e3);
  EXPECT_EQ(NiceTicks(lo, hi).size(), 1u);
  // Just above that: a handful of ticks, all inside.
  const std::vector<double> narrow = NiceTicks(lo, lo * (1 + 1e-10));
  EXPECT_GE(narrow.size(), 1u);
  EXPECT_LE(narrow.size(), 20u);
  for (double t : narrow) EXPECT_TRUE(t >= lo && t <= lo * (1 + 1e-10)) << t;
}

TEST(SvgPlot, TickLabelsHaveTheDecimalsOfTheirStep) {
  EXPECT_EQ(TickLabels({0, 100, 200}), (std::vector<std::string>{"0", "100", "200"}));
  EXPECT_EQ(TickLabels({-1, -0.5, 0, 0.5}),
            (std::vector<std::string>{"-1.0", "-0.5", "0.0", "0.5"}));
  EXPECT_EQ(TickLabels({0, 2.5, 5}), (std::vector<std::string>{"0.0", "2.5", "5.0"}));
  EXPECT_EQ(TickLabels({3.15, 3.2, 3.25}), (std::vector<std::string>{"3.15", "3.20", "3.25"}));
  EXPECT_EQ(TickLabels({0, 2e6, 4e6}), (std::vector<std::string>{"0", "2e+06", "4e+06"}));
}

TEST(SvgPlot, FrameHasTitleLabelsAndRoundTicksOnEachAxis) {
  const Axis x{0, 4, kLeft, kWidth - kRight};
  const Axis y{-1, 1, kHeight - kBottom, kTop};
  const std::string svg = Frame("Convergence", "evaluation", "objective", x, y);
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"480.00\"", 0), 0u);
  EXPECT_NE(svg.find(">Convergence</text>"), std::string::npos);
  EXPECT_NE(svg.find(">evaluation</text>"), std::string::npos);
  EXPECT_NE(svg.find("rotate(-90)\" text-anchor=\"middle\">objective</text>"), std::string::npos);
  // Ticks at 0, 1, 2, 3, 4 on x and -1, -0.5, 0, 0.5, 1 on y, placed by the axes.
  for (const char* tick : {">0</text>", ">1</text>", ">2</text>", ">3</text>", ">4</text>",
                           ">-1.0</text>", ">-0.5</text>", ">0.5</text>"})
    EXPECT_GE(Count(svg, tick), 1) << tick;
  EXPECT_EQ(Count(svg, "text-anchor=\"end\">"), 5);  // the y ticks
  EXPECT_NE(svg.find("<text x=\"" + F(x(2)) + "\" y=\"" + F(kHeight - kBottom + 14) + "\""),
            std::string::npos);
  EXPECT_NE(svg.find("y=\"" + F(y(0) + 4) + "\" text-anchor=\"end\">0.0</text>"),
            std::string::npos);
  // The caller closes the plot.
  EXPECT_EQ(svg.find("</svg>"), std::string::npos);
}

TEST(SvgPlot, FrameEscapesItsTitleAndLabels) {
  // A category or unit name from a user's file ("a<b & c") must not break the SVG.
  const Axis x{0, 1, kLeft, kWidth - kRight};
  const Axis y{0, 1, kHeight - kBottom, kTop};
  const std::string svg = Frame("kind <a&b>", "observed (m<sup>)", "\"y\"", x, y);
  EXPECT_NE(svg.find(">kind &lt;a&amp;b&gt;</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">observed (m&lt;sup&gt;)</text>"), std::string::npos) << svg;
  EXPECT_NE(svg.find(">&quot;y&quot;</text>"), std::string::npos) << svg;
  EXPECT_EQ(svg.find("<a&b>"), std::string::npos);
}

TEST(SvgPlot, FrameIsByteIdenticalForTheSameInput) {
  const Axis x{0.1, 0.7, kLeft, kWidth - kRight};
  const Axis y{3, 9, kHeight - kBottom, kTop};
  EXPECT_EQ(Frame("t", "x", "y", x, y), Frame("t", "x", "y", x, y));
}

}  // namespace
}  // namespace talus::io::svg
