// SPDX-License-Identifier: GPL-3.0-or-later
// The datasheet description of an IMU: units against closed forms, overrides over a preset, and the round trip
// datasheet -> spec -> datasheet.
#include "ins/imu_datasheet.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace ultratrack::ins {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(ImuDatasheet, UnitsAreTheDatasheetsOnes) {
  ImuDatasheet d;
  d.gyro_bias_dph = 3600.0;            // 1 deg/s
  d.accel_bias_mg = 1000.0;            // 1 g
  d.gyro_bias_instability_dph = 36.0;  // 0.01 deg/s
  d.accel_bias_instability_mg = 0.5;
  d.bias_correlation_time_s = 250.0;
  d.gyro_arw_dpsh = 60.0;    // 1 deg/sqrt(s)
  d.accel_vrw_mpspsh = 0.6;  // 0.01 m/s/sqrt(s)
  d.gyro_scale_factor_ppm = 500.0;
  d.accel_scale_factor_ppm = 300.0;
  const ImuErrorSpec s = apply_datasheet(ImuErrorSpec{}, d);
  EXPECT_NEAR(s.gyro.bias_sigma, 1.0 * kDeg, 1e-15);
  EXPECT_NEAR(s.accel.bias_sigma, 9.80665, 1e-12);
  EXPECT_NEAR(s.gyro.bias_instability_sigma, 0.01 * kDeg, 1e-15);
  EXPECT_NEAR(s.accel.bias_instability_sigma, 0.5e-3 * 9.80665, 1e-15);
  EXPECT_EQ(s.gyro.bias_correlation_time_s, 250.0);
  EXPECT_EQ(s.accel.bias_correlation_time_s, 250.0);
  EXPECT_NEAR(s.gyro.random_walk, 1.0 * kDeg, 1e-15);
  EXPECT_NEAR(s.accel.random_walk, 0.01, 1e-15);
  EXPECT_NEAR(s.gyro.scale_factor_sigma, 5e-4, 1e-18);
  EXPECT_NEAR(s.accel.scale_factor_sigma, 3e-4, 1e-18);
}

TEST(ImuDatasheet, OnlyGivenValuesReplaceThePreset) {
  const ImuErrorSpec preset = imu_preset("mems");
  ImuDatasheet d;
  d.gyro_arw_dpsh = 2.0;
  const ImuErrorSpec s = apply_datasheet(preset, d);
  EXPECT_NEAR(s.gyro.random_walk, 2.0 * kDeg / 60.0, 1e-15);
  EXPECT_EQ(s.gyro.bias_sigma, preset.gyro.bias_sigma);
  EXPECT_EQ(s.accel.random_walk, preset.accel.random_walk);
  EXPECT_EQ(s.accel.scale_factor_sigma, preset.accel.scale_factor_sigma);
}

TEST(ImuDatasheet, RoundTripsThroughTheSpec) {
  for (const auto& name : imu_preset_names()) {
    const ImuErrorSpec preset = imu_preset(name);
    const ImuErrorSpec again = apply_datasheet(ImuErrorSpec{}, datasheet_of(preset));
    EXPECT_NEAR(again.gyro.bias_sigma, preset.gyro.bias_sigma, 1e-15) << name;
    EXPECT_NEAR(again.accel.bias_instability_sigma, preset.accel.bias_instability_sigma, 1e-15) << name;
    EXPECT_NEAR(again.gyro.random_walk, preset.gyro.random_walk, 1e-15) << name;
    EXPECT_NEAR(again.accel.random_walk, preset.accel.random_walk, 1e-15) << name;
  }
}

TEST(ImuDatasheet, Adis16405PresetIsItsDatasheet) {
  // ADIS16405 datasheet: initial gyro bias 3 deg/s, in-run 0.007 deg/s, ARW 2 deg/sqrt(h); accelerometer 50 mg
  // initial, 0.2 mg in run, VRW 0.2 m/s/sqrt(h).
  const ImuDatasheet d = datasheet_of(imu_preset("adis16405"));
  EXPECT_NEAR(*d.gyro_bias_dph, 3.0 * 3600.0, 1e-9);
  EXPECT_NEAR(*d.gyro_bias_instability_dph, 0.007 * 3600.0, 1e-9);
  EXPECT_NEAR(*d.gyro_arw_dpsh, 2.0, 1e-12);
  EXPECT_NEAR(*d.accel_bias_mg, 50.0, 1e-12);
  EXPECT_NEAR(*d.accel_bias_instability_mg, 0.2, 1e-12);
  EXPECT_NEAR(*d.accel_vrw_mpspsh, 0.2, 1e-12);
}

TEST(ImuDatasheet, RefusesNegativeAndAbsurdValues) {
  for (const auto& key : imu_datasheet_keys()) {
    EXPECT_FALSE(datasheet_value_problem(key, -1.0).empty()) << key.name;
    EXPECT_FALSE(datasheet_value_problem(key, key.max * 2.0).empty()) << key.name;
    EXPECT_TRUE(datasheet_value_problem(key, key.max / 2.0).empty()) << key.name;
  }
  const auto tau = std::find_if(imu_datasheet_keys().begin(), imu_datasheet_keys().end(),
                                [](const auto& k) { return k.name == "bias_correlation_time_s"; });
  ASSERT_NE(tau, imu_datasheet_keys().end());
  EXPECT_FALSE(datasheet_value_problem(*tau, 0.0).empty());
}

}  // namespace
}  // namespace ultratrack::ins
