// SPDX-License-Identifier: GPL-3.0-or-later
// Trajectory profiles reproduce [ChoUKF]'s motions (checked on the truth, not on the code's inputs),
// the land profile stays within 0-30 m/s and stops, the antenna motion interpolates the truth with its
// own velocity (checked against finite differences of the exact antenna positions), and the odometer
// counts the distance travelled with its scale-factor error.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/odometer.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"

using namespace ultratrack::ins;

namespace {
constexpr double kLat = 36.37 * ultratrack::io::kRadPerDeg, kLon = 127.36 * ultratrack::io::kRadPerDeg;

double speed_h(const TruthSample& s) { return std::hypot(s.v_n.x(), s.v_n.y()); }
}  // namespace

TEST(Profiles, StraightAccelerates1mps2North) {
  const SimulatedRun run = simulate(profile_spec("straight", 100.0, kLat, kLon, 100.0), 100.0);
  const TruthSample& end = run.truth.back();
  // quintic start ramp of 1 s delays the speed by 0.5 s: v(100) = 99.5 m/s
  EXPECT_NEAR(end.v_n.x(), 99.5, 1e-9);
  EXPECT_NEAR(end.v_n.y(), 0.0, 1e-12);
  const double north_m = (end.lat_rad - kLat) * (radii_of_curvature(kLat).meridian_m + 100.0);
  EXPECT_NEAR(north_m, 0.5 * 100.0 * 100.0 - 0.5 * 100.0, 5.0);  // ~4950 m (ellipsoid curvature: metres)
}

TEST(Profiles, CircleIs500kmhTurningPiOver100) {
  const SimulatedRun run = simulate(profile_spec("circle", 400.0, kLat, kLon, 1000.0), 100.0);
  // After the 3 s roll-in the heading advances pi/100 rad/s at 500 km/h; a full circle takes 200 s.
  const TruthSample& a = run.truth[10000];  // t = 100 s
  const TruthSample& b = run.truth[30000];  // t = 300 s
  EXPECT_NEAR(speed_h(a), 500.0 / 3.6, 1e-9);
  EXPECT_NEAR(wrap_pi(euler_from_quaternion(b.q_nb).yaw_rad - euler_from_quaternion(a.q_nb).yaw_rad), 0.0, 1e-9);
  const Eigen::Vector3d ra = ecef_from_geodetic(a.lat_rad, a.lon_rad, a.height_m);
  const Eigen::Vector3d rb = ecef_from_geodetic(b.lat_rad, b.lon_rad, b.height_m);
  // Closes on itself except for meridian convergence: heading is kept relative to local north, which turns
  // by dlon sin L as the vehicle moves east, shifting the circle by about pi r^2 tan L / R per turn (7 m).
  const double r = 500.0 / 3.6 / (std::numbers::pi / 100);
  const double drift = std::numbers::pi * r * r * std::tan(kLat) / radii_of_curvature(kLat).transverse_m;
  EXPECT_LT((ra - rb).norm(), 1.1 * drift);
  // coordinated bank atan(v w / g0) = 24 deg
  EXPECT_NEAR(euler_from_quaternion(a.q_nb).roll_rad, std::atan(500.0 / 3.6 * std::numbers::pi / 100 / 9.80665), 1e-12);
}

TEST(Profiles, SReversesTheTurnAt100s) {
  const SimulatedRun run = simulate(profile_spec("s", 200.0, kLat, kLon, 1000.0), 100.0);
  auto yaw_rate = [&](std::size_t k) {
    return wrap_pi(euler_from_quaternion(run.truth[k + 1].q_nb).yaw_rad -
                   euler_from_quaternion(run.truth[k].q_nb).yaw_rad) *
           100.0;
  };
  EXPECT_NEAR(yaw_rate(5000), std::numbers::pi / 100, 1e-9);
  EXPECT_NEAR(yaw_rate(15000), -std::numbers::pi / 100, 1e-9);
}

TEST(Profiles, SpiralClimbs02mps) {
  const SimulatedRun run = simulate(profile_spec("spiral", 200.0, kLat, kLon, 1000.0), 100.0);
  EXPECT_NEAR(run.truth[15000].v_n.z(), -0.2, 1e-12);
  EXPECT_NEAR(run.truth[20000].height_m - run.truth[10000].height_m, 20.0, 1e-6);
}

TEST(Profiles, LandStaysWithin0To30mpsStopsTurnsAndClimbs) {
  const SimulatedRun run = simulate(profile_spec("land", 600.0, kLat, kLon, 50.0), 100.0);
  double vmax = 0.0, vmin = 1e9, pitch_max = 0.0;
  int stopped = 0;
  for (const auto& s : run.truth) {
    vmax = std::max(vmax, speed_h(s));
    vmin = std::min(vmin, speed_h(s));
    pitch_max = std::max(pitch_max, std::fabs(euler_from_quaternion(s.q_nb).pitch_rad));
    if (speed_h(s) < 1e-9) ++stopped;
  }
  EXPECT_NEAR(vmax, 30.0, 1e-6);
  EXPECT_GE(vmin, -1e-9);
  EXPECT_GT(stopped, 2000);  // at least 20 s standing still
  EXPECT_NEAR(pitch_max, 4.0 * ultratrack::io::kRadPerDeg, 1e-9);
}

TEST(TruthInterpolator, AntennaMotionMatchesExactSamplesAndDerivatives) {
  // Truth at 100 Hz for the interpolator; the same trajectory at 400 Hz provides exact values in between.
  const TrajectorySpec spec = profile_spec("s", 130.0, kLat, kLon, 1000.0);
  const SimulatedRun coarse = simulate(spec, 100.0);
  const SimulatedRun fine = simulate(spec, 400.0);
  const TruthInterpolator interp(coarse.truth);
  const Eigen::Vector3d lever(1.2, -0.4, -0.8);  // antenna ahead, left, above the IMU
  // at a sample: IMU position from GeographicLib plus the rotated lever arm
  const TruthSample& s0 = coarse.truth[500];
  const Eigen::Vector3d expect =
      ecef_from_geodetic(s0.lat_rad, s0.lon_rad, s0.height_m) + C_en(s0.lat_rad, s0.lon_rad) * (s0.q_nb * lever);
  EXPECT_LT((interp.antenna(s0.t_s, lever).r_e - expect).norm(), 1e-6);
  double worst_r = 0.0, worst_v = 0.0;
  for (std::size_t k = 2; k + 2 < fine.truth.size(); k += 37) {
    const double t = fine.truth[k].t_s;
    const EcefMotion m = interp.antenna(t, lever);
    const EcefMotion exact = antenna_motion_at_sample(fine.truth[k], lever);
    worst_r = std::max(worst_r, (m.r_e - exact.r_e).norm());
    // velocity against the central difference of exact antenna positions (independent of the w x l formula)
    const Eigen::Vector3d dr = (antenna_motion_at_sample(fine.truth[k + 1], lever).r_e -
                                antenna_motion_at_sample(fine.truth[k - 1], lever).r_e) /
                               (2.0 / 400.0);
    worst_v = std::max(worst_v, (m.v_e - dr).norm());
  }
  std::printf("[ antenna ] S profile, 100 Hz truth: worst interpolated position error %.2e m, velocity %.2e m/s\n",
              worst_r, worst_v);
  EXPECT_LT(worst_r, 1e-3);
  EXPECT_LT(worst_v, 5e-3);  // includes the central difference's own error (a h^2 / 6 ~ 1e-3 m/s)
}

TEST(Odometer, CountsDistanceWithScaleFactorError) {
  const SimulatedRun run = simulate(profile_spec("land", 300.0, kLat, kLon, 50.0), 100.0);
  // distance from the truth velocities by the trapezoid rule (independent of the simulator's integral)
  double distance = 0.0;
  for (std::size_t k = 1; k < run.truth.size(); ++k)
    distance += 0.5 * (run.truth[k].v_n.norm() + run.truth[k - 1].v_n.norm()) * 0.01;
  OdometerOptions opt;
  opt.scale_factor_error = 0.02;
  const auto odo = simulate_odometer(run.truth, opt);
  ASSERT_EQ(odo.size(), 3000u);
  double measured = 0.0;
  for (const auto& o : odo) {
    EXPECT_GE(o.pulses, 0);
    measured += o.distance_m;
  }
  EXPECT_NEAR(measured, 1.02 * distance, opt.meters_per_pulse + 1e-3);
  EXPECT_EQ(odo.front().pulses, 0);  // the land profile starts standing
}

TEST(TruthInterpolator, UnevenSamplesAndSampleTimesAgree) {
  const SimulatedRun run = simulate(profile_spec("circle", 20.0, kLat, kLon, 1000.0), 100.0);
  std::vector<TruthSample> uneven;
  for (std::size_t k = 0; k < run.truth.size(); ++k)
    if (k % 7 != 3) uneven.push_back(run.truth[k]);  // gaps of 20 ms: binary-search path
  const TruthInterpolator even(run.truth), odd(uneven);
  const Eigen::Vector3d lever(0.5, 0.2, -1.0);
  for (std::size_t k = 0; k < run.truth.size(); k += 13) {
    const double t = run.truth[k].t_s;
    const EcefMotion exact = antenna_motion_at_sample(run.truth[k], lever);
    EXPECT_LT((even.antenna(t, lever).r_e - exact.r_e).norm(), 1e-9) << t;  // at a sample: the sample itself
    EXPECT_LT((odd.antenna(t + 0.004, lever).r_e - even.antenna(t + 0.004, lever).r_e).norm(), 1e-4) << t;
  }
  // outside the span: clamped to the ends
  EXPECT_LT((even.antenna(-5.0, lever).r_e - antenna_motion_at_sample(run.truth.front(), lever).r_e).norm(), 1e-9);
  EXPECT_LT((even.antenna(99.0, lever).r_e - antenna_motion_at_sample(run.truth.back(), lever).r_e).norm(), 1e-9);
}
