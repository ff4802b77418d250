// SPDX-License-Identifier: GPL-3.0-or-later
// Is the datasheet MEMS model honest, not only good? A Monte Carlo of the ADIS16405-class drive
// (scenarios/mems_drive_adis16405.toml: 50 mg and 3 deg/s turn-on biases drawn anew for every unit), 5 Hz fixes with
// velocity (0.5/0.5/1 m, 0.05 m/s) at non-integer times, `fuse` told only the datasheet values
// (scenarios/mems_datasheet_fuse.toml) with in-motion alignment and the land constraints. After the first 60 s, the
// NEES of position, velocity and attitude (NED, the filter's diagonal 1-sigmas, as benchmarks/nav_nees.py) averaged
// over the units and times lies in the chi-square 95 % band of a 20-unit average of 3 degrees of freedom,
// [chi2(0.025, 60), chi2(0.975, 60)] / 20 = [2.024, 4.165]. Without fusion/bias_frame_reset.hpp the attitude gave
// 4.61 (the tilt believed from the first straight road on) and the vertical velocity twice its variance.
// benchmarks/mems_nees.sh runs the same over 50 units from the command line.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "config/fuse_config_toml.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "pipelines/fuse.hpp"
#include "support/mems_drive_unit.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines {
namespace {

struct NeesSums {
  double position = 0.0, velocity = 0.0, attitude = 0.0;
  long long samples = 0;
};

void add_unit(std::uint64_t seed, NeesSums& sums) {
  const test_support::MemsDriveUnit unit =
      test_support::simulate_mems_drive_unit(test::scratch_dir() / ("unit" + std::to_string(seed)), seed, true);
  const ins::TruthInterpolator& truth = unit.truth;
  FuseSettings s;
  s.config = config::read_fuse_config(test::scenarios_dir() / "mems_datasheet_fuse.toml");
  s.config.land.nhc = true;
  s.config.velocity_sigma_mps = unit.fix_options.sigma_velocity_mps;
  s.align = AlignMode::Motion;
  double next_t = 60.0;
  fuse(unit.imu, unit.fixes, {}, s, [&](const ins::NavState& nav, const NavSigma& sigma) {
    if (nav.t_s < next_t - 1e-6 || nav.t_s > truth.end_s()) return;
    next_t = nav.t_s + 0.1;  // 10 Hz, as nav.csv
    const ins::EcefMotion m = truth.antenna(nav.t_s, Eigen::Vector3d::Zero());
    const Eigen::Matrix3d C_en = ins::C_en(nav.lat_rad, nav.lon_rad);
    const Eigen::Vector3d dr =
        C_en.transpose() * (ins::ecef_from_geodetic(nav.lat_rad, nav.lon_rad, nav.height_m) - m.r_e);
    const Eigen::Vector3d dv = nav.v_n - C_en.transpose() * m.v_e;
    const Eigen::Vector3d psi = ins::attitude_error_n(nav.q_nb, truth.attitude(nav.t_s));
    sums.position += dr.cwiseQuotient(sigma.position_ned_m).squaredNorm();
    sums.velocity += dv.cwiseQuotient(sigma.velocity_ned_mps).squaredNorm();
    sums.attitude += psi.cwiseQuotient(sigma.attitude_ned_rad).squaredNorm();
    ++sums.samples;
  });
}

TEST(FuseMemsNees, DatasheetModelIsConsistentOverTwentyUnits) {
  NeesSums sums;
  const int units = 20;
  for (int seed = 1; seed <= units; ++seed) add_unit(static_cast<std::uint64_t>(seed), sums);
  ASSERT_GT(sums.samples, units * 3000);
  const double n = static_cast<double>(sums.samples);
  std::printf("NEES over %d units after 60 s: position %.2f, velocity %.2f, attitude %.2f (band [2.024, 4.165])\n",
              units, sums.position / n, sums.velocity / n, sums.attitude / n);
  for (const double nees : {sums.position / n, sums.velocity / n, sums.attitude / n}) {
    EXPECT_GT(nees, 2.024);
    EXPECT_LT(nees, 4.165);
  }
}

}  // namespace
}  // namespace ultratrack::pipelines
