// SPDX-License-Identifier: GPL-3.0-or-later
// The one degree constant of the tree: angles are radians inside, degrees only at the edges (files, command lines,
// configuration keys with _deg in their names).
#pragma once

#include <numbers>

namespace ultratrack::io {

inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;  // x_deg * kRadPerDeg = x_rad
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;  // x_rad * kDegPerRad = x_deg

}  // namespace ultratrack::io
