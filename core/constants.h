#pragma once
// Physical and numerical constants. Units: millimetres and picoseconds.

#include <limits>

namespace femto {
/// Speed of light in vacuum, mm/ps.
constexpr double kSpeedOfLight = 0.299792458;
constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 1.0 / kPi;
constexpr double kInv4Pi = 1.0 / (4.0 * kPi);
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace femto
