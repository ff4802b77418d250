// SPDX-License-Identifier: GPL-3.0-or-later
// In-motion alignment: the levelling equation against random attitudes (closed form, exact), whole alignments on
// simulated trajectories against the simulator's truth attitude, and the alignment's error sensitivities to the
// IMU biases and GNSS velocity errors against the level closed form and against the actual error of alignments
// made with the simulator's own IMU error draws and with perturbed velocities.
#include "fusion/fuse_motion_alignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
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

// A straight, level drive at 12 m/s, heading 37 deg: first order, the accelerometer bias tilts the levelled frame
// by psi x f_n = C_nb b_a with f_n = (0, 0, -g): psi_N = (C b_a)_E / g, psi_E = -(C b_a)_N / g; the gyro bias turns
// each increment on its way to the window's end by b_g (t_end - t), on average b_g T / 2, so the mean specific force
// is off by f_b x (b_g T / 2) and psi_N,E = -(T / 2) (C b_g)_N,E. The heading comes from the track: psi_D = 0.
TEST(FuseMotionAlignment, BiasSensitivitiesMatchTheLevelClosedForm) {
  ins::TrajectorySpec spec;
  spec.lat0_rad = 47.4 * io::kRadPerDeg;
  spec.lon0_rad = 8.5 * io::kRadPerDeg;
  spec.height0_m = 420.0;
  spec.speed0_mps = 12.0;
  spec.heading0_rad = 37.0 * io::kRadPerDeg;
  spec.segments = {{20.0, 0.0, 0.0, 0.0, 0.0}};
  const ins::SimulatedRun run = ins::simulate(spec, 200.0);
  const ins::TruthInterpolator truth(run.truth);
  const auto a = fusion::align_in_motion(run.imu, gnss_velocities(truth, 0.137), {5.0, 2.0});
  ASSERT_TRUE(a.has_value());
  const double g = ins::gravity_n(spec.lat0_rad, spec.height0_m).z();  // down, positive
  const double T = a->t_s - a->t_start_s;
  const Eigen::Matrix3d C = a->q_nb.toRotationMatrix();
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();  // (C b)_N,E -> (psi_N, psi_E) = ((C b)_E, -(C b)_N)
  K(0, 1) = 1.0;
  K(1, 0) = -1.0;
  const Eigen::Matrix3d accel_expected = K * C / g;
  Eigen::Matrix3d gyro_expected = -0.5 * T * C;
  gyro_expected.row(2).setZero();
  EXPECT_LT((a->psi_per_accel_bias - accel_expected).norm(), 2e-3 * accel_expected.norm())
      << a->psi_per_accel_bias << "\nexpected\n"
      << accel_expected;
  EXPECT_LT((a->psi_per_gyro_bias - gyro_expected).norm(), 2e-3 * gyro_expected.norm())
      << a->psi_per_gyro_bias << "\nexpected\n"
      << gyro_expected;
}

// The simulator's own error draws: 20 ADIS16405-class units (3 deg/s gyro and 50 mg accelerometer turn-on biases;
// random walks and instability off, so that each unit's error is deterministic) on the land profile, aligned while
// accelerating. Each alignment's actual attitude error against the truth is the first-order prediction
// A_a b_a + A_g b_g up to terms of second order in the errors: about 6 % of errors of 6 deg RMS, and ten times less
// for biases ten times smaller.
struct PredictionCheck {
  double rms_error_rad = 0.0, relative_residual = 0.0, relative_residual_accel_only = 0.0;
};
PredictionCheck predict_unit_errors(double bias_scale) {
  const auto spec = ins::profile_spec("land", 40.0, 47.4 * io::kRadPerDeg, 8.5 * io::kRadPerDeg, 420.0);
  const ins::SimulatedRun run = ins::simulate(spec, 200.0);
  const ins::TruthInterpolator truth(run.truth);
  const auto gnss = gnss_velocities(truth, 0.137);
  ins::ImuErrorSpec unit = ins::imu_preset("adis16405");
  unit.gyro.random_walk = unit.accel.random_walk = 0.0;
  unit.gyro.bias_instability_sigma = unit.accel.bias_instability_sigma = 0.0;
  unit.gyro.bias_sigma *= bias_scale;
  unit.accel.bias_sigma *= bias_scale;
  double sum_actual2 = 0.0, sum_residual2 = 0.0, sum_accel_only2 = 0.0;
  const int units = 20;
  for (int seed = 1; seed <= units; ++seed) {
    ins::ImuErrorModel model(unit, static_cast<std::uint64_t>(seed));
    std::vector<ins::ImuIncrement> imu;
    for (std::size_t k = 0; k < run.imu.size(); ++k)
      imu.push_back(model.apply(run.imu[k], run.truth[k + 1].t_s - run.truth[k].t_s));
    const auto a = fusion::align_in_motion(imu, gnss, {5.0, 2.0});
    if (!a) {
      ADD_FAILURE() << "no alignment for unit " << seed;
      continue;
    }
    const Eigen::Vector3d actual = ins::attitude_error_n(a->q_nb, truth.attitude(a->t_s));
    const Eigen::Vector3d accel_part = a->psi_per_accel_bias * model.turn_on_errors().accel.bias;
    const Eigen::Vector3d predicted = accel_part + a->psi_per_gyro_bias * model.turn_on_errors().gyro.bias;
    sum_actual2 += actual.squaredNorm();
    sum_residual2 += (actual - predicted).squaredNorm();
    sum_accel_only2 += (actual - accel_part).squaredNorm();
  }
  return {std::sqrt(sum_actual2 / units), std::sqrt(sum_residual2 / sum_actual2),
          std::sqrt(sum_accel_only2 / sum_actual2)};
}

TEST(FuseMotionAlignment, BiasSensitivitiesPredictTheErrorsOfSimulatedUnits) {
  const PredictionCheck full = predict_unit_errors(1.0);
  EXPECT_GT(full.rms_error_rad, 4.0 * io::kRadPerDeg);  // the biases' errors: degrees
  EXPECT_LT(full.relative_residual, 0.08);
  EXPECT_GT(full.relative_residual_accel_only, 0.4);  // the gyro's part is not negligible
  const PredictionCheck small = predict_unit_errors(0.1);
  EXPECT_LT(small.relative_residual, 0.01);  // second order: ten times smaller for biases ten times smaller
}

// GNSS velocity errors at the window's ends (exact IMU): the alignment's actual error against the truth equals
// V_start e_start + V_end e_end, for 20 draws of 0.1 m/s per axis.
TEST(FuseMotionAlignment, VelocitySensitivitiesPredictTheErrorsOfPerturbedFixes) {
  const auto spec = ins::profile_spec("land", 40.0, 47.4 * io::kRadPerDeg, 8.5 * io::kRadPerDeg, 420.0);
  const ins::SimulatedRun run = ins::simulate(spec, 200.0);
  const ins::TruthInterpolator truth(run.truth);
  const auto exact = gnss_velocities(truth, 0.137);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 0.1);
  for (int trial = 0; trial < 20; ++trial) {
    auto gnss = exact;
    for (auto& s : gnss) s.v_n += Eigen::Vector3d(n(rng), n(rng), n(rng));
    const auto a = fusion::align_in_motion(run.imu, gnss, {5.0, 2.0});
    ASSERT_TRUE(a.has_value());
    Eigen::Vector3d predicted = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < gnss.size(); ++i) {
      const Eigen::Vector3d e = gnss[i].v_n - exact[i].v_n;
      if (gnss[i].t_s == a->t_start_s) predicted += a->psi_per_velocity_start * e;
      if (gnss[i].t_s == a->t_s) predicted += a->psi_per_velocity_end * e;
    }
    const Eigen::Vector3d actual = ins::attitude_error_n(a->q_nb, truth.attitude(a->t_s));
    EXPECT_GT(actual.norm(), 0.1 * io::kRadPerDeg);  // the velocity errors matter
    EXPECT_LT((actual - predicted).norm(), 0.02 * actual.norm() + 2e-5)
        << "trial " << trial << ": actual " << actual.transpose() << " predicted " << predicted.transpose();
  }
}

}  // namespace
