// SPDX-License-Identifier: GPL-3.0-or-later
// The simulation scenario: plain data that says what `simulate` makes (signal, time, navigation data, receiver,
// atmosphere, truth rate, and for inertial scenarios the trajectory, IMU and antennas on the body). SI units and
// degrees at the edges as the names say; relative paths resolve against `source`'s folder. config/scenario_toml.hpp
// reads and writes it as TOML (the keys are the field names there).
//
// Static scenarios: antennas at `llh_deg_m` plus ENU offsets, or a trajectory CSV (signals/receiver_motion.hpp).
// Inertial scenarios (trajectory_enabled()): one trajectory (profile or segment CSV, ins/trajectory.hpp) drives
// the IMU data, the truth and the antennas at body lever arms (x forward, y right, z down, from the IMU); t = 0
// of the trajectory is the [time] start; `signal` false makes IMU and truth only.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "ins/imu_datasheet.hpp"
#include "ins/odometer.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::sim {

struct Scenario {
  std::filesystem::path source;  // the scenario file ("" for a built-in one); relative paths resolve against it

  // Signal: samples at sample_rate_hz (100 kHz..1 GHz), IF if_hz (|if| < fs/2, > 0 for real formats).
  double sample_rate_hz = 2.6e6;
  double if_hz = 0.0;
  signals::SampleFormat format = signals::SampleFormat::i8;
  signals::TwoBitLayout two_bit;  // r2/i2 only
  double duration_s = 60.0;       // (0, 86400]
  double cn0_dbhz = 45.0;         // every satellite unless cn0_dbhz_by_prn names it; 0..80
  std::uint64_t seed = 1;
  std::map<int, double> cn0_dbhz_by_prn;
  bool nav_data = true;
  bool noise = true;
  // Another generator's conventions (signals/if_synthesiser.hpp): exact parameters every parameter_update_s
  // (1 ms ours, 0.1 s as gps-sdr-sim) with the rates held in between.
  double parameter_update_s = 1e-3;

  // True GPS time of the first sample (full weeks).
  int gps_week = 2190;
  double tow_s = 518400.0;

  // Navigation data: a RINEX nav file, or the built-in constellation when `rinex` is empty.
  std::string rinex;
  std::string constellation = "nominal";
  double elevation_mask_deg = 5.0;
  bool include_unhealthy = false;
  // How the LNAV message is made (signals/lnav_transmitter.hpp): ephemeris fields rounded to nearest or toward
  // zero; subframe 4/5 pages with almanacs or with random content no nav file predicts.
  signals::FieldRounding nav_field_rounding = signals::FieldRounding::kNearest;
  bool nav_random_pages = false;

  // Receiver: a static position (with optional extra antennas, one file each) or a trajectory CSV.
  std::array<double, 3> llh_deg_m = {35.274016, 137.013759, 100.0};
  std::string trajectory;
  std::vector<std::array<double, 3>> antenna_offsets_enu_m = {{0.0, 0.0, 0.0}};
  double clock_bias_m = 0.0;
  double clock_drift_mps = 0.0;
  double clock_bias_noise_m_per_sqrt_s = 0.0;
  double clock_drift_noise_mps_per_sqrt_s = 0.0;

  bool ionosphere = true;
  bool troposphere = false;

  double truth_rate_hz = 10.0;  // (0, 1000]

  // Whether IF samples are synthesised (an inertial scenario may make IMU and truth only).
  bool signal = true;

  // Inertial: exactly one of trajectory_profile / trajectory_file (trajectory_enabled()).
  std::string trajectory_profile;
  std::string trajectory_file;
  double trajectory_duration_s = 0.0;  // profiles only
  double imu_rate_hz = 100.0;          // 50..1000
  double start_speed_mps = 0.0;        // segment files only
  double start_heading_deg = 0.0;      // segment files only
  bool coordinated_turns = false;      // segment files only: bank into turns (aircraft)
  double ramp_s = 1.0;                 // segment files only: command blend time at segment starts
  bool odometer = false;
  double odometer_scale_factor_error = 0.0;
  double odometer_delay_s = 0.0;                  // pulses lag the motion (ins/odometer.hpp)
  double odometer_misalignment_pitch_deg = 0.0;   // IMU mounting relative to the vehicle: the IMU data and the
  double odometer_misalignment_yaw_deg = 0.0;     // truth attitude are the trajectory's rotated by C_bv
  std::vector<ins::OdometerSlip> odometer_slips;  // [[odometer_slip]]
  // [[vibration]] (with [trajectory]): tones the whole platform carries, IMU and antennas (ins::Vibration).
  std::vector<ins::Vibration> vibrations;
  double sideslip_deg_per_mps2 = 0.0;  // the vehicle yaws from its track by this times the lateral acceleration

  // IMU errors: a preset (ins/imu_error_model.hpp) with optional datasheet overrides.
  std::string imu_preset = "ideal";
  std::uint64_t imu_seed = 1;
  double imu_time_offset_s = 0.0;   // the IMU's time stamps read true time + this (a mis-synchronised IMU)
  ins::ImuDatasheet imu_datasheet;  // the [imu] datasheet keys given (ins/imu_datasheet.hpp)

  // Antennas on the body (inertial scenarios; the first is the master) and the parked attitude (static profile).
  std::vector<std::array<double, 3>> lever_arms_body_m = {{0.0, 0.0, 0.0}};
  std::array<double, 3> attitude_deg = {0.0, 0.0, 0.0};
  // Impairments and events of the synthesiser (signals/if_synthesiser.hpp); they need the signal.
  std::vector<signals::AntennaImpairment> antenna_impairments;
  std::vector<signals::CycleSlipEvent> cycle_slips;
  std::vector<signals::BlockageEvent> blockages;
  std::vector<signals::Cn0StepEvent> cn0_steps;

  bool trajectory_enabled() const { return !trajectory_profile.empty() || !trajectory_file.empty(); }
  // Antennas simulated: lever arms (inertial) or static offsets.
  std::size_t antenna_count() const {
    return trajectory_enabled() ? lever_arms_body_m.size() : antenna_offsets_enu_m.size();
  }

  // What can be checked without reading a file (ranges and keys that need each other). False with the first
  // problem in *why ("key <section>.<name>: ..."); files (RINEX, trajectory, segments) are checked when read.
  bool IsValid(std::string* why) const;
};

// A path from the scenario, resolved against the scenario file's folder when relative.
std::filesystem::path resolve_path(const Scenario& scenario, const std::string& path);

}  // namespace ultratrack::sim
