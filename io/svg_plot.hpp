#pragma once
// Small, deterministic SVG plots shared by the calibration plots and the run report: a frame
// with a title, axis labels and ticks, and the helpers that place values in it. Numbers are
// printed with fixed digits, so the same data give the same bytes.

#include <string>
#include <vector>

namespace talus::io::svg {

inline constexpr double kWidth = 480, kHeight = 360;
inline constexpr double kLeft = 64, kRight = 16, kTop = 32, kBottom = 48;

// Appends the parts one by one (GCC 12 warns wrongly about chains of std::string operator+).
template <class... Parts>
void Add(std::string& out, const Parts&... parts) {
  (out.append(parts), ...);
}

// A coordinate in pixels (2 decimals).
std::string F(double v);
// A value on an axis or in a label (4 significant digits).
std::string Label(double v);

// A linear axis from lo to hi onto pixels a .. b.
struct Axis {
  double lo, hi, a, b;
  double operator()(double v) const { return a + (v - lo) / (hi - lo) * (b - a); }
};

// lo and hi widened to at least a small range, and by 5 % on each side.
void Pad(double& lo, double& hi);

// Round ("nice number") tick values inside [lo, hi]: multiples of 1, 2, 2.5 or 5 times a power
// of ten, about `target` of them (at least two when lo < hi), e.g. 0, 100, 200, 300, 400 for
// 0 .. 434.4 and 0, 2, 4, 6, 8 for 0 .. 8.525.
std::vector<double> NiceTicks(double lo, double hi, int target = 5);
// The labels of `ticks` (NiceTicks) with the decimals their step needs and no more: "0", "0.5",
// "1", "1.5"; "2.5e+06" style beyond 1e6 or below 1e-4.
std::vector<std::string> TickLabels(const std::vector<double>& ticks);

// The opening of a kWidth × kHeight plot: white background, title, plot box, round ticks on each
// axis (NiceTicks) and the axis labels (the title and labels are escaped here: pass them as plain
// text). The caller adds the marks and closes it with "</svg>\n".
std::string Frame(const std::string& title, const std::string& x_label, const std::string& y_label,
                  const Axis& x, const Axis& y);

// Plots made by Frame (each closed) side by side, `columns` to a row, as one SVG document: for a
// file of several panels. With no plot, one line of `empty` text.
std::string Stack(const std::vector<std::string>& plots, int columns, const std::string& empty);

// Escapes &, <, > and " for text in SVG or HTML.
std::string Escape(const std::string& text);

}  // namespace talus::io::svg
