// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight period measurement models (fusion/ultratight_measurement_models.hpp): h against closed forms (the
// triangle R(tau) = 1 - |tau| with sinc(pi df T) and the start phase; the replica errors of clock-only states), the
// analytic H against central differences of h at strong and weak signals, code errors near 0 and near +-d, start
// phases across (-pi, pi] and a moving, turning receiver with a lever arm; the noise terms of R against the
// numerical tap derivatives they stand for; the period geometry (span, offset) against quadrature.
#include "fusion/ultratight_measurement_models.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kChip = signals::kSpeedOfLight_mps / signals::kCaChipRate_hz;  // 293.05 m
constexpr double kLambda = signals::kL1Wavelength_m;                            // 0.1903 m
constexpr double kEarthRadius_m = 6.37e6;

// A receiver at 210 m/s, climbing, turning at 0.3 rad/s, with a 1.4 m lever arm; one satellite at 20,200 km
// altitude in the direction (azimuth, elevation), moving at 3.1 km/s across the line of sight.
struct Geometry {
  NominalState nominal;
  SatelliteObservable sat;
  Eigen::Vector3d lever_b{0.8, 0.1, -1.1};
  Eigen::Vector3d w_ib_b{0.05, -0.02, 0.3};
};

Geometry moving_geometry(double azimuth_rad, double elevation_rad) {
  Geometry g;
  ins::NavState& nav = g.nominal.nav;
  nav.lat_rad = 47.1 * kPi / 180.0;
  nav.lon_rad = 8.5 * kPi / 180.0;
  nav.height_m = 2400.0;
  nav.v_n = Eigen::Vector3d(-35.0, 210.0, -4.0);
  nav.q_nb = ins::quaternion_from_euler({0.3, 0.05, 2.0});
  g.nominal.clock_bias_m = 23456.0;
  g.nominal.clock_drift_mps = 80.0;
  g.nominal.accel_bias_b = Eigen::Vector3d(2e-3, -1e-3, 4e-3);
  g.nominal.gyro_bias_b = Eigen::Vector3d(1e-5, -3e-5, 2e-5);
  const Eigen::Vector3d r_e = ins::ecef_from_geodetic(nav.lat_rad, nav.lon_rad, nav.height_m);
  const Eigen::Matrix3d C_en = ins::C_en(nav.lat_rad, nav.lon_rad);
  const Eigen::Vector3d u_n(std::cos(elevation_rad) * std::cos(azimuth_rad),
                            std::cos(elevation_rad) * std::sin(azimuth_rad), -std::sin(elevation_rad));
  const Eigen::Vector3d u_e = C_en * u_n;
  g.sat.prn = 5;
  g.sat.r_sat_e = r_e + 2.3e7 * u_e;
  g.sat.v_sat_e = 3100.0 * u_e.cross(Eigen::Vector3d::UnitZ()).normalized();
  g.sat.elevation_rad = elevation_rad;
  g.sat.azimuth_rad = azimuth_rad;
  g.sat.has_rate = true;
  return g;
}

// An error state along which the replica errors are linear and without cross terms with the other states
// (velocity, accelerometer bias, clock; the velocity's only cross term, with the attitude through the transport
// rate in the lever-arm velocity, is |dv| |l| / R_earth = 7e-8 m/s per rad): H, taken at the nominal, is then the
// derivative of h there too. A gyro-bias error would not do: the lever-arm velocity C ((w_ib - bg) x l) is bilinear
// in it and the attitude (a 3e-5 rad/s error moves the attitude columns by 1e-4 of their rate entries).
StateVector<17> linear_state() {
  StateVector<17> dx = StateVector<17>::Zero();
  dx.segment<3>(ix::kVel) << 0.3, -0.2, 0.1;
  dx.segment<3>(ix::kAccelBias) << 1e-3, 2e-3, -1e-3;
  dx(ix::kClockBias) = 4.0;
  dx(ix::kClockDrift) = -0.3;
  return dx;
}

IqSettings iq_settings(double cn0_dbhz, double T, double d, double lag1 = 0.0) {
  IqSettings s;
  s.cn0_dbhz = cn0_dbhz;
  s.integration_time_s = T;
  s.tap_offset_chips = d;
  s.code_lag1_correlation = lag1;
  return s;
}

// Central-difference steps (state units). Each moves the period's range error by <= 0.14 m (5e-4 chip) or its
// rate error by <= 1e-3 m/s (x = pi df T by <= 3.3e-4 rad at T = 20 ms).
StateVector<17> steps() {
  StateVector<17> h;
  h << 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-5, 1e-5, 1e-5, 0.1, 1e-3;
  return h;
}

// Rounding of the replica errors per evaluation: the range is a difference of 2.3e7 m ECEF coordinates (one ulp
// 3.7e-9 m), 1e-8 m; it only changes for states that move the antenna (position, attitude through the lever arm)
// or the clock bias; the rate (~3e3 m/s, one ulp 4.5e-13 m/s), 1e-12 m/s.
bool moves_range(int j) { return j < ix::kPos + 3 || (j >= ix::kAtt && j < ix::kAtt + 3) || j == ix::kClockBias; }
constexpr double kRangeRounding_m = 1e-8, kRateRounding_mps = 1e-12;

// Curvature of the replica errors along a column (per state unit, m or m/s), third-derivative bound times
// h^2 / 6: the lever arm turning with the attitude, |l| (range) and |l| (|w_ib| + |w_in|) (rate); the others are
// linear (velocity, biases, clock) or curved by 1 / rho^2 (position, < 1e-15).
double replica_truncation(int j, const Geometry& g) {
  if (j < ix::kAtt || j >= ix::kAtt + 3) return 0.0;
  return g.lever_b.norm() * (1.0 + g.w_ib_b.norm() + 1e-3) * steps()(j) * steps()(j) / 6.0;
}

// The replica Jacobian also leaves out the receiver's share of the travel-time rate (predicted_range_rate_mps): d rate
// / d v_ant gains u (u . (v_sat + w_e x r_sat)) / c, a fraction <= (|v_sat| + w_e |r_sat|) / c (1.7e-5 here) of the
// rate entry of every column that moves the antenna velocity (velocity, attitude through the lever arm, gyro bias).
bool moves_antenna_velocity(int j) {
  return (j >= ix::kVel && j < ix::kVel + 3) || (j >= ix::kAtt && j < ix::kAtt + 3) ||
         (j >= ix::kGyroBias && j < ix::kGyroBias + 3);
}
double travel_time_fraction(const SatelliteObservable& sat) {
  return (sat.v_sat_e.norm() + 7.2921151467e-5 * sat.r_sat_e.norm()) / signals::kSpeedOfLight_mps;
}

// The replica Jacobian leaves out the rotation of the antenna velocity with position, |v_ant| / R_earth (m/s) per
// metre in the rate row (tight_measurements.hpp), taken at twice |v_n| + |w x l|.
double position_omission(int j, const Geometry& g) {
  if (j >= ix::kPos + 3) return 0.0;
  return 2.0 * (g.nominal.nav.v_n.norm() + g.w_ib_b.cross(g.lever_b).norm()) / kEarthRadius_m;
}

template <class F>
Eigen::MatrixXd central_difference(const F& f, const StateVector<17>& x, int rows) {
  Eigen::MatrixXd J(rows, 17);
  const StateVector<17> h = steps();
  for (int j = 0; j < 17; ++j) {
    StateVector<17> p = x, m = x;
    p(j) += h(j);
    m(j) -= h(j);
    J.col(j) = (f(p) - f(m)) / (2.0 * h(j));
  }
  return J;
}

// The period errors' sensitivity to each state, from central differences of PeriodIqMeasurement::errors:
// s_j = |d code / d x_j| (chips) + pi T |d frequency / d x_j| (rad of x = pi df T).
Eigen::Matrix<double, 1, 17> error_sensitivity(const PeriodIqMeasurement& m, const StateVector<17>& x, double T) {
  const auto f = [&](const StateVector<17>& y) {
    const TrackingErrors e = m.errors(y);
    return Eigen::Vector2d(e.code_chips, kPi * T * e.frequency_hz);
  };
  return central_difference(f, x, 2).cwiseAbs().colwise().sum();
}

// Tolerance of one column (tap units per state unit) for the I&Q form. The taps are A R(tau - o) g(x) with g(x) =
// sinc(x) exp(i (phi + x)) = exp(i phi) int_0^1 exp(2 i x s) ds, so |g^(n)| <= 2^n / (n + 1) (|g'| <= 1).
//  - Truncation, code: R is piecewise linear and no step crosses a corner (the operating points stay >= 0.03 chip
//    from every corner, a step moves tau by <= 5e-4 chip): 0. Frequency: h^2 / 6 |t'''| <= A s_j (dx)^2 / 3 with
//    dx <= 3.3e-4 the step in x: < 4e-8 A s_j. With the replica errors' own curvature (replica_truncation, through
//    1 / chip and pi T / lambda): within 1e-6 A s_j + A (1 / chip + pi T / lambda) replica_truncation.
//  - Rounding (kRangeRounding_m, kRateRounding_mps) through 1 / chip and pi T / lambda, over 2 h_j, doubled.
//  - Position columns: position_omission through pi T / lambda |g'| <= pi T / lambda; columns that move the antenna
//    velocity: travel_time_fraction of their sensitivity, A s_j.
double column_tolerance(int j, double A, double s_j, double T, const Geometry& g) {
  const double h = steps()(j), per_m_code = 1.0 / kChip, per_mps_x = kPi * T / kLambda;
  const double travel = moves_antenna_velocity(j) ? travel_time_fraction(g.sat) : 0.0;
  return A * ((1e-6 + travel) * s_j + (per_m_code + per_mps_x) * replica_truncation(j, g) +
              ((moves_range(j) ? kRangeRounding_m * per_m_code : 0.0) + kRateRounding_mps * per_mps_x) / h +
              per_mps_x * position_omission(j, g));
}

// Columns swapped or sign-flipped would fail: every non-zero column differs from its negative and from every other
// column by far more than the tolerance.
void expect_columns_distinguishable(const Eigen::MatrixXd& N, const std::vector<double>& tol, const std::string& what) {
  for (int i = 0; i < N.cols(); ++i) {
    if (N.col(i).cwiseAbs().maxCoeff() <= 1e-12) continue;  // the accelerometer-bias columns: h does not depend on them
    EXPECT_GT(2.0 * N.col(i).cwiseAbs().maxCoeff(), 20.0 * tol[i]) << what << " col " << i;
    for (int j = 0; j < N.cols(); ++j)
      if (j != i) {
        EXPECT_GT((N.col(i) - N.col(j)).cwiseAbs().maxCoeff(), 3.0 * tol[i]) << what << " cols " << i << "," << j;
      }
  }
}

struct OperatingPoint {
  double cn0_dbhz, T, d, lag1;
  double tau_chips, df_hz, phase_rad;
};

// Strong (50 dB-Hz, A = 63) and weak (25 dB-Hz, A = 3.6 at 20 ms) signals; code errors near the prompt's peak and
// within 0.03-0.04 chip of the early/late peaks (+-d); start phases across (-pi, pi]; 1 to 20 ms; the C/A code's
// own one-chip correlation (PRN 15's +63/1023) in one case.
const std::array<OperatingPoint, 8> kPoints{{
    {50.0, 0.020, 0.5, 0.0, 0.03, 2.0, 0.0},
    {50.0, 0.020, 0.5, 0.0, -0.04, -7.0, 2.5},
    {50.0, 0.020, 0.5, 63.0 / 1023.0, 0.47, 12.0, -1.2},
    {50.0, 0.005, 0.25, 0.0, -0.22, -20.0, 3.1},
    {25.0, 0.020, 0.5, 0.0, 0.03, -1.5, -3.0},
    {25.0, 0.020, 0.5, 0.0, -0.46, 20.0, 1.6},
    {25.0, 0.020, 0.5, 0.0, 0.2, 0.0, -0.4},
    {35.0, 0.001, 0.5, 0.0, 0.45, 150.0, 0.9},
}};

// The measurement at dx = x with its period errors placed at the operating point: the offset is what is left of
// (tau chip, df lambda) after the replica errors of x.
PeriodIqMeasurement iq_at(const Geometry& g, const OperatingPoint& op, const StateVector<17>& x, double span_s,
                          double prior_code_sigma_chips = 0.0) {
  const IqSettings s = iq_settings(op.cn0_dbhz, op.T, op.d, op.lag1);
  IqPeriodOptions period;
  period.span_s = span_s;
  period.start_phase_rad = op.phase_rad;
  const PeriodIqMeasurement bare(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, period);
  const TrackingErrors e = bare.errors(x);
  period.offset = Eigen::Vector2d((op.tau_chips - e.code_chips) * kChip, (op.df_hz - e.frequency_hz) * kLambda);
  period.prior_code_sigma_chips = prior_code_sigma_chips;
  return PeriodIqMeasurement(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, period);
}

TEST(UltraTightIqPeriod, JacobianMatchesCentralDifferences) {
  for (const auto& [az, el] : {std::pair{0.3, 1.1}, std::pair{3.5, 0.2}}) {
    const Geometry g = moving_geometry(az, el);
    for (const StateVector<17>& x : {StateVector<17>(StateVector<17>::Zero()), linear_state()}) {
      for (const double span : {0.02, 0.047}) {
        for (const OperatingPoint& op : kPoints) {
          const PeriodIqMeasurement m = iq_at(g, op, x, span * op.T / 0.02);
          const TrackingErrors e = m.errors(x);
          ASSERT_NEAR(e.code_chips, op.tau_chips, 1e-9);
          ASSERT_NEAR(e.frequency_hz, op.df_hz, 1e-9);
          const double A = iq_amplitude(iq_settings(op.cn0_dbhz, op.T, op.d));
          const Eigen::MatrixXd N = central_difference([&](const StateVector<17>& y) { return m.h(y); }, x, 6);
          const MeasurementJacobian<17> H = m.H(x);
          const Eigen::Matrix<double, 1, 17> s = error_sensitivity(m, x, op.T);
          std::vector<double> tol(17);
          for (int j = 0; j < 17; ++j) {
            tol[j] = column_tolerance(j, A, s(j), op.T, g);
            for (int r = 0; r < 6; ++r)
              EXPECT_NEAR(H(r, j), N(r, j), tol[j])
                  << "el " << el << " tau " << op.tau_chips << " df " << op.df_hz << " row " << r << " col " << j;
          }
          expect_columns_distinguishable(N, tol, "I&Q el " + std::to_string(el));
        }
      }
    }
  }
}

// h at one point against the closed form, with the replica errors of a clock-only state written out: a clock
// bias error b (estimate minus truth) makes the replica b metres late (range error +b), a drift error d a rate
// error +d; over the period the taps see the mean range error b - d span / 2 plus the offset.
TEST(UltraTightIqPeriod, PredictionIsTheTriangleTimesSincAtOnePoint) {
  const Geometry g = moving_geometry(0.7, 1.1);
  const IqSettings s = iq_settings(42.0, 0.02, 0.5);
  IqPeriodOptions period;
  period.offset = Eigen::Vector2d(12.0, 0.9);  // m, m/s
  period.span_s = 0.034;
  period.start_phase_rad = 0.8;
  const PeriodIqMeasurement m(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, period);
  StateVector<17> x = StateVector<17>::Zero();
  x(ix::kClockBias) = 40.0;
  x(ix::kClockDrift) = 1.1;
  const double tau = (40.0 - 1.1 * 0.034 / 2.0 + 12.0) / kChip;  // 0.1774 chip
  const double df = (1.1 + 0.9) / kLambda;                       // 10.51 Hz
  const double xf = kPi * df * 0.02, sinc = std::sin(xf) / xf;
  const double A = std::sqrt(2.0 * std::pow(10.0, 4.2) * 0.02);
  const double offsets[3] = {0.5, 0.0, -0.5};  // E, P, L: the early replica d chips ahead
  const Eigen::Matrix<double, 6, 1> t = m.h(x);
  for (int k = 0; k < 3; ++k) {
    const double R = 1.0 - std::abs(tau - offsets[k]);
    EXPECT_NEAR(t(k), A * R * sinc * std::cos(0.8 + xf), 1e-9 * A) << k;
    EXPECT_NEAR(t(3 + k), A * R * sinc * std::sin(0.8 + xf), 1e-9 * A) << k;
  }
  // Signs: the signal leads (tau > 0), so the early tap is the larger; df > 0 turns the prompt counter-clockwise
  // from the start phase.
  EXPECT_GT(std::hypot(t(0), t(3)), std::hypot(t(2), t(5)));
  EXPECT_GT(std::atan2(t(4), t(1)), 0.8);
}

// The prompt rows' code column is weighted by erf(|tau| / (sqrt 2 sigma)): the expected slope of R over the prior
// tau ~ N(guess, sigma^2). Checked against that expectation by quadrature, then in H's clock-bias column (which
// enters through the code alone: H(:, bias) = dtaps / dtau / chip).
TEST(UltraTightIqPeriod, PromptSlopeIsTheExpectedSlopeOverThePrior) {
  for (const double guess : {0.01, -0.03, 0.2}) {
    for (const double sigma : {0.02, 0.1}) {
      // E[R'(tau)] for R = 1 - |tau| near the peak: P(tau < 0) - P(tau > 0) = 1 - 2 P(tau > 0), P by Simpson's rule
      // over [max(0, guess - 8 sigma), guess + 8 sigma] (smooth integrand: error < 1e-12 at n = 2000).
      const double lo = std::max(0.0, guess - 8.0 * sigma), hi = guess + 8.0 * sigma;
      const int n = 2000;
      const double du = (hi - lo) / n;
      double p_positive = 0.0;
      for (int i = 0; i <= n; ++i) {
        const double tau = lo + i * du;
        const double pdf = std::exp(-0.5 * std::pow((tau - guess) / sigma, 2)) / (std::sqrt(2.0 * kPi) * sigma);
        p_positive += (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0)) * pdf * du / 3.0;
      }
      const double expected = 1.0 - 2.0 * p_positive;
      const double local = guess > 0.0 ? -1.0 : 1.0;
      EXPECT_NEAR(local * prompt_code_slope_weight(guess, sigma), expected, 1e-6) << guess << " " << sigma;
    }
  }
  EXPECT_EQ(prompt_code_slope_weight(0.3, 0.0), 1.0);
  const Geometry g = moving_geometry(0.7, 1.1);
  const OperatingPoint op{45.0, 0.02, 0.5, 0.0, 0.015, 3.0, 0.4};
  const StateVector<17> x = linear_state();
  const PeriodIqMeasurement plain = iq_at(g, op, x, 0.02), weighted = iq_at(g, op, x, 0.02, 0.05);
  const double w = std::erf(0.015 / (std::sqrt(2.0) * 0.05));  // 0.236
  const Eigen::MatrixXd N = central_difference([&](const StateVector<17>& y) { return plain.h(y); }, x, 6);
  const MeasurementJacobian<17> Hw = weighted.H(x), Hp = plain.H(x);
  for (int r = 0; r < 6; ++r) {
    const double factor = (r == 1 || r == 4) ? w : 1.0;
    EXPECT_NEAR(Hw(r, ix::kClockBias), factor * N(r, ix::kClockBias),
                1e-6 * iq_amplitude(iq_settings(45, 0.02, 0.5)) / kChip)
        << r;
    if (r != 1 && r != 4) {
      EXPECT_EQ(Hw.row(r), Hp.row(r)) << r;
    }
  }
  EXPECT_EQ(weighted.h(x), plain.h(x));  // the weight is in H only
}

// R's extra terms are var g g' with g the taps' derivative along the noise: the rate error (clock frequency noise
// within the period) and the start phase. g here by central differences of h in the offset's rate and in the start
// phase (steps 1e-4 m/s and 1e-5 rad; the taps' second derivatives are <= A (pi T / lambda)^2 and A, so the
// difference error is < 1e-8 A per unit).
TEST(UltraTightIqPeriod, NoiseTermsFollowTheTapDerivatives) {
  const Geometry g = moving_geometry(3.9, 0.25);
  const IqSettings s = iq_settings(38.0, 0.02, 0.5);
  const double A = iq_amplitude(s);
  IqPeriodOptions base;
  base.offset = Eigen::Vector2d(20.0, -1.3);
  base.span_s = 0.02;
  base.start_phase_rad = -2.2;
  auto taps = [&](const IqPeriodOptions& p) {
    return PeriodIqMeasurement(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, p).h(StateVector<17>::Zero());
  };
  IqPeriodOptions up = base, down = base;
  up.offset(1) += 1e-4;
  down.offset(1) -= 1e-4;
  const Eigen::Matrix<double, 6, 1> g_rate = (taps(up) - taps(down)) / 2e-4;
  up = base;
  down = base;
  up.start_phase_rad += 1e-5;
  down.start_phase_rad -= 1e-5;
  const Eigen::Matrix<double, 6, 1> g_phase = (taps(up) - taps(down)) / 2e-5;
  IqPeriodOptions noisy = base;
  noisy.clock_rate_var_m2ps2 = 0.04;
  noisy.start_phase_var_rad2 = 0.09;
  const PeriodIqMeasurement m(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, noisy);
  const Eigen::Matrix<double, 6, 6> expected =
      iq_noise_covariance(s) + 0.04 * g_rate * g_rate.transpose() + 0.09 * g_phase * g_phase.transpose();
  EXPECT_LT((m.R() - expected).cwiseAbs().maxCoeff(), 1e-6 * A * A);
  // Without them R is the taps' thermal covariance, unit diagonal.
  const PeriodIqMeasurement quiet(g.nominal, g.sat, g.lever_b, g.w_ib_b, s, IqTaps{}, base);
  EXPECT_EQ(quiet.R(), iq_noise_covariance(s));
  EXPECT_EQ(quiet.R()(1, 1), 1.0);
}

TEST(UltraTightIqPeriod, MeasuredTapsAreZInRowOrder) {
  const Geometry g = moving_geometry(0.7, 1.1);
  IqTaps t;
  t.i = {1.0, 2.0, 3.0};
  t.q = {4.0, 5.0, 6.0};
  const PeriodIqMeasurement m(g.nominal, g.sat, g.lever_b, g.w_ib_b, iq_settings(40, 0.02, 0.5), t, {});
  EXPECT_EQ(m.z(), (Eigen::Matrix<double, 6, 1>() << 1, 2, 3, 4, 5, 6).finished());
}

// The discriminator form is linear in the replica errors: h(dx) = M e(dx) + offset. Tolerance per column (m or
// m/s per state unit): the replica errors' rounding over 2 h_j (doubled) and curvature (replica_truncation), and
// the replica Jacobian's omissions: position_omission in the rate row, travel_time_fraction of the column.
TEST(UltraTightDiscriminatorPeriod, JacobianMatchesCentralDifferences) {
  for (const auto& [az, el] : {std::pair{0.3, 1.1}, std::pair{3.5, 0.2}}) {
    const Geometry g = moving_geometry(az, el);
    for (const StateVector<17>& x : {StateVector<17>(StateVector<17>::Zero()), linear_state()}) {
      const PeriodDiscriminatorMeasurement m(g.nominal, g.sat, g.lever_b, g.w_ib_b, Eigen::Vector2d(3.0, -0.2), 0.03,
                                             Eigen::Vector2d::Zero(), DiscriminatorNoise{}, 0.0, 0.0);
      const Eigen::MatrixXd N = central_difference([&](const StateVector<17>& y) { return m.h(y); }, x, 2);
      const MeasurementJacobian<17> H = m.H(x);
      std::vector<double> tol(17);
      for (int j = 0; j < 17; ++j) {
        tol[j] = ((moves_range(j) ? kRangeRounding_m : 0.0) + kRateRounding_mps) / steps()(j) +
                 replica_truncation(j, g) + position_omission(j, g) +
                 (moves_antenna_velocity(j) ? travel_time_fraction(g.sat) * N.col(j).cwiseAbs().maxCoeff() : 0.0);
        for (int r = 0; r < 2; ++r)
          EXPECT_NEAR(H(r, j), N(r, j), tol[j]) << "el " << el << " row " << r << " col " << j;
      }
      expect_columns_distinguishable(N, tol, "discriminator el " + std::to_string(el));
    }
  }
}

// The chain's first link for several satellites at once: ReplicaErrors17 through DiscriminatorEpochMeasurement17
// (the covariance analysis' discriminator form), with and without the rate rows, same steps and tolerances. The
// rows are replica minus signal: a clock bias error b gives +b in every range row, a drift error d +d in every
// rate row (so a sign error or a swapped bias / drift column fails the first check).
TEST(UltraTightDiscriminatorPeriod, EpochReplicaErrorsJacobianMatchesCentralDifferences) {
  const Geometry a = moving_geometry(0.7, 1.1), b = moving_geometry(3.9, 0.25), c = moving_geometry(2.2, 0.6);
  const std::vector<SatelliteObservable> sats{a.sat, b.sat, c.sat};
  for (const bool rate : {true, false}) {
    const DiscriminatorEpochMeasurement17 m(a.nominal, sats, a.lever_b, a.w_ib_b, Eigen::VectorXd::Zero(6), 5.0, 0.1,
                                            rate);
    const int rows = rate ? 6 : 3;
    ASSERT_EQ(m.size(), rows);
    for (const StateVector<17>& x : {StateVector<17>(StateVector<17>::Zero()), linear_state()}) {
      const Eigen::MatrixXd N = central_difference([&](const StateVector<17>& y) { return m.h(y); }, x, rows);
      const MeasurementJacobian<17> H = m.H(x);
      std::vector<double> tol(17);
      for (int j = 0; j < 17; ++j) {
        const double travel =
            std::max({travel_time_fraction(a.sat), travel_time_fraction(b.sat), travel_time_fraction(c.sat)});
        tol[j] = ((moves_range(j) ? kRangeRounding_m : 0.0) + kRateRounding_mps) / steps()(j) +
                 replica_truncation(j, a) + position_omission(j, a) +
                 (moves_antenna_velocity(j) ? travel * N.col(j).cwiseAbs().maxCoeff() : 0.0);
        for (int r = 0; r < rows; ++r)
          EXPECT_NEAR(H(r, j), N(r, j), tol[j]) << "rate " << rate << " row " << r << " col " << j;
      }
      expect_columns_distinguishable(N, tol, rate ? "epoch with rates" : "epoch, ranges only");
    }
    StateVector<17> clock = StateVector<17>::Zero();
    clock(ix::kClockBias) = 2.5;
    clock(ix::kClockDrift) = -0.4;
    const Eigen::VectorXd h = m.h(clock);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(h(rate ? 2 * i : i), 2.5, 1e-7) << i;
      if (rate) {
        EXPECT_NEAR(h(2 * i + 1), -0.4, 1e-10) << i;
      }
    }
  }
}

// h of a clock-only state in closed form (as for the I&Q form), and z's noise.
TEST(UltraTightDiscriminatorPeriod, PredictionAndNoiseInClosedForm) {
  const Geometry g = moving_geometry(3.9, 0.25);
  DiscriminatorNoise noise;
  noise.range_sigma_m = 7.0;
  noise.rate_sigma_mps = 0.3;
  const PeriodDiscriminatorMeasurement m(g.nominal, g.sat, g.lever_b, g.w_ib_b, Eigen::Vector2d(-5.0, 0.25), 0.026,
                                         Eigen::Vector2d(1.0, 2.0), noise, 0.01, 0.02);
  StateVector<17> x = StateVector<17>::Zero();
  x(ix::kClockBias) = -12.0;
  x(ix::kClockDrift) = 0.7;
  const Eigen::VectorXd h = m.h(x);
  EXPECT_NEAR(h(0), -12.0 - 0.7 * 0.026 / 2.0 - 5.0, 1e-7);
  EXPECT_NEAR(h(1), 0.7 + 0.25, 1e-9);
  EXPECT_EQ(m.z(), Eigen::Vector2d(1.0, 2.0));
  const Eigen::MatrixXd R = m.R();
  EXPECT_DOUBLE_EQ(R(0, 0), 49.0);
  EXPECT_DOUBLE_EQ(R(1, 1), 0.09 + 0.01 + 0.02);
  EXPECT_EQ(R(0, 1), 0.0);
  EXPECT_EQ(R(1, 0), 0.0);
}

// The discriminators read noise-free taps back as the period errors: the NELP is exact for the triangle within
// +-d (its float arithmetic: < 1e-6 chip), the prompt's phase is start phase + pi df T, and the start phase comes
// off. A start phase error of delta rad moves the rate by lambda delta / (pi T), whence its variance.
TEST(UltraTightDiscriminatorPeriod, DiscriminatorsReadTheTapsBack) {
  for (const double T : {0.02, 0.005}) {
    const IqSettings s = iq_settings(40.0, T, 0.5);
    for (const TrackingErrors e :
         {TrackingErrors{0.12, 4.0, 0.7}, TrackingErrors{-0.3, -9.0, -2.0}, TrackingErrors{0.02, 0.5, 2.9}}) {
      const Eigen::Vector2d z = period_discriminator_errors(expected_iq(e, s), s, e.phase_rad);
      EXPECT_NEAR(z(0), e.code_chips * kChip, 1e-6 * kChip) << T;
      EXPECT_NEAR(z(1), e.frequency_hz * kLambda, 1e-9) << T;
      const double delta = 1e-3;
      const double moved = period_discriminator_errors(expected_iq(e, s), s, e.phase_rad - delta)(1);
      const double per_rad = (moved - z(1)) / delta;
      EXPECT_NEAR(per_rad, kLambda / (kPi * T), 1e-6 * kLambda / (kPi * T));
      EXPECT_NEAR(start_phase_rate_variance(0.05, T), per_rad * per_rad * 0.05, 1e-6 * per_rad * per_rad * 0.05);
    }
  }
}

// The mixing: a rate error held over the period moves the range error linearly, so the mean over [t0, t0 + T]
// of e0 + e1 (t - t_u) is e0 - e1 (t_u - t0 - T / 2) = e0 - e1 span / 2 with span = 2 (t_u - t0) - T.
TEST(UltraTightPeriodGeometry, SpanPlacesTheMeanRangeAtThePeriodsMiddle) {
  const double t0 = 10.0, T = 0.02, tu = 10.031;
  const double span = period_span_s(tu, t0, T);
  EXPECT_NEAR(span, 2.0 * 0.031 - 0.02, 1e-12);
  const Eigen::Vector2d e(3.0, -0.8);
  const Eigen::Vector2d p = period_mixing(span) * e;
  EXPECT_NEAR(p(0), 3.0 + (-0.8) * (t0 + T / 2.0 - tu), 1e-12);
  EXPECT_EQ(p(1), -0.8);
}

// The offset of the replica that ran (start range, constant rate) from a signal whose rate changes linearly, with
// the signal's prediction at an update time 13 ms after the period's end: the mean range error over the period and
// the rate error at T / 3, by Simpson's rule (exact for the quadratic range) and the linear rate.
TEST(UltraTightPeriodGeometry, OffsetIsTheMeanRangeErrorAndTheRateErrorAtAThird) {
  const double t0 = 4.0, T = 0.02, tu = t0 + T + 0.013;
  const double rho_u = 2.1e7 + 123.4, rate_u = -612.5, slope = 3.7;  // signal at t_u: m, m/s, m/s^2
  const double replica_start = 2.1e7 + 140.0, replica_rate = -612.3;
  auto signal_range = [&](double t) { return rho_u + rate_u * (t - tu) + 0.5 * slope * (t - tu) * (t - tu); };
  auto signal_rate = [&](double t) { return rate_u + slope * (t - tu); };
  auto error = [&](double t) { return replica_start + replica_rate * (t - t0) - signal_range(t); };
  const double mean = (error(t0) + 4.0 * error(t0 + T / 2.0) + error(t0 + T)) / 6.0;
  const Eigen::Vector2d o = period_signal_offset(replica_start, replica_rate, t0, T, tu, rho_u, rate_u, slope);
  EXPECT_NEAR(o(0), mean, 1e-7);  // 2.1e7 m ranges: a few ulps
  EXPECT_NEAR(o(1), replica_rate - signal_rate(t0 + T / 3.0), 1e-10);
}

// The prior code sigma: the clock-bias state moves the range one to one, the drift by -span / 2 through the mean.
TEST(UltraTightPeriodGeometry, PriorCodeSigmaFromTheClockStates) {
  const Geometry g = moving_geometry(0.7, 1.1);
  const ReplicaErrors17 rep(g.nominal, {g.sat}, g.lever_b, g.w_ib_b);
  StateMatrix<17> P = StateMatrix<17>::Zero();
  P(ix::kClockBias, ix::kClockBias) = 9.0;
  EXPECT_NEAR(prior_code_sigma_chips(rep, P, 0.03), 3.0 / kChip, 1e-12 / kChip);
  P.setZero();
  P(ix::kClockDrift, ix::kClockDrift) = 4.0;
  EXPECT_NEAR(prior_code_sigma_chips(rep, P, 0.03), 2.0 * 0.015 / kChip, 1e-12 / kChip);
  P(ix::kClockBias, ix::kClockBias) = 9.0;
  P(ix::kClockBias, ix::kClockDrift) = P(ix::kClockDrift, ix::kClockBias) = 3.0;  // correlation 1/2
  EXPECT_NEAR(prior_code_sigma_chips(rep, P, 0.03), std::sqrt(9.0 + 4.0 * 0.015 * 0.015 - 2.0 * 0.015 * 3.0) / kChip,
              1e-12 / kChip);
}

}  // namespace
}  // namespace ultratrack::fusion
