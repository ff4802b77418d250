// SPDX-License-Identifier: GPL-3.0-or-later
// The one GNSS/INS start of `fuse` and `receive --coupling loose|tight|ultra-tight`: an alignment gives the time,
// attitude (and for motion the velocity) with their 1-sigmas; initialise_navigation adds the position (the
// configuration's, or a GNSS fix's moved from the antenna to the IMU by the lever arm) and the configuration's
// overrides of the initial state and sigmas. Alignments:
//   static    levelling + gyrocompassing over the IMU rows of the first static_duration_s at rest; attitude sigmas
//             from the residual biases (tilt b_a / g, heading b_g / (W cos L)) and the span's noise, twice for margin
//   motion    heading from the GNSS track, tilt from the accelerometers (fusion/fuse_motion_alignment.hpp)
//   config    the configuration's attitude_deg
//   attitude  the first fixed GPS attitude (`fuse` only: it is built from the attitude rows there)
// Units SI (angles in radians) except where the name says deg.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "fusion/fuse_motion_alignment.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"
#include "ins/standstill_gyro_bias.hpp"
#include "pipelines/fuse_config.hpp"

namespace ultratrack::pipelines {

enum class AlignMode { Static, Motion, Config, Attitude };
const char* to_string(AlignMode mode);                                   // "static", "motion", "config", "attitude"
std::optional<AlignMode> align_mode_from_string(std::string_view name);  // to_string's names; nothing otherwise

// An alignment's result: the INS start time, attitude and velocity, their 1-sigmas, and a note for summaries.
struct AttitudeStart {
  double t_s = 0.0;
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_vel_n_mps = Eigen::Vector3d::Constant(1.0);
  Eigen::Vector3d sigma_att_rad = Eigen::Vector3d::Zero();
  std::string note;
  double heading_sigma_rad = 0.0;  // static: the gyrocompassing's heading 1-sigma (before the margin)
  // Motion: the attitude error per unit of IMU bias (fusion/attitude_bias_correlation.hpp); sigma_att_rad is then
  // the part independent of the biases. Zero for the other alignments.
  fusion::AttitudePerBias attitude_per_bias = fusion::AttitudePerBias::Zero();
  // Motion: the gyro biases a standstill at the record's start measured (motion_standstill), removed from the
  // alignment's increments; they start the filter's gyro bias states.
  std::optional<ins::StandstillGyroBias> standstill;
};

// Motion alignment's standstill (ins/standstill_gyro_bias.hpp): the gyro biases measured over a standstill at the
// start of imu, ending by end_by_s, when config.standstill_gyro_bias and the estimate beats the preset's turn-on
// sigma on every axis; nothing otherwise.
std::optional<ins::StandstillGyroBias> motion_standstill(std::span<const ins::ImuIncrement> imu, double lat_rad,
                                                         const FuseConfig& config, const ins::ImuErrorSpec& preset,
                                                         double end_by_s);

// Static: the number of IMU rows in the span [t0_s, t0_s + config.static_duration_s] (rows past it must exist);
// io::InputError naming imu_name when the span holds fewer than two rows or the data end inside it.
std::size_t static_span_end(std::span<const ins::ImuIncrement> imu, double t0_s, const FuseConfig& config,
                            const std::string& imu_name);
// Static over span (static_span_end's rows) from t0_s at lat_rad; velocity zero, 1-sigma 0.1 m/s.
AttitudeStart align_static(std::span<const ins::ImuIncrement> span, double t0_s, double lat_rad,
                           const ins::ImuErrorSpec& preset);
// Motion over the GNSS velocities (window_s: the velocity difference span), with a standstill's gyro biases
// (motion_standstill) when given. The attitude's error from the IMU
// biases goes into attitude_per_bias (the filter correlates it with its bias states); sigma_att_rad holds the rest:
// from measured velocities, the first-order effect of their white noise (config.velocity_sigma_mps at both ends of
// the window: tilt about sqrt(2) sigma_v / (T g), heading sigma_v / speed), velocity 2 x that sigma; position_only
// (velocities from positions, correlated between the window's ends): tilt 3 deg, heading the end velocity's
// sigma_horizontal_mps / speed (at least 1 deg: sideslip; 5 deg when not known), velocity 1 m/s. Nothing when the
// GNSS never shows config.motion_min_speed_mps over the window.
std::optional<AttitudeStart> align_moving(std::span<const ins::ImuIncrement> imu,
                                          std::span<const fusion::GnssVelocitySample> velocities,
                                          const FuseConfig& config, double window_s, bool position_only,
                                          const std::optional<ins::StandstillGyroBias>& standstill = std::nullopt);
// Config: config.attitude_deg (must be set) at t_s; attitude 1-sigma 1, 1, 5 deg, velocity 1 m/s.
AttitudeStart align_from_config(double t_s, const FuseConfig& config);

// A GNSS position (the antenna's) and its NED 1-sigma.
struct GnssPosition {
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Vector3d sigma_ned_m = Eigen::Vector3d::Ones();
};

struct NavigationStart {
  ins::NavState nav;  // at the IMU
  Eigen::Vector3d sigma_pos_ned_m, sigma_vel_n_mps, sigma_att_rad;
  fusion::AttitudePerBias attitude_per_bias = fusion::AttitudePerBias::Zero();  // the alignment's (AttitudeStart)
  std::optional<ins::StandstillGyroBias> standstill;                            // the alignment's (AttitudeStart)
};

// The INS start: the alignment's time, attitude and velocity; the position from config.position_deg_m (with
// sigma_configured_position_m) or else from fix (which must then be given) moved by config.lever_arm_b (with
// the fix's sigma); then config.sigma_position_m, sigma_velocity_mps and sigma_attitude_deg replace the sigmas
// (sigma_attitude_deg the whole attitude error: the alignment's bias sensitivity is then dropped).
NavigationStart initialise_navigation(const AttitudeStart& alignment, const GnssPosition* fix, const FuseConfig& config,
                                      const Eigen::Vector3d& sigma_configured_position_m);

// The integration's options for that start: coupling and filter, the IMU preset's error model, the lever arm, the
// start's 1-sigmas, the configuration's gate, UKF parameters and propagation interval. (Tight callers add the
// clock and the GPS time origin; `fuse` the GPS attitude options.) The configuration's initial biases and their
// 1-sigma (an alignment file's) start the bias states when given; else a standstill's gyro biases.
fusion::IntegrationOptions integration_options(const NavigationStart& start, const FuseConfig& config,
                                               fusion::Coupling coupling, fusion::FilterKind filter);

}  // namespace ultratrack::pipelines
