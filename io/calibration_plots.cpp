#include "io/calibration_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace talus::io {
namespace {

constexpr double kWidth = 480, kHeight = 360;
constexpr double kLeft = 64, kRight = 16, kTop = 32, kBottom = 48;

// Appends the parts one by one (GCC 12 warns wrongly about chains of std::string operator+).
template <class... Parts>
void Add(std::string& out, const Parts&... parts) {
  (out.append(parts), ...);
}

std::string F(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string Label(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A linear axis from lo to hi onto pixels a .. b.
struct Axis {
  double lo, hi, a, b;
  double operator()(double v) const { return a + (v - lo) / (hi - lo) * (b - a); }
};

// lo and hi widened to at least a small range, and by 5 % on each side.
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
      title, "</text>\n");
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
      "\" text-anchor=\"middle\">", x_label, "</text>\n");
  Add(out, "<text transform=\"translate(14,", F(kTop + (kHeight - kTop - kBottom) / 2),
      ") rotate(-90)\" text-anchor=\"middle\">", y_label, "</text>\n");
  return out;
}

}  // namespace

std::string ConvergenceSvg(const calibration::Summary& summary) {
  double lo = INFINITY, hi = -INFINITY;
  for (const calibration::Evaluation& e : summary.history)
    if (e.feasible && std::isfinite(e.value)) {
      lo = std::min(lo, e.value);
      hi = std::max(hi, e.value);
    }
  if (!std::isfinite(lo)) lo = hi = 0;
  Pad(lo, hi);
  const double n = std::max<double>(1, summary.evaluations() - 1);
  const Axis x{0, n, kLeft, kWidth - kRight}, y{lo, hi, kHeight - kBottom, kTop};
  std::string out =
      Frame("Convergence (" + summary.algorithm + ")", "evaluation", "objective", x, y);
  std::string line;
  double best = INFINITY;
  for (int k = 0; k < summary.evaluations(); ++k) {
    const calibration::Evaluation& e = summary.history[static_cast<std::size_t>(k)];
    if (!e.feasible || !std::isfinite(e.value)) continue;
    Add(out, "<circle cx=\"", F(x(k)), "\" cy=\"", F(y(e.value)),
        "\" r=\"2.5\" fill=\"#999999\"/>\n");
    best = std::min(best, e.value);
    Add(line, line.empty() ? "" : " ", F(x(k)), ",", F(y(best)));
  }
  Add(out, "<polyline points=\"", line,
      "\" fill=\"none\" stroke=\"#1f5fbf\" stroke-width=\"2\"/>\n");
  Add(out, "<text x=\"", F(kWidth - kRight - 4), "\" y=\"", F(kTop + 14),
      "\" text-anchor=\"end\" fill=\"#1f5fbf\">best so far</text>\n");
  return out + "</svg>\n";
}

std::string ObservedSimulatedSvg(const std::string& kind,
                                 const std::vector<fieldobs::ObservationScore>& before,
                                 const std::vector<fieldobs::ObservationScore>& after) {
  double lo = INFINITY, hi = -INFINITY;
  std::string unit;
  for (const auto* set : {&before, &after})
    for (const fieldobs::ObservationScore& o : *set)
      if (o.kind == kind && o.scored) {
        unit = o.unit;
        for (double v : {o.observed, o.median})
          if (std::isfinite(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
      }
  if (!std::isfinite(lo)) lo = hi = 0;
  Pad(lo, hi);
  const Axis x{lo, hi, kLeft, kWidth - kRight}, y{lo, hi, kHeight - kBottom, kTop};
  std::string out = Frame(kind + ": observed vs simulated median", "observed (" + unit + ")",
                          "simulated median (" + unit + ")", x, y);
  Add(out, "<line x1=\"", F(x(lo)), "\" y1=\"", F(y(lo)), "\" x2=\"", F(x(hi)), "\" y2=\"",
      F(y(hi)), "\" stroke=\"black\" stroke-dasharray=\"4 3\"/>\n");
  const auto dots = [&](const std::vector<fieldobs::ObservationScore>& set, const char* colour) {
    for (const fieldobs::ObservationScore& o : set)
      if (o.kind == kind && o.scored && std::isfinite(o.median))
        Add(out, "<circle cx=\"", F(x(o.observed)), "\" cy=\"", F(y(o.median)),
            "\" r=\"3\" fill=\"", colour, "\" fill-opacity=\"0.7\"/>\n");
  };
  dots(before, "#999999");
  dots(after, "#1f5fbf");
  Add(out, "<text x=\"", F(kLeft + 6), "\" y=\"", F(kTop + 14),
      "\" fill=\"#999999\">before</text>\n<text x=\"", F(kLeft + 6), "\" y=\"", F(kTop + 28),
      "\" fill=\"#1f5fbf\">after</text>\n");
  return out + "</svg>\n";
}

}  // namespace talus::io
