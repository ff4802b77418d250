// SPDX-License-Identifier: GPL-3.0-or-later
// A slow platform through the library: the rover of scenarios/rover_slow_bmi088.toml (0.4 m/s, BMI088-class unit
// with a 1 deg/s turn-on gyro bias, parked for its first 20 s), 5 Hz position-only fixes with 0.6/0.6/1.2 m
// Gauss-Markov errors of 30 s, `fuse` configured as scenarios/rover_fuse.toml (the preset class, alignment from
// 0.3 m/s, land constraints) and told the fixes' correlation. Checked per seed:
// - the gyro biases measured over the standstill against the unit's simulated ones, within 4 of their 1-sigma;
// - the in-motion heading from the longer track within 3 of its 1-sigma (0.6 m fixes over 40 s at 0.4 m/s: 3 deg);
// - the yaw RMS after the alignment at most 1.5 times that 1-sigma, and the yaw inside 3 of the filter's own
//   1-sigma at >= 95 % of the rows. Before the standstill and the longer track (a 5 s track, the bias learnt in
//   motion) these runs started 3-20 deg off with a 5 deg sigma and held 2-8 deg RMS (docs/validation.md, 14).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "config/fuse_config_toml.hpp"
#include "config/scenario_toml.hpp"
#include "ins/attitude.hpp"
#include "ins/imu_csv.hpp"
#include "pipelines/fuse.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "sim/scenario_models.hpp"
#include "sim/simulation_files.hpp"
#include "sim/truth_csv.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

double wrapped(double a_rad) { return std::remainder(a_rad, 2.0 * std::numbers::pi); }

TEST(FuseSlowPlatform, StandstillBiasesAndALongerTrackGiveAnHonestHeading) {
  const auto scenario_file = test::scenarios_dir() / "rover_slow_bmi088.toml";
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    sim::Scenario scenario = config::read_scenario(scenario_file);
    scenario.imu_seed = seed;
    const auto dir = test::scratch_dir() / ("rover" + std::to_string(seed));
    const sim::SimulationResult simulated =
        sim::simulate_to_folder(scenario, dir / "sim", test::read_text_file(scenario_file));
    const ins::TruthInterpolator truth(truth_samples_from_nav(sim::read_truth_csv(dir / "sim" / "truth.csv")));
    GnssFixSimulationOptions fix_options;
    fix_options.rate_hz = 5.0;
    fix_options.first_time_s = 0.137;
    fix_options.sigma_ned_m = Eigen::Vector3d(0.6, 0.6, 1.2);
    fix_options.correlation_time_s = 30.0;
    fix_options.with_velocity = false;
    fix_options.seed = seed;
    const std::vector<GnssFixRow> fixes = simulate_gnss_fixes(truth, fix_options);

    FuseSettings s;
    s.config = config::read_fuse_config(test::scenarios_dir() / "rover_fuse.toml");
    s.config.fix_error_correlation_s = 30.0;
    s.config.fix_error_sigma_ned_m = Eigen::Vector3d(0.6, 0.6, 1.2);
    s.align = AlignMode::Motion;
    bool first = true;
    double start_error = 0.0, start_sigma = 0.0, y2 = 0.0;
    int rows = 0, inside = 0;
    const FuseResult result = fuse(
        ins::read_imu_csv(dir / "sim" / "imu.csv"), fixes, {}, s, [&](const ins::NavState& nav, const NavSigma& sig) {
          if (nav.t_s > truth.end_s()) return;
          const double e = wrapped(ins::euler_from_quaternion(nav.q_nb).yaw_rad -
                                   ins::euler_from_quaternion(truth.attitude(nav.t_s)).yaw_rad);
          if (first) {
            start_error = e;
            start_sigma = sig.attitude_ned_rad.z();
            first = false;
          }
          y2 += e * e;
          inside += std::fabs(e) <= 3.0 * sig.attitude_ned_rad.z();
          ++rows;
        });
    ASSERT_TRUE(result.standstill.has_value());
    EXPECT_NEAR(result.standstill->t_end_s, 19.0, 1.0);  // parked for 20 s
    const ins::ImuErrorSpec spec = sim::imu_error_spec(scenario);
    const Eigen::Vector3d z = (result.standstill->gyro_bias_rps - simulated.imu_turn_on.gyro.bias).array() /
                              result.standstill->sigma_rps.array();
    EXPECT_LT(z.cwiseAbs().maxCoeff(), 4.0) << z.transpose();
    EXPECT_LT(result.standstill->sigma_rps.maxCoeff(), spec.gyro.bias_sigma / 30.0);
    EXPECT_EQ(result.motion_span_s, 40.0);
    EXPECT_NEAR(start_sigma / kDeg, 3.0, 0.5);
    EXPECT_LT(std::fabs(start_error), 3.0 * start_sigma) << start_error / kDeg << " deg";
    ASSERT_GT(rows, 10000);
    EXPECT_LT(std::sqrt(y2 / rows), 1.5 * start_sigma) << std::sqrt(y2 / rows) / kDeg << " deg RMS";
    EXPECT_GE(inside, rows * 95 / 100);
  }
}

}  // namespace
}  // namespace ultratrack::pipelines
