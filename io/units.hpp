// SPDX-License-Identifier: GPL-3.0-or-later
// The degree constants of the tree: angles are radians inside, degrees only at the edges (files, command lines,
// configuration keys with _deg in their names); gyro rates likewise rad/s inside, deg/h (datasheets, reports) at the
// edges.
#pragma once

#include <numbers>

namespace ultratrack::io {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;          // x_deg * kRadPerDeg = x_rad
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;          // x_rad * kDegPerRad = x_deg
inline constexpr double kRadPerSecPerDegPerHour = kRadPerDeg / 3600.0;  // x_dph * this = x_rps

}  // namespace ultratrack::io
