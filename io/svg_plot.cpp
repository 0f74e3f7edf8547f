#include "io/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/format.hpp"

namespace talus::io::svg {

std::string F(double v) { return FormatDouble(v, "%.2f"); }

std::string Label(double v) { return FormatDouble(v, "%.4g"); }

void Pad(double& lo, double& hi) {
  if (!(hi > lo)) {
    const double d = std::max(std::abs(lo) * 0.1, 1e-9);
    lo -= d;
    hi += d;
  }
  const double d = 0.05 * (hi - lo);
  lo -= d;
  hi += d;
}

std::string Frame(const std::string& title, const std::string& x_label, const std::string& y_label,
                  const Axis& x, const Axis& y) {
  std::string out;
  Add(out, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", F(kWidth), "\" height=\"",
      F(kHeight), "\" font-family=\"sans-serif\" font-size=\"11\">\n");
  Add(out, "<rect x=\"0\" y=\"0\" width=\"", F(kWidth), "\" height=\"", F(kHeight),
      "\" fill=\"white\"/>\n");
  Add(out, "<text x=\"", F(kWidth / 2), "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">",
      Escape(title), "</text>\n");
  Add(out, "<rect x=\"", F(kLeft), "\" y=\"", F(kTop), "\" width=\"", F(kWidth - kLeft - kRight),
      "\" height=\"", F(kHeight - kTop - kBottom), "\" fill=\"none\" stroke=\"black\"/>\n");
  for (int k = 0; k <= 4; ++k) {
    const double vx = x.lo + (x.hi - x.lo) * k / 4, vy = y.lo + (y.hi - y.lo) * k / 4;
    Add(out, "<text x=\"", F(x(vx)), "\" y=\"", F(kHeight - kBottom + 14),
        "\" text-anchor=\"middle\">", Label(vx), "</text>\n");
    Add(out, "<text x=\"", F(kLeft - 4), "\" y=\"", F(y(vy) + 4), "\" text-anchor=\"end\">",
        Label(vy), "</text>\n");
  }
  Add(out, "<text x=\"", F(kLeft + (kWidth - kLeft - kRight) / 2), "\" y=\"", F(kHeight - 10),
      "\" text-anchor=\"middle\">", Escape(x_label), "</text>\n");
  Add(out, "<text transform=\"translate(14,", F(kTop + (kHeight - kTop - kBottom) / 2),
      ") rotate(-90)\" text-anchor=\"middle\">", Escape(y_label), "</text>\n");
  return out;
}

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace talus::io::svg
