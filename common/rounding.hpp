#pragma once
// Rounding to the nearest integer without a call into the maths library, for grid lookups made in
// every step (a raster's cell, a ground category).

#include <cmath>
#include <limits>

namespace talus {

// std::lround(x): the nearest integer, halves away from zero, for |x| < 2^62. x - trunc(x) is
// exact for |x| < 2^52, and from there on x is an integer. NaN and |x| >= 2^62 give LONG_MIN,
// outside every grid (as lround's result is for NaN and |x| >= 2^63).
inline long RoundHalfAway(double x) {
  if (!(std::abs(x) < 0x1p62)) return std::numeric_limits<long>::min();
  const auto whole = static_cast<long>(x);  // truncated towards zero
  const double fraction = x - static_cast<double>(whole);
  if (fraction >= 0.5) return whole + 1;
  if (fraction <= -0.5) return whole - 1;
  return whole;
}

}  // namespace talus
