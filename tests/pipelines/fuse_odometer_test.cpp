// SPDX-License-Identifier: GPL-3.0-or-later
// Odometer (VMS) aiding through the library ([KimVMS]): a 6-minute simulated drive (turns, a slope, a lane
// change, a stop, a locked-wheel skid) whose odometer has every error the 19-state filter models; GNSS only for the
// first 90 s. Checked against the simulator's truth: the estimated scale factor, misalignment and delay within
// 3 sigma of the simulated ones, the horizontal error below [KimVMS]'s best Table 1 figure (0.16 % of the distance
// travelled), both gating rules active, the skid refused; and the same drive without the odometer drifts further.
#include <gtest/gtest.h>

#include <fstream>
#include <numbers>

#include "config/fuse_config_toml.hpp"
#include "config/scenario_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/odometer_csv.hpp"
#include "pipelines/fuse.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "sim/simulation_files.hpp"
#include "sim/truth_csv.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Drive {
  std::vector<ins::ImuIncrement> imu;
  std::vector<ins::TruthSample> truth;
  std::vector<GnssFixRow> gnss;
  std::vector<ins::OdometerSample> odometer;
};

const Drive& drive() {
  static const Drive d = [] {
    const auto dir = test::scratch_dir();
    std::ofstream(dir / "segments.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                           "60,0,0,0,0\n15,1,0,0,0\n30,0,0,0,0\n12,0,-7.5,0,0\n40,0,0,0,3\n"
                                           "4,0,3,0,0\n4,0,-3,0,0\n30,0,1.2,0,0\n20,0,0,0,-2\n10,-1.5,0,0,0\n"
                                           "15,0,0,0,0\n10,1.5,0,0,0\n8,0,10,0,0\n60,0,0,0,0\n20,0,-0.8,0,0\n"
                                           "30,0,0,0,0\n";
    std::ofstream(dir / "drive.toml") << "[time]\ngps_week = 1880\ntow_s = 259200.0\n[receiver]\n"
                                         "llh_deg_m = [36.35, 127.38, 60.0]\n[trajectory]\nfile = \"segments.csv\"\n"
                                         "heading_deg = 20.0\nimu_rate_hz = 100.0\nodometer = true\n"
                                         "odometer_scale_factor_error = 0.01\nodometer_delay_s = 0.05\n"
                                         "odometer_misalignment_pitch_deg = 0.4\nodometer_misalignment_yaw_deg = -0.6\n"
                                         "[imu]\npreset = \"navigation\"\nseed = 3\n"
                                         "[[odometer_slip]]\nstart_s = 300.0\nduration_s = 1.0\nratio = -1.0\n";
    const sim::Scenario scenario = config::read_scenario(dir / "drive.toml");
    sim::simulate_to_folder(scenario, dir / "sim", "");
    Drive out;
    out.imu = ins::read_imu_csv(dir / "sim" / "imu.csv");
    out.truth = truth_samples_from_nav(sim::read_truth_csv(dir / "sim" / "truth.csv"));
    out.odometer = ins::read_odometer_csv(dir / "sim" / "odometer.csv", {10.0}).samples;
    GnssFixSimulationOptions fixes;
    fixes.rate_hz = 1.0;
    fixes.sigma_ned_m = Eigen::Vector3d(1.5, 1.5, 3.0);
    fixes.seed = 1;
    out.gnss = simulate_gnss_fixes(ins::TruthInterpolator(out.truth), fixes);
    return out;
  }();
  return d;
}

FuseResult run(bool with_odometer, fusion::OdometerMode mode = fusion::OdometerMode::kGated) {
  FuseSettings s;
  s.config.imu_preset = "navigation";
  s.config.static_duration_s = 50.0;
  s.config.odometer.mode = mode;
  s.config.odometer.sigma_misalignment_rad = 1.0 * kDeg;
  s.align = AlignMode::Static;
  s.gnss_until_s = 90.0;
  if (with_odometer) s.odometer = drive().odometer;
  return fuse(drive().imu, drive().gnss, drive().truth, s);
}

TEST(FuseOdometer, EstimatesTheOdometerErrorsAndBoundsTheDrift) {
  const FuseResult r = run(true);
  ASSERT_TRUE(r.odometer);
  const OdometerUse& u = *r.odometer;
  const fusion::OdometerNominal &v = u.estimate.value, &sd = u.estimate.sigma;
  EXPECT_NEAR(v.scale_factor, 0.01, 3.0 * sd.scale_factor);
  EXPECT_LT(sd.scale_factor, 0.002);
  EXPECT_NEAR(v.pitch_rad, 0.4 * kDeg, 3.0 * sd.pitch_rad);
  EXPECT_NEAR(v.yaw_rad, -0.6 * kDeg, 3.0 * sd.yaw_rad);
  EXPECT_LT(sd.yaw_rad, 0.2 * kDeg);
  EXPECT_NEAR(v.delay_s, 0.05, 3.0 * sd.delay_s);
  EXPECT_EQ(u.gnss_last_used_s, 90.0);
  ASSERT_TRUE(u.distance_travelled_m && u.horizontal_error_max_m);
  EXPECT_GT(*u.distance_travelled_m, 3000.0);
  EXPECT_LT(100.0 * *u.horizontal_error_max_m / *u.distance_travelled_m, 0.16);
  EXPECT_GT(r.counters.odometer.gated_yaw_rate, 10);  // the turns
  EXPECT_GT(r.counters.odometer.gated_speed, 5);      // the stop (and the parked start)
  EXPECT_GE(r.counters.odometer.rejected, 1);         // the locked wheel at 300 s
  EXPECT_GT(r.counters.odometer.accepted, 150);
  EXPECT_GT(r.fixes_after_gnss_until, 200);

  const FuseResult always = run(true, fusion::OdometerMode::kAlways);
  EXPECT_EQ(always.counters.odometer.gated_yaw_rate + always.counters.odometer.gated_speed, 0);
  EXPECT_GT(always.counters.odometer.accepted, r.counters.odometer.accepted);

  // Without the odometer the same drive after the GNSS is pure inertial: its error at the end is larger.
  const FuseResult inertial = run(false);
  ASSERT_TRUE(r.rms_all && inertial.rms_all);
  EXPECT_GT(inertial.rms_all->velocity_mps, 2.0 * r.rms_all->velocity_mps);
}

}  // namespace
}  // namespace ultratrack::pipelines
