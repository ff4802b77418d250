// SPDX-License-Identifier: GPL-3.0-or-later
// Seed 000's stationary alignment: the 12-state model against the 15-state INS error model at rest, H_G (eq. 16)
// against a numerical derivative of the exact Euler difference, the observability rank (eqs. 18-20: 12 at
// generic attitudes, less at pitch 90 deg or with one of the two measurements alone), and closed-loop alignments
// on closed-form IMU increments of a vehicle at rest (HG1700AE errors drawn per run, GPS attitude = truth + white
// Euler noise): errors inside the filter's sigmas, EKF and UKF alike.
#include "fusion/stationary_alignment.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusion/alignment_observability.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/stationary_alignment_model.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "io/units.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kDeg = io::kRadPerDeg;

TEST(StationaryAlignmentModel, EqualsTheFullErrorModelAtRest) {
  const double lat = 36.0 * kDeg, g = 9.8;
  const ins::EulerAngles e{3.0 * kDeg, -5.0 * kDeg, 130.0 * kDeg};
  InsLinearisation lin;
  lin.nav.lat_rad = lat;
  lin.nav.q_nb = ins::quaternion_from_euler(e);
  const Eigen::Matrix3d C_nb = lin.nav.q_nb.toRotationMatrix();
  lin.f_b = C_nb.transpose() * Eigen::Vector3d(0.0, 0.0, -g);
  lin.w_ib_b = C_nb.transpose() * ins::earth_rate_n(lat);
  const StateMatrix<15> F15 = ins_error_dynamics<15>(lin, InsErrorModelOptions{});
  StationaryAlignmentModelOptions o;
  o.lat_rad = lat;
  o.gravity_mps2 = g;
  const AlignmentMatrix A = stationary_error_dynamics(C_nb, o);
  // The seed drops the position states and the transport-rate terms (1 / earth radius ~ 1.6e-7).
  EXPECT_LT((A - F15.bottomRightCorner<12, 12>()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_GT(A.cwiseAbs().maxCoeff(), 9.0);
}

TEST(StationaryAlignmentModel, EulerJacobianIsSeedHg) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    const ins::EulerAngles e{u(rng) * 3.0, u(rng) * 1.3, u(rng) * 3.1};
    const Eigen::Quaterniond q = ins::quaternion_from_euler(e);
    const EulerAttitudeMeasurement m(q, q, Eigen::Vector3d::Constant(1e-3));
    Eigen::Matrix3d J;
    const double d = 1e-7;
    for (int j = 0; j < 3; ++j) {
      AlignmentVector xp = AlignmentVector::Zero(), xm = AlignmentVector::Zero();
      xp(align_ix::kAtt + j) = d;
      xm(align_ix::kAtt + j) = -d;
      J.col(j) = (m.h(xp) - m.h(xm)) / (2.0 * d);
    }
    const Eigen::Matrix3d HG = m.H(AlignmentVector::Zero()).block<3, 3>(0, align_ix::kAtt);
    EXPECT_LT((J - HG).cwiseAbs().maxCoeff(), 1e-6 / std::cos(e.pitch_rad)) << k;
  }
}

StationaryAlignmentModelOptions hg1700_model(double lat) {
  return alignment_model_options(ins::imu_preset("hg1700ae"), lat, 9.8);
}

TEST(AlignmentObservability, FullRankAtGenericAttitudes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    const ins::EulerAngles e{u(rng) * 3.0, u(rng) * 1.4, u(rng) * 3.1};
    EXPECT_EQ(alignment_observability(e, hg1700_model(0.6)).rank, 12) << k;
  }
  EXPECT_EQ(alignment_observability({0.0, 0.0, 0.0}, hg1700_model(0.6)).rank, 12);
}

TEST(AlignmentObservability, RankDropsAtPitch90AndWithOneMeasurementAlone) {
  for (double yaw : {0.0, 0.7, -2.0}) {
    const ins::EulerAngles vertical{0.3, 90.0 * kDeg, yaw};
    const ObservabilityReport r = alignment_observability(vertical, hg1700_model(0.6));
    EXPECT_LT(r.rank, 12) << yaw;
    EXPECT_NEAR(r.weakest_direction.norm(), 1.0, 1e-12);
  }
  const ins::EulerAngles generic{0.1, 0.2, 0.3};
  EXPECT_LT(alignment_observability(generic, hg1700_model(0.6), {.zero_velocity = true, .gps_attitude = false}).rank,
            12);
  EXPECT_LT(alignment_observability(generic, hg1700_model(0.6), {.zero_velocity = false, .gps_attitude = true}).rank,
            12);
}

// Closed-form increments of a vehicle at rest (earth rate and gravity only), corrupted by an HG1700AE drawn from
// the seed; GPS attitude at 1 Hz = truth + white Euler noise.
struct StaticRun {
  std::vector<ins::ImuIncrement> imu;
  std::vector<GnssAttitude> gps;
  ins::ImuErrors errors;
};

StaticRun static_run(const ins::EulerAngles& truth, double lat, double duration_s, const Eigen::Vector3d& sigma,
                     std::uint64_t seed) {
  StaticRun run;
  const ins::ImuErrorSpec spec = ins::imu_preset("hg1700ae");
  ins::ImuErrorModel model(spec, seed);
  run.errors = model.turn_on_errors();
  const Eigen::Matrix3d C_bn = ins::quaternion_from_euler(truth).toRotationMatrix().transpose();
  const Eigen::Vector3d w_b = C_bn * ins::earth_rate_n(lat), f_b = C_bn * -ins::gravity_n(lat, 0.0);
  const double dt = 0.01;
  for (int k = 1; k <= static_cast<int>(std::lround(duration_s / dt)); ++k) {
    ins::ImuIncrement ideal{k * dt, w_b * dt, f_b * dt};
    run.imu.push_back(model.apply(ideal, dt));
  }
  std::mt19937_64 rng(seed + 1000);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int s = 0; s <= static_cast<int>(duration_s); ++s) {
    GnssAttitude a;
    a.t_s = s + 0.005;
    a.euler_a = {truth.roll_rad + sigma.x() * n(rng), truth.pitch_rad + sigma.y() * n(rng),
                 truth.yaw_rad + sigma.z() * n(rng)};
    a.sigma_euler_rad = sigma;
    run.gps.push_back(a);
  }
  return run;
}

TEST(StationaryAlignment, ErrorsInsideSigmaAndBiasesEstimatedEkfAndUkf) {
  const double lat = 36.37 * kDeg;
  const ins::EulerAngles truth{2.0 * kDeg, -3.0 * kDeg, 35.0 * kDeg};
  const Eigen::Vector3d sigma(0.3 * kDeg, 0.3 * kDeg, 0.1 * kDeg);
  StationaryAlignmentOptions o;
  o.imu = ins::imu_preset("hg1700ae");
  o.lat_rad = lat;
  o.duration_s = 100.0;
  int worst_outside = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const StaticRun run = static_run(truth, lat, 101.0, sigma, seed);
    o.filter = FilterKind::Ekf;
    const auto ekf = align_stationary(run.imu, run.gps, o);
    o.filter = FilterKind::Ukf;
    const auto ukf = align_stationary(run.imu, run.gps, o);
    EXPECT_EQ(ekf.history.size(), 100u);
    EXPECT_EQ(ekf.attitude_updates, 100);
    EXPECT_NEAR(ekf.end_s - ekf.start_s, 100.0, 0.011);
    const ins::EulerAngles e = ins::euler_from_quaternion(ekf.nav.q_nb);
    const Eigen::Vector3d err(e.roll_rad - truth.roll_rad, e.pitch_rad - truth.pitch_rad,
                              ins::wrap_pi(e.yaw_rad - truth.yaw_rad));
    // The filter's sigma after 100 s: far below one GPS attitude's (averaging), and the error inside 4 sigma.
    EXPECT_LT(ekf.sigma_euler_rad.x(), 0.3 * sigma.x());
    EXPECT_LT(ekf.sigma_euler_rad.z(), 0.5 * sigma.z());
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(std::abs(err(i)), 4.0 * ekf.sigma_euler_rad(i)) << seed << " axis " << i;
      if (std::abs(err(i)) > 3.0 * ekf.sigma_euler_rad(i)) ++worst_outside;
    }
    // Linear dynamics, a mildly nonlinear Euler measurement: the UKF ends within 5 % of a sigma of the EKF.
    const ins::EulerAngles eu = ins::euler_from_quaternion(ukf.nav.q_nb);
    EXPECT_NEAR(eu.roll_rad, e.roll_rad, 0.05 * ekf.sigma_euler_rad.x());
    EXPECT_NEAR(eu.yaw_rad, e.yaw_rad, 0.05 * ekf.sigma_euler_rad.z());
    EXPECT_LT((ukf.sigma_euler_rad - ekf.sigma_euler_rad).cwiseAbs().maxCoeff(), 1e-3 * ekf.sigma_euler_rad.maxCoeff());
    // Horizontal accelerometer biases (observable through zero velocity + attitude): inside 4 sigma.
    const Eigen::Vector3d ba_err = ekf.accel_bias_b - run.errors.accel.bias;
    for (int i = 0; i < 3; ++i)
      EXPECT_LT(std::abs(ba_err(i)), 4.0 * std::sqrt(ekf.P(align_ix::kAccelBias + i, align_ix::kAccelBias + i)))
          << seed << " accel axis " << i;
  }
  EXPECT_LE(worst_outside, 1);
}

}  // namespace
}  // namespace ultratrack::fusion
