// SPDX-License-Identifier: GPL-3.0-or-later
// IMU simulation shared by `simulate` and `ultratrack imusim`: runs a trajectory through the trajectory
// simulator, hands the error-corrupted increments (seeded preset) and every truth sample (t = 0 and the end of
// each IMU interval) to the caller in time order. Units SI; times on the trajectory's time line (s from its start).
#pragma once

#include <cstdint>
#include <functional>
#include <stop_token>

#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"

namespace ultratrack::sim {

struct ImuSimulationResult {
  std::size_t imu_rows = 0;
  bool interrupted = false;  // stopped by the stop token before the trajectory's end
  ins::ImuErrors turn_on;    // the unit's drawn turn-on errors
  double distance_m = 0.0;
};

struct ImuSimulationCallbacks {
  std::function<void(const ins::ImuIncrement&)> on_imu;   // one per IMU interval
  std::function<void(const ins::TruthSample&)> on_truth;  // t = 0, then the end of each interval
  std::function<void(int percent)> on_progress;           // every 10 % of long runs (>= 500000 rows); optional
};

// A stop request ends the run between two IMU intervals: what was handed over is a consistent prefix.
ImuSimulationResult simulate_imu(const ins::TrajectorySpec& spec, double imu_rate_hz, const ins::ImuErrorSpec& errors,
                                 std::uint64_t seed, const ImuSimulationCallbacks& callbacks,
                                 std::stop_token stop = {});

}  // namespace ultratrack::sim
