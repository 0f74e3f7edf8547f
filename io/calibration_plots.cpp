#include "io/calibration_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "io/html_page.hpp"
#include "io/svg_plot.hpp"

namespace talus::io {

using svg::Add;
using svg::Axis;
using svg::F;
using svg::Frame;
using svg::kBottom;
using svg::kHeight;
using svg::kLeft;
using svg::kRight;
using svg::kTop;
using svg::kWidth;
using svg::Pad;

std::string ConvergenceSvg(const calibration::OptimizerSummary& summary) {
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
  const bool dimensionless = unit.empty() || unit == "1";
  std::string out =
      Frame(html::HumanLabel(kind) + ": observed vs simulated median",
            dimensionless ? "observed" : "observed (" + unit + ")",
            dimensionless ? "simulated median" : "simulated median (" + unit + ")", x, y);
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

std::string ProfileSvg(const std::string& name, const std::string& unit,
                       const std::vector<double>& values, const std::vector<double>& objective,
                       double fitted, bool identified) {
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (std::size_t k = 0; k < values.size() && k < objective.size(); ++k)
    if (std::isfinite(values[k]) && std::isfinite(objective[k])) {
      x_lo = std::min(x_lo, values[k]);
      x_hi = std::max(x_hi, values[k]);
      y_lo = std::min(y_lo, objective[k]);
      y_hi = std::max(y_hi, objective[k]);
    }
  if (std::isfinite(fitted)) {
    x_lo = std::min(x_lo, fitted);
    x_hi = std::max(x_hi, fitted);
  }
  if (!std::isfinite(x_lo)) x_lo = x_hi = 0;
  if (!std::isfinite(y_lo)) y_lo = y_hi = 0;
  Pad(x_lo, x_hi);
  Pad(y_lo, y_hi);
  const Axis x{x_lo, x_hi, kLeft, kWidth - kRight}, y{y_lo, y_hi, kHeight - kBottom, kTop};
  std::string out =
      Frame("Profile of " + name + (identified ? "" : " (flat: unidentified)"),
            unit.empty() || unit == "1" ? name : name + " (" + unit + ")", "objective", x, y);
  std::string line;
  for (std::size_t k = 0; k < values.size() && k < objective.size(); ++k) {
    if (!std::isfinite(values[k]) || !std::isfinite(objective[k])) continue;
    Add(out, "<circle cx=\"", F(x(values[k])), "\" cy=\"", F(y(objective[k])),
        "\" r=\"3\" fill=\"#1f5fbf\"/>\n");
    Add(line, line.empty() ? "" : " ", F(x(values[k])), ",", F(y(objective[k])));
  }
  Add(out, "<polyline points=\"", line, "\" fill=\"none\" stroke=\"#1f5fbf\"/>\n");
  if (std::isfinite(fitted))
    Add(out, "<line x1=\"", F(x(fitted)), "\" x2=\"", F(x(fitted)), "\" y1=\"", F(kTop), "\" y2=\"",
        F(kHeight - kBottom), "\" stroke=\"#d7191c\" stroke-dasharray=\"4 3\"/>\n", "<text x=\"",
        F(x(fitted) + 4), "\" y=\"", F(kTop + 14), "\" fill=\"#d7191c\">fitted</text>\n");
  return out + "</svg>\n";
}

}  // namespace talus::io
