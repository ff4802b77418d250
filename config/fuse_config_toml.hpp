// SPDX-License-Identifier: GPL-3.0-or-later
// The `fuse` command's TOML configuration (--config). Sections and keys (all optional):
//   [imu]        preset = "hg1700ae" (the filter's noise model: fusion::error_model_from_preset;
//   ins/imu_error_model.hpp
//                names the presets) and datasheet values over it, each optional, the scenario's names
//                (ins/imu_datasheet.hpp): gyro_bias_dph, accel_bias_mg, gyro_bias_instability_dph,
//                accel_bias_instability_mg, bias_correlation_time_s, gyro_arw_dpsh, accel_vrw_mpspsh,
//                gyro_scale_factor_ppm, accel_scale_factor_ppm; max_gap_s = 1 (a longer gap between IMU rows is
//                an input error)
//   [initial]    attitude_deg = [roll, pitch, yaw] (needed by --align config), position_deg_m = [lat, lon, h]
//                (else the first GNSS fix), velocity_ned_mps = [n, e, d] (else the GNSS velocity), sigma_position_m,
//                sigma_velocity_mps, sigma_attitude_deg = [n, e, d]
//   [alignment]  static_duration_s = 60, motion_min_speed_mps = 5, motion_window_s = 2, motion_heading_sigma_deg = 5
//                (position-only fixes: the track span grows until the heading 1-sigma is at most this),
//                standstill_gyro_bias = true (gyro biases from a standstill at the start, motion alignment)
//   [gnss]       velocity_sigma_mps = 0.1, use_velocity = true, lever_arm_body_m = [x, y, z], update_interval_s = 0
//                (fixes closer than this to the last one used are skipped: a decorrelating interval for fixes whose
//                errors are correlated in time; 0: every fix), error_correlation_time_s = "auto" (fuse: measured
//                from the fixes, fusion/fix_error_whiteness.hpp; receive: white) or seconds (the fixes' position
//                errors first-order Gauss-Markov with this time: their variance is inflated by 1 + 2 tau / dt; 0:
//                white), error_sigma_ned_m = [n, e, d] (with a correlation time, loose: the Gauss-Markov part's
//                1-sigma, carried as three filter states instead of the inflation; fusion/fix_error_model.hpp)
//   [vehicle]    nhc = false (land vehicles: zero lateral and vertical body velocity, fusion/nhc_measurement.hpp),
//                nhc_sigma_mps = 0.3, nhc_interval_s = 0.5, nhc_lever_arm_body_m = [x, y, z] (IMU -> rear axle)
//   [odometer]   (fuse --odometer; [KimVMS], fusion/vms_measurement.hpp) mode = "gated"|"always" (gated: update only
//                while |heading change| per second < yaw_rate_threshold_dps = 1.5 and the VMS speed > min_speed_mps
//                = 5; always: every window), update_rate_hz = 1, rate_hz (the odometer file's declared rate; else
//                its first interval), lever_arm_body_m = [x, y, z] (IMU -> wheels' non-holonomic point),
//                sigma_scale_factor = 0.01, sigma_misalignment_deg = 0.5, sigma_delay_s = 0.05 (initial 1-sigmas),
//                scale_factor_psd = 1e-12 (random walk, 1/s), sigma_forward_mps = 0.05, sigma_lateral_mps = 0.1,
//                sigma_vertical_mps = 0.1 (measurement 1-sigmas)
//   [clock]      (tight) oscillator = "tcxo"|"ocxo" (fusion/clock_model presets; default tcxo), h0, h_minus2
//                (override the preset's Allan coefficients)
//   [height_aiding] (tight) mode = "off"|"auto" (default off: aircraft; auto: land vehicles, a terrain-height
//                state and a height aid in epochs with < 4 satellites, fusion/height_aiding.hpp), sigma_m = 2
//                (white part of each aid), terrain_sigma_m = 10 and terrain_correlation_s = 100 (Gauss-Markov
//                terrain about the reference height), height_m (a fixed IMU ellipsoidal reference height instead of
//                the one held from the last epoch with >= 4 satellites), interval_s = 1 (at most one aid per interval)
//   [filter]     ukf_alpha = 1, ukf_beta = 2, ukf_kappa = 0, gate = true, gate_probability = 0.9999,
//                propagation_interval_s = 0.05, recovery = true (no gate lock-out: fusion/lockout_recovery.hpp),
//                recovery_rejections = 5 and recovery_span_s = 2 (a run of rejected fixes / all-rejected epochs at
//                least this long re-opens the filter), recovery_nis_window = 20 (windowed NIS test; 0: off)
//   [output]     convergence_heading_sigma_deg = 1
//   [attitude]   (GPS attitude, --attitude) gps_time_at_imu_zero = [week, tow_s] (GPS time of IMU t_s = 0; the
//                attitude file is tagged in GPS time), misalignment_deg = [roll, pitch, yaw] (antenna array ->
//                IMU body, default 0), max_pitch_deg = 80 (beyond: refused, Euler sigmas degenerate)
// Unknown sections or keys and wrong value types are InputErrors naming the file and line.
#pragma once

#include <filesystem>

#include "pipelines/fuse_config.hpp"

namespace ultratrack::config {

using pipelines::FuseConfig;  // the plain struct (pipelines/fuse_config.hpp); this file reads it from TOML

// Reads the file over the defaults; throws io::InputError.
FuseConfig read_fuse_config(const std::filesystem::path& path);

}  // namespace ultratrack::config
