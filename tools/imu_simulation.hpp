// IMU simulation shared by `ultratrack imusim` and `ultratrack simulate`: runs a trajectory through the
// trajectory simulator, writes the error-corrupted increments (seeded preset) to an IMU CSV and hands every
// truth sample (t = 0 and the end of each IMU interval) to the caller; odometer CSV and summary fields.
// Units SI; truth and increments on the trajectory's time line (seconds from its start).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"

namespace ultratrack::tools {

struct ImuSimulationResult {
  std::size_t imu_rows = 0;
  ins::ImuErrors turn_on;  // the unit's drawn turn-on errors
  double distance_m = 0.0;
};

// Streams the trajectory: imu_csv gets one row per IMU interval (written atomically), on_truth sees every
// truth sample in time order. progress_label: prints every 10 % on stderr for long runs ("" = silent).
ImuSimulationResult simulate_imu(const ins::TrajectorySpec& spec, double imu_rate_hz, const ins::ImuErrorSpec& errors,
                                 std::uint64_t seed, const std::filesystem::path& imu_csv,
                                 const std::function<void(const ins::TruthSample&)>& on_truth,
                                 const std::string& progress_label = "");

// odometer.csv (`t_s,pulses,distance_m`, 10 Hz, 2 cm pulses) from truth at the IMU rate.
void write_odometer_csv(const std::filesystem::path& file, std::span<const ins::TruthSample> truth,
                        double scale_factor_error);

// JSON members (no braces, trailing comma) with the turn-on biases: deg/h and m/s^2.
std::string turn_on_bias_json(const ins::ImuErrors& errors);

}  // namespace ultratrack::tools
