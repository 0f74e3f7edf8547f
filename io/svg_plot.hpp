#pragma once
// Small, deterministic SVG plots shared by the calibration plots and the run report: a frame
// with a title, axis labels and ticks, and the helpers that place values in it. Numbers are
// printed with fixed digits, so the same data give the same bytes.

#include <string>

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

// The opening of a kWidth × kHeight plot: white background, title, plot box, five ticks on each
// axis and the axis labels (the title and labels are escaped here: pass them as plain text). The
// caller adds the marks and closes it with "</svg>\n".
std::string Frame(const std::string& title, const std::string& x_label, const std::string& y_label,
                  const Axis& x, const Axis& y);

// Escapes &, <, > and " for text in SVG or HTML.
std::string Escape(const std::string& text);

}  // namespace talus::io::svg
