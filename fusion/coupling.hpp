// SPDX-License-Identifier: GPL-3.0-or-later
// How GNSS and the tracking loops (and an INS) are coupled: the one coupling enum of the tree, used by the
// GNSS/INS integration (loose, tight), the covariance analysis (tight, ultra-tight) and every receive pipeline
// (pipelines/ re-exports it as pipelines::Coupling).
//   kScalar      every channel its own DLL/PLL (receiver/scalar_tracking.hpp)
//   kVector      one vector filter closes the channels' code loops (pipelines/vector_loop_driver.hpp)
//   kLoose       GNSS/INS integration on the PVT fixes (pipelines/gnss_ins_coupler.hpp)
//   kTight       GNSS/INS integration on pseudoranges and rates (pipelines/gnss_ins_coupler.hpp)
//   kUltraTight  tight pull-in, then the INS-predicted replica drives the channels (pipelines/ultratight_loop.hpp)
// Text names: "scalar" (also "none"), "vector", "loose", "tight", "ultra-tight".
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace ultratrack::fusion {

enum class Coupling { kScalar, kVector, kLoose, kTight, kUltraTight };

// Nothing for an unknown name.
std::optional<Coupling> coupling_from_string(std::string_view text);
std::string to_string(Coupling coupling);

// Couplings that run an INS (need an IMU file): loose, tight, ultra-tight.
constexpr bool uses_imu(Coupling c) {
  return c == Coupling::kLoose || c == Coupling::kTight || c == Coupling::kUltraTight;
}
// Couplings whose GNSS/INS filter takes raw observations (ultra-tight pulls in with the tight filter).
constexpr bool is_tight(Coupling c) { return c == Coupling::kTight || c == Coupling::kUltraTight; }

}  // namespace ultratrack::fusion
