// SPDX-License-Identifier: GPL-3.0-or-later
// The work of `ultratrack align`, callable in process: an IMU at rest and a multi-antenna receiver's attitude.csv
// through [KimAlign]'s stationary alignment (fusion/stationary_alignment.hpp), with the observability of the final
// attitude (fusion/alignment_observability.hpp, a warning near pitch 90 deg), the array's mounting on the IMU
// (fusion/mounting_misalignment.hpp: mean GPS attitude against the IMU's own levelling and gyrocompassing over the
// same span, or against a given reference attitude), and the files: alignment.json (the result) and alignment.csv (one
// row per filter epoch). The settings come from `fuse`'s configuration keys: [imu] (the filter's error model),
// [initial] position_deg_m (needed: latitude and gravity), [attitude] gps_time_at_imu_zero, misalignment_deg (the
// mounting assumed), max_pitch_deg, [filter] ukf_* and gate keys. Times on the IMU time line (s); angles rad inside,
// deg in files.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fusion/alignment_observability.hpp"
#include "fusion/mounting_misalignment.hpp"
#include "fusion/stationary_alignment.hpp"
#include "ins/nav_state.hpp"
#include "pipelines/fuse_config.hpp"
#include "pipelines/fuse_inputs.hpp"

namespace ultratrack::pipelines {

struct AlignSettings {
  FuseConfig config;
  fusion::FilterKind filter = fusion::FilterKind::Ekf;
  double duration_s = 100.0;  // from the first usable GPS attitude; 0: all the data
  double filter_interval_s = 1.0;
  std::string imu_file = "IMU file", attitude_file = "attitude file";  // for messages
  std::string time_note;  // how the IMU was put on GPS time (PPS), for the json
  // The body's attitude from a reference (an INS aligned to the vehicle, as [KimAlign]'s MAPS) and its 1-sigma (roll,
  // pitch, yaw): the mounting is then measured against it instead of the IMU's own levelling and gyrocompassing.
  std::optional<ins::EulerAngles> reference_attitude;
  Eigen::Vector3d reference_sigma_rad = Eigen::Vector3d::Zero();
};

struct AlignRunResult {
  fusion::StationaryAlignmentResult alignment;
  fusion::ObservabilityReport observability;
  fusion::MountingEstimate mounting;
  ins::EulerAngles reference_attitude;  // the IMU's own levelling + gyrocompassing, or the given one
  Eigen::Vector3d reference_sigma_rad = Eigen::Vector3d::Zero();
  std::vector<std::string> warnings;
  long long attitude_rows = 0, fixed_rows = 0, rows_in_span = 0;
};

// Throws io::InputError naming the file for: no fixed attitude rows, fixed attitudes that do not overlap the IMU
// data, no position, no GPS time origin, too short a span.
AlignRunResult run_alignment(const std::vector<ins::ImuIncrement>& imu, const std::vector<GpsAttitudeRow>& attitude,
                             const AlignSettings& settings);

std::string alignment_json(const AlignRunResult& result, const AlignSettings& settings);
std::string alignment_csv(const AlignRunResult& result);

// alignment.json read back to start `fuse` or `receive --imu` (`--align file:alignment.json`): the attitude and
// its 1-sigma become [initial] attitude_deg and sigma_attitude_deg of the configuration (a `config` start); the
// bias estimates and their 1-sigma (when the file has them; all four or none) start the filter's bias states.
// Throws io::InputError naming the file when a key is missing or malformed, a sigma not positive.
struct AlignmentFileStart {
  Eigen::Vector3d attitude_deg = Eigen::Vector3d::Zero();  // roll, pitch, yaw
  Eigen::Vector3d sigma_attitude_deg = Eigen::Vector3d::Zero();
  struct Biases {
    Eigen::Vector3d accel_mps2, sigma_accel_mps2;  // body axes
    Eigen::Vector3d gyro_rps, sigma_gyro_rps;      // (deg/h in the file)
  };
  std::optional<Biases> biases;
};
AlignmentFileStart read_alignment_json(const std::filesystem::path& file);
void apply_alignment_file(FuseConfig& config, const std::filesystem::path& file);

}  // namespace ultratrack::pipelines
