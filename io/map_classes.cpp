#include "io/map_classes.hpp"

#include <algorithm>
#include <cmath>

#include "common/format.hpp"

namespace talus::io {
namespace {

using Rgb = std::array<double, 3>;

// Yellow (low) through orange to dark red (high), t in [0, 1].
std::array<unsigned char, 3> Ramp(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const Rgb stops[] = {{255, 255, 150}, {253, 141, 60}, {189, 0, 38}, {90, 0, 20}};
  const double s = t * 3;
  const int k = std::min(2, static_cast<int>(s));
  const double f = s - k;
  std::array<unsigned char, 3> rgb{};
  for (int c = 0; c < 3; ++c)
    rgb[c] =
        static_cast<unsigned char>(std::lround(stops[k][c] + f * (stops[k + 1][c] - stops[k][c])));
  return rgb;
}

// Classes with the given lower bounds and labels, coloured evenly along the ramp.
std::vector<ColourClass> Classes(const std::vector<double>& lower,
                                 const std::vector<std::string>& labels) {
  std::vector<ColourClass> classes;
  for (std::size_t k = 0; k < lower.size(); ++k)
    classes.push_back(
        {lower[k], labels[k], Ramp(lower.size() == 1 ? 1.0 : double(k) / (lower.size() - 1))});
  return classes;
}

std::string Number(double value) { return FormatDouble(value, "%.3g"); }

bool StartsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// The statistic of a layer name such as "speed_p95", for the legend's title.
std::string StatisticOf(const std::string& name) {
  const std::size_t underscore = name.rfind('_');
  std::string statistic = underscore == std::string::npos ? "" : name.substr(underscore + 1);
  if (statistic == "max") return "largest";
  if (statistic == "mean") return "mean";
  if (statistic.size() > 1 && statistic[0] == 'p') {
    const std::string n = statistic.substr(1);  // 1st, 2nd, 3rd, 4th, ..., 11th .. 13th, 21st
    const char last = n.back();
    const bool teen = n.size() > 1 && n[n.size() - 2] == '1';
    const char* suffix = teen          ? "th"
                         : last == '1' ? "st"
                         : last == '2' ? "nd"
                         : last == '3' ? "rd"
                                       : "th";
    return n + suffix + " percentile of";
  }
  return statistic;
}

}  // namespace

int QuickLookLegend::ClassOf(double value) const {
  if (!(value > 0) || classes.empty()) return -1;
  int k = 0;
  // Rasters hold floats: compare in float, so that 1 rock in 100 (0.01f, just below 0.01) is 1 %.
  while (k + 1 < static_cast<int>(classes.size()) &&
         static_cast<float>(value) >= static_cast<float>(classes[k + 1].lower))
    ++k;
  return k;
}

QuickLookLegend LegendOf(const ensemble::RasterLayer& layer) {
  const std::string& name = layer.name;
  if (name == "reach_probability")
    return {"Reach probability",
            Classes({0, 0.01, 0.1, 0.3}, {"below 1 %", "1 - 10 %", "10 - 30 %", "30 - 100 %"})};
  if (StartsWith(name, "energy"))
    return {
        "Energy, " + StatisticOf(name) + " (kJ)",
        Classes({0, 30e3, 300e3, 1000e3, 3000e3}, {"below 30 kJ", "30 - 300 kJ", "300 - 1000 kJ",
                                                   "1000 - 3000 kJ", "3000 kJ and more"})};
  if (StartsWith(name, "speed"))
    return {"Speed, " + StatisticOf(name) + " (m/s)",
            Classes({0, 5, 10, 20, 30}, {"below 5 m/s", "5 - 10 m/s", "10 - 20 m/s", "20 - 30 m/s",
                                         "30 m/s and more"})};
  if (StartsWith(name, "jump_height"))
    return {"Jump height, " + StatisticOf(name) + " (m)",
            Classes({0, 1, 2, 5, 10},
                    {"below 1 m", "1 - 2 m", "2 - 5 m", "5 - 10 m", "10 m and more"})};
  if (name == "passages" || name == "deposits")
    return {name == "passages" ? "Rocks that passed" : "Rocks at rest",
            Classes({0, 1.5, 10.5, 100.5, 1000.5}, {"1 rock", "2 - 10 rocks", "11 - 100 rocks",
                                                    "101 - 1000 rocks", "more than 1000"})};
  // Anything else: five equal classes up to the largest value.
  double top = 0;
  for (float v : layer.values)
    if (v != ensemble::RasterLayer::kNoData) top = std::max(top, double(v));
  std::vector<double> lower;
  std::vector<std::string> labels;
  for (int k = 0; k < 5; ++k) {
    lower.push_back(k * top / 5);
    labels.push_back(Number(k * top / 5) + " - " + Number((k + 1) * top / 5) + " " + layer.unit);
  }
  return {name + " (" + layer.unit + ")", Classes(lower, labels)};
}

QuickLookLegend EnergyLegend() { return LegendOf({"energy_max", "J", {}}); }

}  // namespace talus::io
