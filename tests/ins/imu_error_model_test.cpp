// SPDX-License-Identifier: GPL-3.0-or-later
// IMU error model: statistics of each error term against its definition, presets against their sources
// ([KimAlign] Table 1, [OhAttINS] Table 1, the navigation grade), determinism of the seed, and
// IMU data at rest (simulator + preset) whose |f| and |w| equal normal gravity and earth rate within the
// preset's errors.
#include "ins/imu_error_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "ins/earth_model.hpp"
#include "ins/ins_error.hpp"
#include "ins/trajectory_simulator.hpp"
#include "io/units.hpp"

using namespace ultratrack::ins;

namespace {

double sample_std(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  double s = 0.0;
  for (double v : x) s += (v - m) * (v - m);
  return std::sqrt(s / static_cast<double>(x.size() - 1));
}
}  // namespace

TEST(ImuPresets, MatchTheirSources) {
  const ImuErrorSpec hg = imu_preset("hg1700ae");
  EXPECT_NEAR(hg.gyro.bias_sigma, 1.0 * ultratrack::io::kRadPerDeg / 3600.0, 1e-15);   // 1 deg/h
  EXPECT_NEAR(hg.gyro.random_walk, 0.125 * ultratrack::io::kRadPerDeg / 60.0, 1e-15);  // 0.125 deg/sqrt(h)
  EXPECT_NEAR(hg.gyro.output_white_noise, 80e-6, 1e-15);                               // 80 urad
  EXPECT_NEAR(hg.accel.bias_sigma, 9.80665e-3, 1e-12);                                 // 1 mg
  EXPECT_NEAR(hg.accel.output_white_noise, 0.008 * 0.3048, 1e-12);                     // 0.008 ft/s
  EXPECT_NEAR(hg.accel.random_walk, 0.065 * 0.3048 / 60.0, 1e-12);                     // 0.065 ft/s/sqrt(h)
  const ImuErrorSpec dmu = imu_preset("dmu6x");
  EXPECT_NEAR(dmu.gyro.bias_sigma, 1.0 * ultratrack::io::kRadPerDeg, 1e-15);  // 1 deg/s
  EXPECT_NEAR(dmu.accel.bias_sigma, 10e-3 * 9.80665, 1e-12);                  // 10 mg
  const ImuErrorSpec nav = imu_preset("navigation");
  EXPECT_NEAR(nav.gyro.bias_sigma, 0.01 * ultratrack::io::kRadPerDeg / 3600.0, 1e-18);  // 0.01 deg/h
  EXPECT_NEAR(nav.accel.bias_sigma, 25e-6 * 9.80665, 1e-12);                            // 25 ug
  const ImuErrorSpec ideal = imu_preset("ideal");
  EXPECT_EQ(ideal.gyro.bias_sigma + ideal.gyro.random_walk + ideal.accel.bias_sigma + ideal.accel.random_walk, 0.0);
  EXPECT_GT(imu_preset("mems").gyro.bias_sigma, dmu.gyro.bias_sigma / 10);
  EXPECT_THROW(imu_preset("tactical"), InputError);
}

TEST(ImuErrorModel, SameSeedSameOutputDifferentSeedDifferent) {
  const ImuErrorSpec spec = imu_preset("mems");
  ImuErrorModel a(spec, 42), b(spec, 42), c(spec, 43);
  const ImuIncrement ideal{0.01, {1e-3, 0, 0}, {0, 0, -0.098}};
  for (int i = 0; i < 10; ++i) {
    const ImuIncrement x = a.apply(ideal, 0.01), y = b.apply(ideal, 0.01), z = c.apply(ideal, 0.01);
    EXPECT_EQ(x.dtheta_b, y.dtheta_b);
    EXPECT_EQ(x.dv_b, y.dv_b);
    EXPECT_NE(x.dtheta_b, z.dtheta_b);
  }
}

TEST(ImuErrorModel, IdealPresetChangesNothing) {
  ImuErrorModel m(imu_preset("ideal"), 1);
  const ImuIncrement ideal{0.01, {1e-3, -2e-3, 3e-4}, {0.1, 0.2, -0.098}};
  const ImuIncrement out = m.apply(ideal, 0.01);
  EXPECT_EQ(out.dtheta_b, ideal.dtheta_b);
  EXPECT_EQ(out.dv_b, ideal.dv_b);
}

TEST(ImuErrorModel, RandomWalkHasSigmaTimesSqrtDt) {
  ImuErrorSpec spec;
  spec.gyro.random_walk = 1e-3;
  spec.accel.random_walk = 2e-3;
  ImuErrorModel m(spec, 7);
  const double dt = 0.01;
  std::vector<double> g, a;
  for (int i = 0; i < 100000; ++i) {
    const ImuIncrement o = m.apply({}, dt);
    g.push_back(o.dtheta_b.x());
    a.push_back(o.dv_b.z());
  }
  // sample std of 1e5 draws: relative sigma 0.22 %, 1 % is 4.5 sigma
  EXPECT_NEAR(sample_std(g), 1e-3 * std::sqrt(dt), 0.01 * 1e-3 * std::sqrt(dt));
  EXPECT_NEAR(sample_std(a), 2e-3 * std::sqrt(dt), 0.01 * 2e-3 * std::sqrt(dt));
}

TEST(ImuErrorModel, TurnOnBiasAndGaussMarkovStatistics) {
  ImuErrorSpec spec;
  spec.gyro.bias_sigma = 1e-4;
  spec.gyro.bias_instability_sigma = 2e-5;
  spec.gyro.bias_correlation_time_s = 10.0;
  const int n = 4000;
  const double dt = 0.1;
  std::vector<double> turn_on, gm0, gm_tau;
  double cross = 0.0;
  for (int s = 0; s < n; ++s) {
    ImuErrorModel m(spec, 1000 + s);
    turn_on.push_back(m.turn_on_errors().gyro.bias.x());
    const double b0 = m.gyro_bias().x() - m.turn_on_errors().gyro.bias.x();
    for (int k = 0; k < 100; ++k) m.apply({}, dt);  // one correlation time
    const double b1 = m.gyro_bias().x() - m.turn_on_errors().gyro.bias.x();
    gm0.push_back(b0);
    gm_tau.push_back(b1);
    cross += b0 * b1;
  }
  // 4000 samples: relative sigma of a std 1.1 %, of the correlation ~1.6 %; tolerances ~4 sigma
  EXPECT_NEAR(sample_std(turn_on), 1e-4, 0.045e-4);
  EXPECT_NEAR(sample_std(gm0), 2e-5, 0.09e-5);
  EXPECT_NEAR(sample_std(gm_tau), 2e-5, 0.09e-5);  // stationary
  const double corr = cross / n / (2e-5 * 2e-5);
  EXPECT_NEAR(corr, std::exp(-1.0), 0.05);
}

TEST(ImuErrorModel, ScaleFactorAndMisalignmentAreAppliedAsDrawn) {
  ImuErrorSpec spec;
  spec.gyro.scale_factor_sigma = 1e-3;
  spec.gyro.misalignment_sigma = 5e-4;
  ImuErrorModel m(spec, 3);
  const Eigen::Matrix3d M = m.turn_on_errors().gyro.scale_misalignment;
  EXPECT_GT(M.norm(), 0.0);
  const Eigen::Vector3d w(0.1, -0.2, 0.3);
  const ImuIncrement out = m.apply({0.01, w, Eigen::Vector3d::Zero()}, 0.01);
  EXPECT_LT((out.dtheta_b - (w + M * w)).norm(), 1e-18);
}

TEST(ImuErrorModel, QuantisationEmitsWholeQuantaWithoutDrift) {
  ImuErrorSpec spec;
  spec.accel.quantum = 1e-3;
  ImuErrorModel m(spec, 5);
  const Eigen::Vector3d dv(0.01234567, -0.0987654, 0.0004321);
  Eigen::Vector3d sum_out = Eigen::Vector3d::Zero();
  for (int k = 1; k <= 10000; ++k) {
    const ImuIncrement o = m.apply({k * 0.01, Eigen::Vector3d::Zero(), dv}, 0.01);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(o.dv_b[i] / 1e-3, std::round(o.dv_b[i] / 1e-3), 1e-6);
    sum_out += o.dv_b;
    // the accumulated output never strays more than half a quantum from the accumulated truth
    ASSERT_LE((sum_out - k * dv).cwiseAbs().maxCoeff(), 0.5e-3 + 1e-9);  // + rounding of 1e4 sums
  }
}

TEST(ImuErrorModel, OutputWhiteNoiseDoesNotAccumulate) {
  ImuErrorSpec spec;
  spec.gyro.output_white_noise = 80e-6;
  std::vector<double> sums, singles;
  for (int s = 0; s < 2000; ++s) {
    ImuErrorModel m(spec, 500 + s);
    double sum = 0.0;
    for (int k = 0; k < 1000; ++k) {
      const double x = m.apply({}, 0.01).dtheta_b.y();
      if (k == 500) singles.push_back(x);
      sum += x;
    }
    sums.push_back(sum);
  }
  // a single increment carries the difference of two draws (sqrt 2 sigma); the sum only the last draw
  EXPECT_NEAR(sample_std(singles), std::sqrt(2.0) * 80e-6, 0.07 * std::sqrt(2.0) * 80e-6);
  EXPECT_NEAR(sample_std(sums), 80e-6, 0.07 * 80e-6);
}

TEST(ImuAtRest, SpecificForceIsNormalGravityAndRateIsEarthRate) {
  const double lat = 36.37 * ultratrack::io::kRadPerDeg, h = 100.0, T = 60.0, rate = 100.0;
  const SimulatedRun run = simulate(profile_spec("static", T, lat, 127.36 * ultratrack::io::kRadPerDeg, h), rate);
  const double g = gravity_n(lat, h).norm();
  for (const char* preset : {"ideal", "navigation", "hg1700ae"}) {
    const ImuErrorSpec spec = imu_preset(preset);
    // 1-sigma of |mean f| and |mean w| about g and W: bias (vertical / earth-rate direction) plus noise
    const double sf =
        std::sqrt(std::pow(spec.accel.bias_sigma, 2) + std::pow(spec.accel.random_walk, 2) / T +
                  2 * std::pow(spec.accel.output_white_noise / T, 2) + std::pow(spec.accel.scale_factor_sigma * g, 2));
    const double sw = std::sqrt(std::pow(spec.gyro.bias_sigma, 2) + std::pow(spec.gyro.random_walk, 2) / T +
                                2 * std::pow(spec.gyro.output_white_noise / T, 2) +
                                std::pow(spec.gyro.scale_factor_sigma * kEarthRate_rps, 2));
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      ImuErrorModel m(spec, seed);
      Eigen::Vector3d sum_dv = Eigen::Vector3d::Zero(), sum_dth = Eigen::Vector3d::Zero();
      double t_prev = 0.0;
      for (const auto& inc : run.imu) {
        const ImuIncrement o = m.apply(inc, inc.t_s - t_prev);
        t_prev = inc.t_s;
        sum_dv += o.dv_b;
        sum_dth += o.dtheta_b;
      }
      const double f = sum_dv.norm() / T, w = sum_dth.norm() / T;
      if (seed == 1)
        std::printf("[ at rest ] %-10s |f| - g = %+.3e m/s^2 (1 sigma %.1e), |w| - W = %+.3e rad/s (1 sigma %.1e)\n",
                    preset, f - g, sf, w - kEarthRate_rps, sw);
      EXPECT_NEAR(f, g, 4 * sf + 1e-12 * g) << preset << " seed " << seed;
      EXPECT_NEAR(w, kEarthRate_rps, 4 * sw + 1e-12 * kEarthRate_rps) << preset << " seed " << seed;
    }
  }
}
