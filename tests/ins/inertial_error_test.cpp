// SPDX-License-Identifier: GPL-3.0-or-later
// Stationary INS with one injected error, against the closed-form error analysis of a local-level INS
// at the equator (where the north and east channels decouple from earth rate, so the textbook solutions
// are exact to first order). The IMU data at rest are built analytically: dtheta = C_bn w_ie^n dt,
// dv = -C_bn g^n dt. Height aiding with the true height holds the vertical channel (except in the
// vertical-channel test). Schuler frequency w_s^2 = g / (R_N + h) for the east channel.
//   east accelerometer bias b:   dE(t) = (b / w_s^2) (1 - cos w_s t)
//   initial roll error phi0:     dE(t) = phi0 (R_N + h) (1 - cos w_s t)
//   north gyro bias eps:         dE(t) = eps (R_N + h) (t - sin(w_s t) / w_s)
//   down gyro bias eps:          yaw error = eps t
//   down accelerometer bias b, free vertical channel: dh(t) = -(b / k) (cosh(sqrt(k) t) - 1), k = -dg/dh
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/strapdown.hpp"

using namespace ultratrack::ins;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRate = 50.0;

struct Injected {
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_b = Eigen::Vector3d::Zero();
  double roll_error_rad = 0.0;
  bool height_aiding = true;
};

struct Series {
  std::vector<double> t, east_m, vel_e, yaw_err, height_err;
};

Series run_static(const Injected& inj, double duration_s, double lat_rad = 0.0) {
  NavState truth;
  truth.lat_rad = lat_rad;
  truth.lon_rad = 0.5;
  truth.height_m = 0.0;
  const double dt = 1.0 / kRate;
  const Eigen::Vector3d dtheta = earth_rate_n(lat_rad) * dt + inj.gyro_bias_b * dt;  // body = NED
  const Eigen::Vector3d dv = -gravity_n(lat_rad, 0.0) * dt + inj.accel_bias_b * dt;
  NavState init = truth;
  init.q_nb = quaternion_from_euler({inj.roll_error_rad, 0.0, 0.0});
  Strapdown ins(init);
  if (inj.height_aiding) ins.set_height_aiding(truth.height_m);
  const Radii r = radii_of_curvature(lat_rad);
  Series s;
  const long n = std::lround(duration_s * kRate);
  for (long k = 1; k <= n; ++k) {
    ins.step(dtheta, dv, dt);
    if (k % 10 == 0) {
      const NavState& e = ins.state();
      s.t.push_back(e.t_s);
      s.east_m.push_back((e.lon_rad - truth.lon_rad) * (r.transverse_m + truth.height_m) * std::cos(lat_rad));
      s.vel_e.push_back(e.v_n.y());
      s.yaw_err.push_back(wrap_pi(euler_from_quaternion(e.q_nb).yaw_rad));
      s.height_err.push_back(e.height_m - truth.height_m);
    }
  }
  return s;
}

// Period from the upward and downward zero crossings of x(t) (linear interpolation), skipping t = 0.
double period_from_crossings(const std::vector<double>& t, const std::vector<double>& x) {
  std::vector<double> crossings;
  for (std::size_t i = 1; i < x.size(); ++i) {
    if ((x[i - 1] < 0.0) != (x[i] < 0.0) && t[i - 1] > 60.0)
      crossings.push_back(t[i - 1] + (t[i] - t[i - 1]) * x[i - 1] / (x[i - 1] - x[i]));
  }
  if (crossings.size() < 2) return 0.0;
  return 2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

double schuler_period_s() {
  return 2 * kPi * std::sqrt(radii_of_curvature(0.0).transverse_m / gravity_n(0.0, 0.0).z());
}

}  // namespace

TEST(StationaryInsErrors, AccelBiasGivesSchulerOscillation) {
  const double g = gravity_n(0.0, 0.0).z(), b = 1e-4 * g;
  Injected inj;
  inj.accel_bias_b.y() = b;
  const double T = schuler_period_s();
  const Series s = run_static(inj, 2.05 * T);
  const double measured_T = period_from_crossings(s.t, s.vel_e);
  double peak = 0.0;
  for (double x : s.east_m) peak = std::max(peak, x);
  const double ws2 = std::pow(2 * kPi / T, 2);
  std::printf(
      "[ schuler ] accel bias %.3e m/s^2: period %.3f min (closed form %.3f min), peak east error %.1f m "
      "(closed form 2 b / w_s^2 = %.1f m)\n",
      b, measured_T / 60, T / 60, peak, 2 * b / ws2);
  EXPECT_NEAR(measured_T, T, 0.002 * T);
  EXPECT_NEAR(measured_T / 60.0, 84.4, 0.5);  // the textbook 84.4 min (R = 6371 km, g = 9.81) within 0.6 %
  EXPECT_NEAR(peak, 2 * b / ws2, 0.005 * 2 * b / ws2);
  // the whole curve, not just its peak
  for (std::size_t i = 0; i < s.t.size(); i += 50)
    EXPECT_NEAR(s.east_m[i], b / ws2 * (1 - std::cos(2 * kPi * s.t[i] / T)), 0.005 * 2 * b / ws2) << s.t[i];
}

TEST(StationaryInsErrors, InitialTiltGivesSchulerOscillation) {
  const double phi0 = 1e-4;
  Injected inj;
  inj.roll_error_rad = phi0;
  const double T = schuler_period_s();
  const Series s = run_static(inj, 2.05 * T);
  const double measured_T = period_from_crossings(s.t, s.vel_e);
  const double R = radii_of_curvature(0.0).transverse_m;
  double peak = 0.0;
  for (double x : s.east_m) peak = std::max(peak, x);
  std::printf(
      "[ schuler ] initial roll error %.1e rad: period %.3f min, peak east error %.1f m (closed form 2 phi0 R = %.1f "
      "m)\n",
      phi0, measured_T / 60, peak, 2 * phi0 * R);
  EXPECT_NEAR(measured_T, T, 0.002 * T);
  EXPECT_NEAR(peak, 2 * phi0 * R, 0.005 * 2 * phi0 * R);
}

TEST(StationaryInsErrors, NorthGyroBiasGivesRampPlusSchuler) {
  const double eps = 0.01 * kPi / 180.0 / 3600.0;  // 0.01 deg/h
  Injected inj;
  inj.gyro_bias_b.x() = eps;
  const double T = schuler_period_s();
  const Series s = run_static(inj, 1.5 * T);
  const double R = radii_of_curvature(0.0).transverse_m, w = 2 * kPi / T;
  double worst = 0.0;
  for (std::size_t i = 0; i < s.t.size(); ++i) {
    const double predicted = eps * R * (s.t[i] - std::sin(w * s.t[i]) / w);
    worst = std::max(worst, std::fabs(s.east_m[i] - predicted));
  }
  const double at_T = eps * R * T;
  std::printf(
      "[ schuler ] north gyro bias 0.01 deg/h: east error after one Schuler period %.1f m (closed form eps R T = %.1f "
      "m), "
      "worst deviation from eps R (t - sin(w t)/w) %.2f m\n",
      s.east_m[static_cast<std::size_t>(T / (s.t[1] - s.t[0])) - 1], at_T, worst);
  EXPECT_LT(worst, 0.005 * 1.5 * at_T);
}

TEST(StationaryInsErrors, DownGyroBiasGivesHeadingDrift) {
  const double eps = 1.0 * kPi / 180.0 / 3600.0;  // 1 deg/h
  Injected inj;
  inj.gyro_bias_b.z() = eps;
  const Series s = run_static(inj, 1200.0);
  const double drift = s.yaw_err.back() / s.t.back();
  std::printf("[ heading ] down gyro bias 1 deg/h: yaw drift %.5f deg/h over 20 min\n", drift * 180 / kPi * 3600);
  // coupling through earth rate enters as (W t)^2 / 6 ~ 0.1 % over 20 min
  EXPECT_NEAR(drift, eps, 0.003 * eps);
}

TEST(StationaryInsErrors, FreeVerticalChannelDivergesAsClosedForm) {
  const double b = 1e-4;  // down accelerometer bias, m/s^2
  Injected inj;
  inj.accel_bias_b.z() = b;
  inj.height_aiding = false;
  const Series s = run_static(inj, 1800.0);
  const double k = -(gravity_n(0.0, 1.0).z() - gravity_n(0.0, -1.0).z()) / 2.0;  // 2 g / R class gradient
  const double predicted = -(b / k) * (std::cosh(std::sqrt(k) * s.t.back()) - 1.0);
  std::printf("[ vertical ] free channel, 1e-4 m/s^2 bias, 30 min: height error %.2f m (closed form %.2f m)\n",
              s.height_err.back(), predicted);
  EXPECT_NEAR(s.height_err.back(), predicted, 0.01 * std::fabs(predicted));
}

TEST(StationaryInsErrors, HeightAidingHoldsTheVerticalChannel) {
  const double b = 1e-3;
  Injected inj;
  inj.accel_bias_b.z() = b;
  const Series s = run_static(inj, 1800.0);
  double late = 0.0;
  for (std::size_t i = s.t.size() / 2; i < s.t.size(); ++i) late = std::max(late, std::fabs(s.height_err[i]));
  std::printf("[ vertical ] aided channel with 1e-3 m/s^2 bias: |height error| after 15 min < %.2e m\n", late);
  EXPECT_LT(late, 1e-3);  // third-order loop: steady-state error to a constant bias is zero
}
