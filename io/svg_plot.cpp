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

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {lo};
  // A range of a few round-off units (values equal but for the last digits) has no round ticks
  // inside: one tick, at its middle.
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) return {0.5 * (lo + hi)};
  // The step is m x 10^e; a tick k m / 10^-e (or k m 10^e) is then the double nearest the round
  // number (3.15, not 63 x 0.05 = 3.1500000000000004).
  const double raw = (hi - lo) / std::max(1, target);
  const int e = static_cast<int>(std::floor(std::log10(raw)));
  const double power = std::pow(10.0, std::abs(e));
  const auto at = [&](double km) { return e < 0 ? km / power : km * power; };
  double m = 10;
  for (double candidate : {1.0, 2.0, 2.5, 5.0})
    if (at(candidate) >= raw * (1 - 1e-9)) {
      m = candidate;
      break;
    }
  // Fewer than two ticks inside (a range shorter than a step from its first multiple): halve,
  // at most a few times (the step starts near (hi - lo) / target).
  for (int halvings = 0;
       halvings < 8 && std::floor(hi / at(m) + 1e-9) - std::ceil(lo / at(m) - 1e-9) < 1; ++halvings)
    m /= 2;
  // Ticks by an integer count, bounded, so that no rounding of k can keep the loop going.
  const double first = std::ceil(lo / at(m) - 1e-9);
  const double count = std::floor(hi / at(m) + 1e-9) - first + 1;
  if (!(count >= 1 && count <= 1000)) return {0.5 * (lo + hi)};
  std::vector<double> ticks;
  for (int i = 0; i < static_cast<int>(count); ++i) {
    const double k = first + i;
    ticks.push_back(k == 0 ? 0.0 : at(k * m));  // never "-0"
  }
  return ticks;
}

std::vector<std::string> TickLabels(const std::vector<double>& ticks) {
  double step = 0, largest = 0;
  for (std::size_t k = 1; k < ticks.size(); ++k) step = std::max(step, ticks[k] - ticks[k - 1]);
  for (double t : ticks) largest = std::max(largest, std::abs(t));
  std::vector<std::string> labels;
  const bool exponent = largest >= 1e6 || (largest > 0 && largest < 1e-4);
  // Decimals of the step: 0.25 needs 2, 0.5 needs 1, 20 needs none.
  int decimals = 0;
  if (step > 0)
    while (decimals < 10 && std::abs(step * std::pow(10.0, decimals) -
                                     std::round(step * std::pow(10.0, decimals))) > 1e-6)
      ++decimals;
  char format[16];
  std::snprintf(format, sizeof format, exponent ? "%%.%dg" : "%%.%df", exponent ? 4 : decimals);
  for (double t : ticks) labels.push_back(FormatDouble(t, format));
  return labels;
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
  const std::vector<double> x_ticks = NiceTicks(x.lo, x.hi), y_ticks = NiceTicks(y.lo, y.hi);
  const std::vector<std::string> x_labels = TickLabels(x_ticks), y_labels = TickLabels(y_ticks);
  for (std::size_t k = 0; k < x_ticks.size(); ++k)
    Add(out, "<text x=\"", F(x(x_ticks[k])), "\" y=\"", F(kHeight - kBottom + 14),
        "\" text-anchor=\"middle\">", x_labels[k], "</text>\n");
  for (std::size_t k = 0; k < y_ticks.size(); ++k)
    Add(out, "<text x=\"", F(kLeft - 4), "\" y=\"", F(y(y_ticks[k]) + 4), "\" text-anchor=\"end\">",
        y_labels[k], "</text>\n");
  Add(out, "<text x=\"", F(kLeft + (kWidth - kLeft - kRight) / 2), "\" y=\"", F(kHeight - 10),
      "\" text-anchor=\"middle\">", Escape(x_label), "</text>\n");
  Add(out, "<text transform=\"translate(14,", F(kTop + (kHeight - kTop - kBottom) / 2),
      ") rotate(-90)\" text-anchor=\"middle\">", Escape(y_label), "</text>\n");
  return out;
}

std::string Stack(const std::vector<std::string>& plots, int columns, const std::string& empty) {
  const int n = static_cast<int>(plots.size());
  const int across = std::max(1, std::min(columns, n)),
            down = std::max(1, (n + across - 1) / across);
  std::string out;
  Add(out, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", F(across * kWidth), "\" height=\"",
      F(n > 0 ? down * kHeight : 40), "\" font-family=\"sans-serif\">\n");
  if (n == 0)
    Add(out, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"20\" y=\"24\">",
        Escape(empty), "</text>\n");
  for (int k = 0; k < n; ++k)
    Add(out, "<g transform=\"translate(", F((k % across) * kWidth), ",", F((k / across) * kHeight),
        ")\">\n", plots[static_cast<std::size_t>(k)], "</g>\n");
  return out + "</svg>\n";
}

std::string Escape(const std::string& text) { return XmlEscaped(text); }

}  // namespace talus::io::svg
