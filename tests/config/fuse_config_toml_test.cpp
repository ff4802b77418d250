// SPDX-License-Identifier: GPL-3.0-or-later
// The fuse configuration's datasheet IMU keys, lock-out recovery, land-vehicle and GNSS error keys: values reach the
// FuseConfig, the filter's model is the preset with them put in, and bad values name the file, line and key.
#include "config/fuse_config_toml.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <numbers>

#include "io/input_error.hpp"
#include "support/test_data.hpp"

namespace ultratrack::config {
namespace {

std::filesystem::path write(const std::string& name, const std::string& text) {
  const auto p = test::scratch_dir() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(FuseConfigToml, DatasheetKeysOverThePreset) {
  const auto p = write("datasheet.toml",
                       "[imu]\npreset = \"mems\"\ngyro_bias_dph = 10800\naccel_vrw_mpspsh = 0.2\n"
                       "bias_correlation_time_s = 100\nmax_gap_s = 0.2\n");
  const FuseConfig c = read_fuse_config(p);
  EXPECT_EQ(c.imu_preset, "mems");
  ASSERT_TRUE(c.imu_datasheet.gyro_bias_dph);
  EXPECT_EQ(*c.imu_datasheet.gyro_bias_dph, 10800.0);
  EXPECT_FALSE(c.imu_datasheet.accel_bias_mg);
  EXPECT_EQ(c.imu_max_gap_s, 0.2);
  const ins::ImuErrorSpec spec = pipelines::imu_error_spec(c);
  EXPECT_NEAR(spec.gyro.bias_sigma, 3.0 * std::numbers::pi / 180.0, 1e-12);  // 3 deg/s
  EXPECT_NEAR(spec.accel.random_walk, 0.2 / 60.0, 1e-15);
  EXPECT_EQ(spec.accel.bias_sigma, ins::imu_preset("mems").accel.bias_sigma);  // not given: the preset's
}

TEST(FuseConfigToml, RecoveryAndVehicleKeys) {
  const auto p = write("vehicle.toml",
                       "[filter]\nrecovery = false\nrecovery_rejections = 8\nrecovery_span_s = 4\n"
                       "recovery_nis_window = 0\n[vehicle]\nnhc = true\nnhc_sigma_mps = 0.5\nnhc_interval_s = 1\n"
                       "nhc_lever_arm_body_m = [-1.5, 0, 0.5]\n");
  const FuseConfig c = read_fuse_config(p);
  EXPECT_FALSE(c.recovery.enabled);
  EXPECT_EQ(c.recovery.consecutive_rejections, 8);
  EXPECT_EQ(c.recovery.min_span_s, 4.0);
  EXPECT_EQ(c.recovery.nis_window, 0);
  EXPECT_TRUE(c.land.nhc);
  EXPECT_EQ(c.land.nhc_sigma_mps, 0.5);
  EXPECT_EQ(c.land.nhc_interval_s, 1.0);
  EXPECT_EQ(c.land.lever_arm_b, Eigen::Vector3d(-1.5, 0.0, 0.5));
}

TEST(FuseConfigToml, OdometerKeys) {
  const auto p =
      write("odometer.toml",
            "[odometer]\nmode = \"always\"\nyaw_rate_threshold_dps = 1.25\nmin_speed_mps = 4\n"
            "update_rate_hz = 2\nrate_hz = 10\nlever_arm_body_m = [-1.2, 0, 0.6]\nsigma_scale_factor = 0.02\n"
            "sigma_misalignment_deg = 2\nsigma_delay_s = 0.1\nsigma_forward_mps = 0.08\n");
  const FuseConfig c = read_fuse_config(p);
  EXPECT_EQ(c.odometer.mode, fusion::OdometerMode::kAlways);
  EXPECT_NEAR(c.odometer.yaw_rate_threshold_rad_s, 1.25 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_EQ(c.odometer.min_speed_mps, 4.0);
  EXPECT_EQ(c.odometer.update_rate_hz, 2.0);
  ASSERT_TRUE(c.odometer_rate_hz);
  EXPECT_EQ(*c.odometer_rate_hz, 10.0);
  EXPECT_EQ(c.odometer.lever_arm_b, Eigen::Vector3d(-1.2, 0.0, 0.6));
  EXPECT_EQ(c.odometer.sigma_scale_factor, 0.02);
  EXPECT_NEAR(c.odometer.sigma_misalignment_rad, 2.0 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_EQ(c.odometer.sigma_delay_s, 0.1);
  EXPECT_EQ(c.odometer.sigma_forward_mps, 0.08);
  EXPECT_FALSE(c.odometer.enabled);  // fuse --odometer turns it on
}

TEST(FuseConfigToml, GnssErrorKeys) {
  const auto p = write("gnss.toml", "[gnss]\nerror_correlation_time_s = 30\nerror_sigma_ned_m = [1, 1.5, 2]\n");
  const FuseConfig c = read_fuse_config(p);
  EXPECT_EQ(c.fix_error_correlation_s, 30.0);
  ASSERT_TRUE(c.fix_error_sigma_ned_m);
  EXPECT_EQ(*c.fix_error_sigma_ned_m, Eigen::Vector3d(1.0, 1.5, 2.0));
  EXPECT_FALSE(read_fuse_config(write("gnss0.toml", "[gnss]\nerror_correlation_time_s = 30\n")).fix_error_sigma_ned_m);
  // A number decides; absent or "auto", fuse measures the fixes (fusion/fix_error_whiteness.hpp).
  EXPECT_FALSE(c.fix_error_auto);
  EXPECT_FALSE(read_fuse_config(write("gnss1.toml", "[gnss]\nerror_correlation_time_s = 0\n")).fix_error_auto);
  EXPECT_TRUE(read_fuse_config(write("gnss2.toml", "[gnss]\nvelocity_sigma_mps = 0.1\n")).fix_error_auto);
  const FuseConfig a = read_fuse_config(write("gnss3.toml", "[gnss]\nerror_correlation_time_s = \"auto\"\n"));
  EXPECT_TRUE(a.fix_error_auto);
  EXPECT_EQ(a.fix_error_correlation_s, 0.0);
}

TEST(FuseConfigToml, BadValuesNameFileLineAndKey) {
  struct Case {
    std::string text, what;
    int line;
  };
  const std::vector<Case> cases{
      {"[imu]\n\ngyro_bias_dph = -3\n", "imu.gyro_bias_dph", 3},
      {"[imu]\nbias_correlation_time_s = 0\n", "imu.bias_correlation_time_s", 2},
      {"[imu]\ngyro_arw_dpsh = \"2\"\n", "must be a number", 2},
      {"[imu]\npreset = \"adis99\"\n", "unknown preset 'adis99'", 2},
      {"[gnss]\n\nerror_correlation_time_s = \"measured\"\n", "number of seconds or \"auto\"", 3},
      {"[imu]\ngyro_bias_dps = 3\n", "unknown key 'imu.gyro_bias_dps'", 2},
      {"[filter]\nrecovery_rejections = 0\n", "at least 1", 2},
      {"[filter]\nrecovery_rejections = 2.5\n", "must be an integer", 2},
      {"[vehicle]\nnhc_sigma_mps = 0\n", "must be positive", 2},
      {"[vehicle]\nnhc = 1\n", "true or false", 2},
      {"[odometer]\nmode = \"sometimes\"\n", "odometer.mode", 2},
      {"[odometer]\nyaw_rate_threshold_dps = -1\n", "odometer.yaw_rate_threshold_dps", 2},
      {"[odometer]\n\nupdate_rate_hz = 0\n", "odometer.update_rate_hz", 3},
      {"[odometer]\nlever_arm_body_m = [1, 2]\n", "odometer.lever_arm_body_m", 2},
      {"[odometer]\nyaw_rate_dps = 1\n", "unknown key 'odometer.yaw_rate_dps'", 2},
      {"[gnss]\nerror_sigma_ned_m = [1, 0, 2]\n", "gnss.error_sigma_ned_m", 2},
  };
  for (const auto& c : cases) {
    const auto p = write("bad.toml", c.text);
    try {
      read_fuse_config(p);
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const io::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_EQ(e.line(), c.line) << e.what();
    }
  }
}

}  // namespace
}  // namespace ultratrack::config
