// SPDX-License-Identifier: GPL-3.0-or-later
// Gyro biases from a standstill at the start: against the simulated unit's own bias (closed form with an
// error-free unit: the only residual is the earth rate's horizontal part, which the estimate cannot know without a
// heading), against the BMI088-class unit's realised bias within the stated 1-sigma over several seeds, and the
// standstill's end found at the first rotation or acceleration; an idling engine's vibration widens the 1-sigma as its
// measured noise says, a rough road's is not a standstill.
#include "ins/standstill_gyro_bias.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "io/units.hpp"

using namespace ultratrack::ins;
using ultratrack::io::kRadPerDeg;

namespace {

constexpr double kLat = 28.57 * kRadPerDeg, kRate = 200.0;

// Ideal increments: at rest at attitude q_nb until t_move, then turning about body z at turn_dps and
// accelerating along body x at accel_mps2 (the earth rate and gravity kept; the small change of attitude during
// the motion is irrelevant to the test, which needs only the start of the motion).
std::vector<ImuIncrement> ideal_record(const Eigen::Quaterniond& q_nb, double T, double t_move, double turn_dps,
                                       double accel_mps2) {
  const double dt = 1.0 / kRate;
  const Eigen::Vector3d w = q_nb.conjugate() * earth_rate_n(kLat), f = q_nb.conjugate() * (-gravity_n(kLat, 0.0));
  std::vector<ImuIncrement> out;
  for (long k = 1; k <= std::lround(T * kRate); ++k) {
    const double t = k * dt;
    Eigen::Vector3d wk = w, fk = f;
    if (t > t_move) {
      wk.z() += turn_dps * kRadPerDeg;
      fk.x() += accel_mps2;
    }
    out.push_back({t, wk * dt, fk * dt});
  }
  return out;
}

std::vector<ImuIncrement> corrupt(const std::vector<ImuIncrement>& ideal, ImuErrorModel& model,
                                  Eigen::Vector3d* mean_bias_to_t = nullptr, double t_end = 0.0) {
  std::vector<ImuIncrement> out;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& inc : ideal) {
    out.push_back(model.apply(inc, 1.0 / kRate));
    if (inc.t_s <= t_end + 1e-9) {
      sum += model.gyro_bias();
      ++n;
    }
  }
  if (mean_bias_to_t) *mean_bias_to_t = sum / std::max(n, 1);
  return out;
}

// White vibration on gyros and accelerometers, `times` the BMI088 datasheet's per-sample noise.
void shake(std::vector<ImuIncrement>& imu, double times, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> w(0.0, times * 0.014 * kRadPerDeg * std::sqrt(kRate) / kRate);
  std::normal_distribution<double> f(0.0, times * 175e-6 * 9.80665 * std::sqrt(kRate) / kRate);
  for (auto& inc : imu) {
    inc.dtheta_b += Eigen::Vector3d(w(rng), w(rng), w(rng));
    inc.dv_b += Eigen::Vector3d(f(rng), f(rng), f(rng));
  }
}

const Eigen::Quaterniond kTilted = quaternion_from_euler({2.0 * kRadPerDeg, -3.0 * kRadPerDeg, 40.0 * kRadPerDeg});

}  // namespace

TEST(StandstillGyroBias, ErrorFreeUnitLeavesOnlyTheHorizontalEarthRate) {
  ImuErrors turn_on;
  turn_on.gyro.bias = Eigen::Vector3d(0.5, -1.0, 2.0) * kRadPerDeg;
  ImuErrorModel model(imu_preset("ideal"), turn_on, 1);
  const auto imu = corrupt(ideal_record(kTilted, 30.0, 12.0, 3.0, 0.0), model);
  const auto s = initial_standstill_gyro_bias(imu, kLat, imu_preset("ideal"), 1e9);
  ASSERT_TRUE(s.has_value());
  // Motion from 12 s: the window (11, 12] passed and is dropped as the margin.
  EXPECT_NEAR(s->t_end_s, 11.0, 1e-9);
  const Eigen::Vector3d horizontal_earth_b =
      kTilted.conjugate() * Eigen::Vector3d(kEarthRate_rps * std::cos(kLat), 0.0, 0.0);
  const Eigen::Vector3d residual = s->gyro_bias_rps - turn_on.gyro.bias;
  EXPECT_LT((residual - horizontal_earth_b).norm(), 1e-9);
  EXPECT_TRUE((s->sigma_rps.array() >= kEarthRate_rps * std::cos(kLat)).all());
}

TEST(StandstillGyroBias, MemsUnitWithinItsSigmaOverSeeds) {
  const ImuErrorSpec spec = imu_preset("bmi088");  // 1 deg/s turn-on, 0.014 deg/s/sqrt(Hz)
  int inside = 0, cases = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    ImuErrorModel model(spec, seed);
    Eigen::Vector3d mean_bias;
    const auto imu = corrupt(ideal_record(kTilted, 40.0, 20.0, 0.0, 0.1), model, &mean_bias, 19.0);
    const auto s = initial_standstill_gyro_bias(imu, kLat, spec, 1e9);
    ASSERT_TRUE(s.has_value()) << "seed " << seed;
    // A 0.1 m/s^2 start is 4 sigma of one window's mean: found within a window of it.
    EXPECT_GE(s->t_end_s, 18.0 - 1e-9) << "seed " << seed;
    EXPECT_LE(s->t_end_s, 20.0 + 1e-9) << "seed " << seed;
    for (int axis = 0; axis < 3; ++axis) {
      const double z = (s->gyro_bias_rps[axis] - mean_bias[axis]) / s->sigma_rps[axis];
      EXPECT_LT(std::fabs(z), 4.0) << "seed " << seed << " axis " << axis;
      inside += std::fabs(z) < 2.0;
      ++cases;
    }
    // 1000 times better than the datasheet's turn-on sigma would be the noise alone; the earth rate and the
    // in-run instability keep it at about 50.
    EXPECT_LT(s->sigma_rps.maxCoeff(), spec.gyro.bias_sigma / 30.0);
  }
  EXPECT_GE(inside, cases * 8 / 10);  // about 95 % expected inside 2 sigma
}

TEST(StandstillGyroBias, NoneWhenTheRecordStartsMovingOrShaking) {
  const ImuErrorSpec spec = imu_preset("bmi088");
  {  // turning from the second second: too short
    ImuErrorModel model(spec, 3);
    const auto imu = corrupt(ideal_record(kTilted, 20.0, 2.0, 5.0, 0.0), model);
    EXPECT_FALSE(initial_standstill_gyro_bias(imu, kLat, spec, 1e9).has_value());
  }
  {  // shaking at 30 times the datasheet's noise (driving on a rough road): not a standstill
    ImuErrorModel model(spec, 4);
    auto imu = corrupt(ideal_record(kTilted, 20.0, 1e9, 0.0, 0.0), model);
    shake(imu, 30.0, 5);
    EXPECT_FALSE(initial_standstill_gyro_bias(imu, kLat, spec, 1e9).has_value());
  }
  {  // at rest throughout, but the caller needs the span to end by 4 s: shorter than the 5 s minimum
    ImuErrorModel model(spec, 6);
    const auto imu = corrupt(ideal_record(kTilted, 20.0, 1e9, 0.0, 0.0), model);
    EXPECT_FALSE(initial_standstill_gyro_bias(imu, kLat, spec, 4.0).has_value());
    const auto s = initial_standstill_gyro_bias(imu, kLat, spec, 10.0);
    ASSERT_TRUE(s.has_value());
    EXPECT_NEAR(s->t_end_s, 9.0, 1e-9);
  }
}

TEST(StandstillGyroBias, AnIdlingEngineWidensTheSigmaAsItsNoiseSays) {
  // Five times the datasheet's noise on every axis (a parked car's engine, a robot's motors): still a standstill,
  // the estimate within its sigma, which the measured noise widens (the noise term about 5 times the datasheet's).
  const ImuErrorSpec spec = imu_preset("bmi088");
  int inside = 0, cases = 0;
  for (std::uint64_t seed = 20; seed < 28; ++seed) {
    ImuErrorModel model(spec, seed);
    Eigen::Vector3d mean_bias;
    auto imu = corrupt(ideal_record(kTilted, 40.0, 20.0, 3.0, 0.0), model, &mean_bias, 19.0);
    shake(imu, 5.0, seed + 100);
    ImuErrorModel quiet_model(spec, seed);
    const auto quiet = initial_standstill_gyro_bias(corrupt(ideal_record(kTilted, 40.0, 20.0, 3.0, 0.0), quiet_model),
                                                    kLat, spec, 1e9);
    const auto s = initial_standstill_gyro_bias(imu, kLat, spec, 1e9);
    ASSERT_TRUE(s.has_value() && quiet.has_value()) << "seed " << seed;
    EXPECT_NEAR(s->t_end_s, 19.0, 1.0 + 1e-9) << "seed " << seed;
    EXPECT_GT(s->sigma_rps.minCoeff(), 2.0 * quiet->sigma_rps.maxCoeff()) << "seed " << seed;  // about 3
    for (int axis = 0; axis < 3; ++axis) {
      const double z = (s->gyro_bias_rps[axis] - mean_bias[axis]) / s->sigma_rps[axis];
      EXPECT_LT(std::fabs(z), 4.0) << "seed " << seed << " axis " << axis;
      inside += std::fabs(z) < 2.0;
      ++cases;
    }
  }
  EXPECT_GE(inside, cases * 8 / 10);
}
