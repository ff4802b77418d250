// SPDX-License-Identifier: GPL-3.0-or-later
// Scenario files: sim::Scenario as TOML, parsed strictly with toml++: every key known and of the right type, or
// an io::InputError naming the file, the line and the key. Units as in the key names; relative paths resolve
// against the scenario's folder (sim::resolve_path).
//
//   [signal]      sample_rate_hz = 2.6e6  if_hz = 0.0  format = "i8"  duration_s = 60.0  cn0_dbhz = 45.0
//                 seed = 1  cn0_dbhz_by_prn = { 5 = 40.0 }  nav_data = true  noise = true
//                 two_bit_coding = "twos"  two_bit_order = "lsb-first"   (r2/i2 packing, signals/sample_format.hpp)
//   [time]        gps_week = 2190  tow_s = 518400.0            (true GPS time of the first sample)
//   [navigation]  rinex = "brdc0010.22n"  or  constellation = "nominal"
//                 elevation_mask_deg = 5.0  include_unhealthy = false
//   [receiver]    llh_deg_m = [35.274016, 137.013759, 100.0]  or  trajectory = "motion.csv"
//                 antenna_offsets_enu_m = [[0, 0, 0], [1.0, 0, 0]]   (static receiver: one file per antenna)
//                 clock_bias_m = 0.0  clock_drift_mps = 0.0
//                 clock_bias_noise_m_per_sqrt_s = 0.0  clock_drift_noise_mps_per_sqrt_s = 0.0
//                 or  oscillator = "ideal" | "tcxo" | "ocxo"   (both random walks from the Allan coefficients
//                 as a signal sees them, signals/oscillator_allan.hpp; the written scenario carries the values)
//   [atmosphere]  ionosphere = true  troposphere = false
//   Another generator's conventions (signals/if_synthesiser.hpp, lnav_transmitter.hpp), all off by default:
//   [signal] parameter_update_s = 0.001 (0.1: exact parameters every 0.1 s, rates held between)
//   [navigation] field_rounding = "nearest" | "toward_zero"   pages = "almanac" | "random"
//   [imu] time_offset_s = 0.0 (the IMU's stamps read true time + this, within +-0.1 s)
//   [output]      truth_rate_hz = 10.0
//
// Inertial scenarios (one trajectory drives the IMU data, the truth and the IF synthesiser's antennas):
//   [trajectory]  profile = "circle"  (static, straight, circle, s, spiral, land)  or  file = "segments.csv"
//                 (ins/trajectory.hpp's segment CSV, relative to the scenario; then speed_mps = 0.0 and
//                 heading_deg = 0.0 give the start state and the file sets the duration; coordinated_turns =
//                 false banks into turns like an aircraft, ramp_s = 1.0 is the command blend time: a quintic
//                 blend, so the peak jerk of a step da in acceleration is 15/8 da / ramp_s)
//                 duration_s = 120.0 (profiles; must cover [signal] duration_s)  imu_rate_hz = 100.0 (50..1000)
//                 odometer = false  odometer_scale_factor_error = 0.0   (odometer.csv; the land profile's use)
//                 odometer_delay_s = 0.0 (0..1)  odometer_misalignment_pitch_deg = 0.0  odometer_misalignment_yaw_deg
//                 = 0.0 (+-10: the IMU mounted rotated from the vehicle, C_bv = Rz(yaw) Ry(pitch); the IMU data and
//                 truth attitude are then the IMU's, the trajectory the vehicle's; ins/odometer.hpp)
//                 sideslip_deg_per_mps2 = 0.0 (+-2: a land vehicle's body yaws from its track by this times the
//                 lateral acceleration, breaking the non-holonomic constraints in turns as real tyres do)
//   [[odometer_slip]] start_s = 100.0  duration_s = 2.0  ratio = -1.0   (wheel slip / skid: pulses scaled by
//                 1 + ratio over the event; -1 a locked wheel, > 0 a spinning one)
//   [[vibration]] frequency_hz = 12.0 (0..500)  accel_amplitude_mps2 = [n, e, d] (peak, +-100)  angle_amplitude_deg
//                 = [roll, pitch, yaw] (peak, +-10)  phase_deg = 0.0   (a tone the whole platform carries, IMU and
//                 antennas: ins::Vibration; at least one amplitude not zero; needs [trajectory])
//                 The start position is [receiver] llh_deg_m; t = 0 of the trajectory is the [time] start.
//   [imu]         preset = "ideal" (ideal, hg1700ae, dmu6x, navigation, mems, adis16405, adis16465, bmi088,
//                 stim300)  seed = 1
//                 datasheet overrides of the preset's 1-sigma values (only when given; ins/imu_datasheet.hpp):
//                 gyro_bias_dph, accel_bias_mg (turn-on), gyro_bias_instability_dph, accel_bias_instability_mg,
//                 bias_correlation_time_s (in-run, Gauss-Markov), gyro_arw_dpsh (deg/sqrt(h)), accel_vrw_mpspsh
//                 (m/s/sqrt(h)), gyro_scale_factor_ppm, accel_scale_factor_ppm
//   [[antenna]]   lever_arm_body_m = [x, y, z]   one table per antenna, body axes (x forward, y right,
//                 z down) from the IMU; the first is the master (antenna0); default one antenna at the IMU
//   [receiver]    attitude_deg = [roll, pitch, yaw]   with profile = "static": the parked body's attitude
//                 line_bias_cycles = 0.0  phase_noise_m = 0.0   (optional, per antenna: carrier line bias, RINEX
//                 sense, and extra carrier phase noise, 1 sigma; signals/if_synthesiser.hpp AntennaImpairment)
//   [[cycle_slip]] antenna = 1  prn = 5  time_s = 20.0  cycles = 3.0  fade_s = 0.1   (receiver time since the
//                 first sample; the signal fades for fade_s, then comes back stepped by `cycles`)
//   [[blockage]]  antenna = 2  start_s = 40.0  duration_s = 5.0   (every satellite absent at that antenna)
//                 Both need [signal]; `simulate` writes them to antenna_events.csv (the detection truth).
//   [[cn0_step]]  antenna = 0  start_s = 15.0  cn0_dbhz = 25.0  prns = [3, 7]   (antenna and prns optional: 0
//                 and every satellite; from the first sample at or after start_s the satellites arrive at that
//                 C/N0, sample-exact, until a later step; needs [signal]; `simulate` writes cn0_steps.csv)
// With [trajectory], [receiver] takes neither trajectory nor antenna_offsets_enu_m, and [signal] is optional:
// without it only the IMU and truth files are written. [[antenna]] and attitude_deg need [trajectory].
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "config/toml_override.hpp"
#include "sim/scenario.hpp"

namespace ultratrack::config {

// Parses scenario text; `source` names it in errors and anchors relative paths. `overrides` change keys before
// the scenario is read (config/toml_override.hpp; a bad one is an InputError naming it). Throws InputError.
sim::Scenario parse_scenario(std::string_view text, const std::filesystem::path& source,
                             const std::vector<TomlOverride>& overrides = {});
// Reads and parses a scenario file. Throws InputError (missing file, syntax, unknown key, wrong type, range).
sim::Scenario read_scenario(const std::filesystem::path& path, const std::vector<TomlOverride>& overrides = {});

// The scenario as TOML with every key written (defaults filled in, paths made absolute): reading it back
// gives the same scenario.
std::string to_toml(const sim::Scenario& scenario);

}  // namespace ultratrack::config
