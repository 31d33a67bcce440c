#pragma once
/// Angles between headings of boxes, whose front and back look alike.
#include <algorithm>
#include <cmath>

namespace romo {

inline constexpr double kAnglesPi = 3.14159265358979323846;

/// The angle between the axes of two headings, radians in [0, pi/2].
inline double AxisAngle(double a_rad, double b_rad) {
  constexpr double kPi = kAnglesPi;
  const double d = std::fmod(std::abs(a_rad - b_rad), kPi);
  return std::min(d, kPi - d);
}

/// The same in degrees, [0, 90].
inline double AxisAngleDeg(double a_rad, double b_rad) { return AxisAngle(a_rad, b_rad) * 180.0 / kAnglesPi; }

}  // namespace romo
