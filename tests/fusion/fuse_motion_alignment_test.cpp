// SPDX-License-Identifier: GPL-3.0-or-later
// In-motion alignment: the levelling equation against random attitudes (closed form, exact), and whole
// alignments on simulated trajectories against the simulator's truth attitude.
#include "fusion/fuse_motion_alignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"

namespace {

using namespace ultratrack;

TEST(FuseMotionAlignment, LevellingRecoversRollAndPitchForAnyHeadingAndAcceleration) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    ins::EulerAngles e{u(rng) * 60.0 * io::kRadPerDeg, u(rng) * 45.0 * io::kRadPerDeg, u(rng) * 180.0 * io::kRadPerDeg};
    // specific force: gravity plus up to 5 m/s^2 of manoeuvre in any direction
    const Eigen::Vector3d f_n = Eigen::Vector3d(0, 0, -9.8) + 5.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d f_b = ins::quaternion_from_euler(e).conjugate() * f_n;
    const auto got = ultratrack::fusion::level_with_heading(f_b, f_n, e.yaw_rad);
    ASSERT_TRUE(got.has_value());
    EXPECT_NEAR(got->roll_rad, e.roll_rad, 1e-9);
    EXPECT_NEAR(got->pitch_rad, e.pitch_rad, 1e-9);
    EXPECT_NEAR(got->yaw_rad, e.yaw_rad, 1e-12);
  }
}

TEST(FuseMotionAlignment, ImpossibleGeometryIsRefused) {
  // |f_b| far larger than |f_n|: no rotation maps one on the other
  EXPECT_FALSE(ultratrack::fusion::level_with_heading({30.0, 0.0, -9.8}, {0.0, 0.0, -9.8}, 0.0).has_value());
}

// Exact GNSS velocities at 5 Hz on non-integer times from the simulator's truth.
std::vector<fusion::GnssVelocitySample> gnss_velocities(const ins::TruthInterpolator& truth, double t0) {
  std::vector<fusion::GnssVelocitySample> out;
  for (double t = t0; t <= truth.end_s(); t += 0.2) {
    const ins::EcefMotion m = truth.antenna(t, Eigen::Vector3d::Zero());
    const auto& s = truth.samples()[static_cast<std::size_t>(t / (truth.samples()[1].t_s - truth.samples()[0].t_s))];
    out.push_back({t, s.lat_rad, s.height_m, ins::C_en(s.lat_rad, s.lon_rad).transpose() * m.v_e});
  }
  return out;
}

void check_alignment(const ins::TrajectorySpec& spec, double tol_tilt_deg, double tol_heading_deg) {
  const ins::SimulatedRun run = ins::simulate(spec, 200.0);
  const ins::TruthInterpolator truth(run.truth);
  const auto gnss = gnss_velocities(truth, 0.137);
  const auto a = fusion::align_in_motion(run.imu, gnss, {5.0, 2.0});
  ASSERT_TRUE(a.has_value());
  const ins::EulerAngles e_true = ins::euler_from_quaternion(truth.attitude(a->t_s));
  EXPECT_NEAR(a->euler.roll_rad / io::kRadPerDeg, e_true.roll_rad / io::kRadPerDeg, tol_tilt_deg);
  EXPECT_NEAR(a->euler.pitch_rad / io::kRadPerDeg, e_true.pitch_rad / io::kRadPerDeg, tol_tilt_deg);
  EXPECT_NEAR(ins::wrap_pi(a->euler.yaw_rad - e_true.yaw_rad) / io::kRadPerDeg, 0.0, tol_heading_deg);
}

// A banked turn (24 deg roll at 500 km/h, pi/100 rad/s): the levelling must use the centripetal acceleration.
// Remaining error: chord versus arc of the 2 s window (~1e-3 m/s^2 -> ~0.005 deg).
TEST(FuseMotionAlignment, BankedCircleAlignsToTruth) {
  const auto spec = ins::profile_spec("circle", 20.0, 36.0 * io::kRadPerDeg, 127.0 * io::kRadPerDeg, 1000.0);
  check_alignment(spec, 0.02, 0.02);
}

// A car accelerating from rest at 2 m/s^2: the first fast-enough window is during the acceleration.
TEST(FuseMotionAlignment, AcceleratingCarAlignsToTruth) {
  const auto spec = ins::profile_spec("land", 40.0, 36.0 * io::kRadPerDeg, 127.0 * io::kRadPerDeg, 100.0);
  check_alignment(spec, 0.02, 0.02);
}

}  // namespace
