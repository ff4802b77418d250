// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/imu_datasheet.hpp"

#include <fmt/core.h>

#include <array>

#include "io/units.hpp"

namespace ultratrack::ins {
namespace {

constexpr double kDph = io::kRadPerSecPerDegPerHour;  // deg/h -> rad/s
constexpr double kDpsh = io::kRadPerDeg / 60.0;       // deg/sqrt(h) -> rad/sqrt(s)
constexpr double kMpspsh = 1.0 / 60.0;                // m/s/sqrt(h) -> m/s/sqrt(s)
constexpr double kMg = 9.80665e-3;                    // milli-g -> m/s^2
constexpr double kPpm = 1e-6;

}  // namespace

std::span<const ImuDatasheetKey> imu_datasheet_keys() {
  using D = ImuDatasheet;
  static const std::array<ImuDatasheetKey, 9> keys{{
      {"gyro_bias_dph", &D::gyro_bias_dph, "deg/h", 1e5, false},
      {"accel_bias_mg", &D::accel_bias_mg, "mg", 1e3, false},
      {"gyro_bias_instability_dph", &D::gyro_bias_instability_dph, "deg/h", 1e5, false},
      {"accel_bias_instability_mg", &D::accel_bias_instability_mg, "mg", 1e3, false},
      {"bias_correlation_time_s", &D::bias_correlation_time_s, "s", 1e7, true},
      {"gyro_arw_dpsh", &D::gyro_arw_dpsh, "deg/sqrt(h)", 1e3, false},
      {"accel_vrw_mpspsh", &D::accel_vrw_mpspsh, "m/s/sqrt(h)", 1e3, false},
      {"gyro_scale_factor_ppm", &D::gyro_scale_factor_ppm, "ppm", 1e5, false},
      {"accel_scale_factor_ppm", &D::accel_scale_factor_ppm, "ppm", 1e5, false},
  }};
  return keys;
}

std::string datasheet_value_problem(const ImuDatasheetKey& key, double value) {
  if (key.strictly_positive ? !(value > 0.0 && value <= key.max) : !(value >= 0.0 && value <= key.max))
    return fmt::format("must be within {}..{} {}", key.strictly_positive ? "(0" : "0", key.max, key.unit);
  return {};
}

ImuErrorSpec apply_datasheet(ImuErrorSpec s, const ImuDatasheet& d) {
  if (d.gyro_bias_dph) s.gyro.bias_sigma = *d.gyro_bias_dph * kDph;
  if (d.accel_bias_mg) s.accel.bias_sigma = *d.accel_bias_mg * kMg;
  if (d.gyro_bias_instability_dph) s.gyro.bias_instability_sigma = *d.gyro_bias_instability_dph * kDph;
  if (d.accel_bias_instability_mg) s.accel.bias_instability_sigma = *d.accel_bias_instability_mg * kMg;
  if (d.bias_correlation_time_s) {
    s.gyro.bias_correlation_time_s = *d.bias_correlation_time_s;
    s.accel.bias_correlation_time_s = *d.bias_correlation_time_s;
  }
  if (d.gyro_arw_dpsh) s.gyro.random_walk = *d.gyro_arw_dpsh * kDpsh;
  if (d.accel_vrw_mpspsh) s.accel.random_walk = *d.accel_vrw_mpspsh * kMpspsh;
  if (d.gyro_scale_factor_ppm) s.gyro.scale_factor_sigma = *d.gyro_scale_factor_ppm * kPpm;
  if (d.accel_scale_factor_ppm) s.accel.scale_factor_sigma = *d.accel_scale_factor_ppm * kPpm;
  return s;
}

ImuDatasheet datasheet_of(const ImuErrorSpec& s) {
  ImuDatasheet d;
  d.gyro_bias_dph = s.gyro.bias_sigma / kDph;
  d.accel_bias_mg = s.accel.bias_sigma / kMg;
  d.gyro_bias_instability_dph = s.gyro.bias_instability_sigma / kDph;
  d.accel_bias_instability_mg = s.accel.bias_instability_sigma / kMg;
  d.bias_correlation_time_s = s.gyro.bias_correlation_time_s;  // the presets use one time for both
  d.gyro_arw_dpsh = s.gyro.random_walk / kDpsh;
  d.accel_vrw_mpspsh = s.accel.random_walk / kMpspsh;
  d.gyro_scale_factor_ppm = s.gyro.scale_factor_sigma / kPpm;
  d.accel_scale_factor_ppm = s.accel.scale_factor_sigma / kPpm;
  return d;
}

}  // namespace ultratrack::ins
