// SPDX-License-Identifier: GPL-3.0-or-later
// An IMU described the way its datasheet describes it: turn-on biases, in-run bias instability with a correlation
// time, angle and velocity random walks, scale-factor errors, each optional over a named preset. One block (the
// `[imu]` keys of a scenario, of `fuse --config` and of `receive --fusion-config`) then describes a sensor to the
// simulator and to the filter alike. Units are the datasheets': deg/h, milli-g (of 9.80665 m/s^2), deg/sqrt(h),
// m/s/sqrt(h), ppm, s; all values 1-sigma per axis. The in-run instability is modelled as a first-order
// Gauss-Markov process with that steady-state sigma (datasheets quote the Allan-deviation floor, which a GM
// process of this sigma and correlation time approximates near tau).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "ins/imu_error_model.hpp"

namespace ultratrack::ins {

struct ImuDatasheet {
  std::optional<double> gyro_bias_dph, accel_bias_mg;                          // turn-on (run-to-run) bias
  std::optional<double> gyro_bias_instability_dph, accel_bias_instability_mg;  // in-run, Gauss-Markov sigma
  std::optional<double> bias_correlation_time_s;                               // of both in-run processes
  std::optional<double> gyro_arw_dpsh, accel_vrw_mpspsh;                       // white rate / acceleration noise
  std::optional<double> gyro_scale_factor_ppm, accel_scale_factor_ppm;
};

// One datasheet key: its name (the TOML key), the member it sets, its unit, and the largest value accepted (a
// guard against unit mistakes: 1e5 deg/h is 28 deg/s). Values must be >= 0, the correlation time > 0.
struct ImuDatasheetKey {
  std::string_view name;
  std::optional<double> ImuDatasheet::*member;
  std::string_view unit;
  double max;
  bool strictly_positive;
};
std::span<const ImuDatasheetKey> imu_datasheet_keys();

// Why the value is refused for that key (empty: accepted).
std::string datasheet_value_problem(const ImuDatasheetKey& key, double value);

// The preset with the datasheet's values put in where given.
ImuErrorSpec apply_datasheet(ImuErrorSpec preset, const ImuDatasheet& datasheet);
// Every datasheet value of a spec (all members set): what a filter or a simulation actually used.
ImuDatasheet datasheet_of(const ImuErrorSpec& spec);

}  // namespace ultratrack::ins
