// SPDX-License-Identifier: GPL-3.0-or-later
// Seed 001 I&Q measurement model: closed forms (amplitude, eq. 7's integral, tap noise correlation from the real
// C/A code), Jacobians against numerical differentiation, the information of the linearised taps equal to the
// first-order discriminator variances, a Monte Carlo of the discriminators against their closed-form noise,
// and the 17-state measurement objects (chain rule, and the discriminator rows equal to the tight rows).
#include "fusion/iq_measurements.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <random>
#include <vector>

#include "ins/earth_model.hpp"
#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"
#include "signals/synth_kernels.hpp"

namespace {

using namespace ultratrack;
using namespace ultratrack::fusion;

constexpr double kPi = 3.14159265358979323846;

IqSettings settings(double cn0_dbhz = 45.0, double T = 0.02, double d = 0.5) {
  IqSettings s;
  s.cn0_dbhz = cn0_dbhz;
  s.integration_time_s = T;
  s.tap_offset_chips = d;
  return s;
}

TEST(IqModel, AmplitudeAndPeakValues) {
  const IqSettings s = settings(45.0, 0.02, 0.5);
  // 45 dB-Hz = 31622.8 Hz; 2 C/N0 T = 1264.9; A = 35.566
  EXPECT_NEAR(iq_amplitude(s), 35.5656, 1e-3);
  const IqTaps t = expected_iq(TrackingErrors{}, s);
  EXPECT_NEAR(t.i[1], 35.5656, 1e-3);
  EXPECT_NEAR(t.i[0], 0.5 * 35.5656, 1e-3);
  EXPECT_NEAR(t.i[2], 0.5 * 35.5656, 1e-3);
  for (double q : t.q) EXPECT_EQ(q, 0.0);
}

// The prompt is the mean of A exp(j 2 pi df s) over [0, T) ([ChoUKF] eqs. 6-7 with zero start phase):
// integrated here by Simpson's rule, independently of the sinc form.
TEST(IqModel, PromptEqualsTheIntegralOfTheRotatingPhasor) {
  const IqSettings s = settings(40.0, 0.02, 0.5);
  const double A = iq_amplitude(s);
  for (double df : {-31.0, -3.7, 0.4, 13.0, 24.0}) {
    const int n = 2000;
    double si = 0.0, sq = 0.0;
    for (int k = 0; k <= n; ++k) {
      const double w = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      const double ph = 2.0 * kPi * df * s.integration_time_s * k / n;
      si += w * std::cos(ph);
      sq += w * std::sin(ph);
    }
    si /= 3.0 * n;
    sq /= 3.0 * n;
    const double tau = 0.2;  // code error scales every tap by R(tau - o)
    const IqTaps t = expected_iq(TrackingErrors{tau, df}, s);
    EXPECT_NEAR(t.i[1], A * 0.8 * si, 1e-9 * A) << df;
    EXPECT_NEAR(t.q[1], A * 0.8 * sq, 1e-9 * A) << df;
    EXPECT_NEAR(t.i[0], A * 0.7 * si, 1e-9 * A) << df;  // early at tau - 0.5 = -0.3
    EXPECT_NEAR(t.q[2], A * 0.3 * sq, 1e-9 * A) << df;  // late at tau + 0.5 = 0.7
  }
}

Eigen::Matrix<double, 6, 1> taps_vector(const IqTaps& t) {
  Eigen::Matrix<double, 6, 1> v;
  v << t.i[0], t.i[1], t.i[2], t.q[0], t.q[1], t.q[2];
  return v;
}

TEST(IqModel, JacobianMatchesNumericalDifferentiation) {
  for (double d : {0.5, 0.25}) {
    const IqSettings s = settings(45.0, 0.02, d);
    for (const TrackingErrors e : {TrackingErrors{0.07, 3.0}, TrackingErrors{-0.13, -11.0}, TrackingErrors{0.3, 0.0},
                                   TrackingErrors{0.0, 0.0}, TrackingErrors{0.02, 1e-6}}) {
      const auto J = iq_jacobian(e, s);
      const double hc = 1e-6, hf = 1e-4;
      const Eigen::Matrix<double, 6, 1> dc = (taps_vector(expected_iq({e.code_chips + hc, e.frequency_hz}, s)) -
                                              taps_vector(expected_iq({e.code_chips - hc, e.frequency_hz}, s))) /
                                             (2 * hc);
      const Eigen::Matrix<double, 6, 1> df = (taps_vector(expected_iq({e.code_chips, e.frequency_hz + hf}, s)) -
                                              taps_vector(expected_iq({e.code_chips, e.frequency_hz - hf}, s))) /
                                             (2 * hf);
      for (int r = 0; r < 6; ++r) {
        EXPECT_NEAR(J(r, 0), dc(r), 1e-5 * iq_amplitude(s)) << "d " << d << " row " << r << " tau " << e.code_chips;
        EXPECT_NEAR(J(r, 1), df(r), 1e-5 * iq_amplitude(s)) << "d " << d << " row " << r << " df " << e.frequency_hz;
      }
    }
  }
  // Start-phase derivative (the absolute-carrier-phase reading of eq. 8b).
  const IqSettings s = settings(45.0, 0.02, 0.5);
  for (const TrackingErrors e : {TrackingErrors{0.05, 4.0, 0.7}, TrackingErrors{-0.1, -9.0, -2.5}}) {
    const double h = 1e-6;
    TrackingErrors p = e, m = e;
    p.phase_rad += h;
    m.phase_rad -= h;
    const Eigen::Matrix<double, 6, 1> num = (taps_vector(expected_iq(p, s)) - taps_vector(expected_iq(m, s))) / (2 * h);
    EXPECT_LT((iq_phase_derivative(e, s) - num).cwiseAbs().maxCoeff(), 1e-5 * iq_amplitude(s));
    // and the phase turns I + jQ: the envelope is unchanged
    const IqTaps t = expected_iq(e, s), t0 = expected_iq({e.code_chips, e.frequency_hz, 0.0}, s);
    EXPECT_NEAR(std::hypot(t.i[1], t.q[1]), std::hypot(t0.i[1], t0.q[1]), 1e-9);
  }
  // The prompt's corner: the one-sided slopes are -+A; the Jacobian takes their mean, 0 (what a central
  // difference, or a UKF with tiny alpha, sees).
  EXPECT_EQ(triangle_slope(0.0), 0.0);
  EXPECT_EQ(triangle_slope(-1e-9), 1.0);
  EXPECT_EQ(triangle_slope(1e-9), -1.0);
}

// Noise of taps o_j, o_k = white noise through the same code shifted by o_j - o_k: its correlation is the
// code's own autocorrelation at that lag, computed here from the real PRN 7 chips sampled at 20 per chip.
TEST(IqModel, TapNoiseCorrelationIsTheCodeAutocorrelation) {
  const auto& code = signals::ca_code(7);
  const int spc = 20, n = 1023 * spc;
  auto chip = [&](int sample) { return code[((sample % n + n) % n) / spc]; };
  for (double d : {0.5, 0.25}) {
    const auto C = iq_noise_covariance(settings(45.0, 0.02, d));
    const int lag = static_cast<int>(std::lround(d * spc));
    double r1 = 0.0, r2 = 0.0;
    for (int k = 0; k < n; ++k) {
      r1 += chip(k) * chip(k + lag);
      r2 += chip(k) * chip(k + 2 * lag);
    }
    r1 /= n;
    r2 /= n;
    // The Gold code's off-peak terms are O(1/1023): 65/1023 at worst, typically -1/1023 at whole-chip lags.
    EXPECT_NEAR(C(0, 1), r1, 0.07) << d;
    EXPECT_NEAR(C(1, 2), r1, 0.07) << d;
    EXPECT_NEAR(C(0, 2), r2, 0.07) << d;
    EXPECT_NEAR(C(3, 5), r2, 0.07) << d;
    EXPECT_EQ(C(0, 3), 0.0);  // I and Q independent
    EXPECT_EQ(C(2, 2), 1.0);
    // With the code's own one-chip autocorrelation in the model the match is exact: at 20 samples per chip and
    // lags of whole samples, the sampled correlation is (1 - lag) + lag R1 (lag in chips, <= 1) to rounding.
    IqSettings s7 = settings(45.0, 0.02, d);
    s7.code_lag1_correlation = ca_code_lag1_correlation(7);
    const auto C7 = iq_noise_covariance(s7);
    EXPECT_NEAR(C7(0, 1), r1, 1e-12) << d;
    EXPECT_NEAR(C7(1, 2), r1, 1e-12) << d;
    EXPECT_NEAR(C7(0, 2), r2, 1e-12) << d;
    EXPECT_NEAR(C7(3, 5), r2, 1e-12) << d;
  }
}

// Linearised at zero error, the six taps carry exactly the information of the first-order discriminators:
// J' C^-1 J = diag(A^2 / d, (A pi T)^2) = diag(1 / code var, 1 / frequency var).
TEST(IqModel, LinearisedTapInformationEqualsFirstOrderDiscriminatorVariance) {
  for (double d : {0.5, 0.3, 0.1}) {
    const IqSettings s = settings(38.0, 0.01, d);
    const auto J = iq_jacobian(TrackingErrors{}, s);
    const Eigen::Matrix2d info = J.transpose() * iq_noise_covariance(s).llt().solve(J);
    const DiscriminatorNoise n = discriminator_noise(s, false);
    EXPECT_NEAR(info(0, 0) * n.code_var_chips2, 1.0, 1e-9) << d;
    EXPECT_NEAR(info(1, 1) * n.frequency_var_hz2, 1.0, 1e-9) << d;
    EXPECT_NEAR(info(0, 1), 0.0, 1e-9 * info(0, 0)) << d;
    const double A = iq_amplitude(s);
    EXPECT_NEAR(info(0, 0), A * A / d, 1e-6 * A * A / d);
    EXPECT_NEAR(info(1, 1), std::pow(A * kPi * s.integration_time_s, 2), 1e-6 * info(1, 1));
  }
}

// Simulated taps (model + correlated Gaussian noise) through the discriminators: the mean recovers the true
// error and the variance matches the closed form within the sampling error (N = 40000: 1-sigma of a variance
// ratio sqrt(2 / N) = 0.7 %; tolerance 3 %).
void monte_carlo(double cn0_dbhz, double tolerance) {
  const IqSettings s = settings(cn0_dbhz, 0.02, 0.5);
  const TrackingErrors truth{0.04, 2.5};
  const IqTaps mean = expected_iq(truth, s);
  const Eigen::Matrix<double, 6, 6> L = iq_noise_covariance(s).llt().matrixL();
  std::mt19937_64 rng(20261123);
  std::normal_distribution<double> g;
  const int n = 40000;
  double sum_c = 0, scc = 0, sum_f = 0, sff = 0;
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix<double, 6, 1> w;
    for (int r = 0; r < 6; ++r) w(r) = g(rng);
    const Eigen::Matrix<double, 6, 1> noise = L * w;
    IqTaps t = mean;
    for (int j = 0; j < 3; ++j) {
      t.i[j] += noise(j);
      t.q[j] += noise(3 + j);
    }
    const double c = code_discriminator_chips(t, s) - truth.code_chips;
    const double f = frequency_discriminator_hz(t, s) - truth.frequency_hz;
    sum_c += c;
    scc += c * c;
    sum_f += f;
    sff += f * f;
  }
  const double mc = sum_c / n, mf = sum_f / n;
  const double vc = scc / n - mc * mc, vf = sff / n - mf * mf;
  // The closed forms hold at zero error; off it the signal amplitude is lower: by sinc(pi df T) for the
  // early-minus-late (E + L stays A (2 - 2d) sinc inside +-d) and by R(tau) sinc for the prompt's phase.
  // Both enter as a lower effective C/N0.
  const double x = kPi * truth.frequency_hz * s.integration_time_s, sinc = std::sin(x) / x;
  IqSettings sc = s, sf_ = s;
  sc.cn0_dbhz += 20.0 * std::log10(sinc);
  sf_.cn0_dbhz += 20.0 * std::log10(sinc * triangle_correlation(truth.code_chips));
  const double cvar = discriminator_noise(sc).code_var_chips2, fvar = discriminator_noise(sf_).frequency_var_hz2;
  EXPECT_NEAR(mc, 0.0, 4.0 * std::sqrt(cvar / n)) << cn0_dbhz;
  EXPECT_NEAR(mf, 0.0, 4.0 * std::sqrt(fvar / n)) << cn0_dbhz;
  EXPECT_NEAR(vc / cvar, 1.0, tolerance) << cn0_dbhz << " dB-Hz code";
  EXPECT_NEAR(vf / fvar, 1.0, tolerance) << cn0_dbhz << " dB-Hz frequency";
  const DiscriminatorNoise first = discriminator_noise(sc, false);
  // The Monte Carlo figures, for docs/validation.md.
  std::printf(
      "MC %.0f dB-Hz: code var ratio %.4f (closed form %.3e chip^2; first order alone %.4f), frequency var "
      "ratio %.4f (%.3e Hz^2; first order alone %.4f)\n",
      cn0_dbhz, vc / cvar, cvar, vc / first.code_var_chips2, vf / fvar, fvar,
      vf / discriminator_noise(sf_, false).frequency_var_hz2);
}

TEST(IqModel, DiscriminatorNoiseMatchesClosedFormAt45DbHz) { monte_carlo(45.0, 0.03); }
TEST(IqModel, DiscriminatorNoiseMatchesClosedFormAt35DbHz) { monte_carlo(35.0, 0.03); }

// --- the 17-state measurement objects ---

struct Scene {
  NominalState nominal;
  std::vector<SatelliteObservable> sats;
  Eigen::Vector3d w_ib_b{0.01, -0.02, 0.05};
  Eigen::Vector3d lever_b{0.5, -0.2, -0.3};
};

Scene scene() {
  Scene sc;
  sc.nominal.nav.lat_rad = 36.37 * kPi / 180.0;
  sc.nominal.nav.lon_rad = 127.36 * kPi / 180.0;
  sc.nominal.nav.height_m = 1000.0;
  sc.nominal.nav.v_n = Eigen::Vector3d(120.0, 60.0, -1.0);
  sc.nominal.nav.q_nb = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
  sc.nominal.clock_bias_m = 1234.0;
  sc.nominal.clock_drift_mps = 2.5;
  const Eigen::Vector3d r = ins::ecef_from_geodetic(sc.nominal.nav.lat_rad, sc.nominal.nav.lon_rad, 1000.0);
  const Eigen::Matrix3d C_en = ins::C_en(sc.nominal.nav.lat_rad, sc.nominal.nav.lon_rad);
  const double az[] = {0.3, 1.9, 3.5, 4.8};
  const double el[] = {1.2, 0.5, 0.8, 0.3};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d u_n(std::cos(el[i]) * std::cos(az[i]), std::cos(el[i]) * std::sin(az[i]), -std::sin(el[i]));
    SatelliteObservable s;
    s.prn = i + 1;
    s.r_sat_e = r + 2.2e7 * (C_en * u_n);
    s.v_sat_e = Eigen::Vector3d(1500.0 * std::cos(i), -2000.0, 2500.0 * std::sin(i));
    s.has_rate = true;
    sc.sats.push_back(s);
  }
  return sc;
}

StateVector<17> small_error() {
  StateVector<17> dx;
  dx << 3.0, -2.0, 4.0, 0.2, -0.3, 0.1, 1e-3, -2e-3, 3e-3, 1e-3, -1e-3, 2e-3, 1e-5, -2e-5, 3e-5, 2.0, -0.4;
  return dx;
}

TEST(IqMeasurement17, JacobianMatchesNumericalDifferentiation) {
  const Scene sc = scene();
  const IqSettings s = settings(45.0, 0.02, 0.5);
  const std::vector<IqTaps> taps(sc.sats.size(), expected_iq(TrackingErrors{}, s));
  const IqEpochMeasurement17 m(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b, s, taps);
  ASSERT_EQ(m.size(), 24);
  // At the nominal the model returns the peak taps (replica errors zero).
  EXPECT_NEAR((m.h(StateVector<17>::Zero()) - m.z()).norm(), 0.0, 1e-6);
  // Clock errors only: the replica errors are then exactly linear in dx, so H (the replica Jacobian at the
  // nominal times the tap Jacobian at the operating point: tau = 0.007 chip, df = 2.1 Hz) must be exact there.
  StateVector<17> x = StateVector<17>::Zero();
  x(15) = 2.0;
  x(16) = -0.4;
  const auto H = m.H(x);
  // Steps well above the rounding of 2e7 m ranges (4e-9 m) and small against the curvature.
  const double steps[17] = {1e-2, 1e-2, 1e-2, 1e-4, 1e-4, 1e-4, 1e-5, 1e-5, 1e-5,
                            1e-6, 1e-6, 1e-6, 1e-5, 1e-5, 1e-5, 1e-2, 1e-4};
  for (int c = 0; c < 17; ++c) {
    StateVector<17> p = x, q = x;
    p(c) += steps[c];
    q(c) -= steps[c];
    const Eigen::VectorXd num = (m.h(p) - m.h(q)) / (2 * steps[c]);
    // Velocity, accelerometer-bias and clock columns are exact in the tight model; position, attitude and gyro
    // columns carry its documented first-order omissions (earth-frame rotation of the velocity with position,
    // |v| / R ~ 2e-5 (m/s)/m here): 1e-3 of the row's scale for those.
    const bool exact = (c >= 3 && c < 6) || (c >= 9 && c < 12) || c >= 15;
    for (int r = 0; r < m.size(); ++r)
      EXPECT_NEAR(H(r, c), num(r),
                  exact ? 1e-5 * std::max(1.0, std::abs(num(r))) : 1e-3 * H.row(r).cwiseAbs().maxCoeff())
          << "row " << r << " col " << c;
  }
  // A general error (3 m, 0.3 m/s, 3 mrad, ...): first order only, the replica Jacobian is that of the nominal;
  // the mismatch is second order: the 3e-3 rad attitude error turns the lever-arm and gyro terms by that
  // fraction, so within 5e-3 of each row's largest entry.
  const StateVector<17> y = small_error();
  const auto Hy = m.H(y);
  for (int c = 0; c < 17; ++c) {
    StateVector<17> p = y, q = y;
    p(c) += steps[c];
    q(c) -= steps[c];
    const Eigen::VectorXd num = (m.h(p) - m.h(q)) / (2 * steps[c]);
    for (int r = 0; r < m.size(); ++r)
      EXPECT_NEAR(Hy(r, c), num(r), 5e-3 * Hy.row(r).cwiseAbs().maxCoeff()) << "row " << r << " col " << c;
  }
}

// The discriminator rows are the tight pseudorange / rate rows with the sign of "replica minus signal", and
// the errors move as the tight prediction does.
TEST(DiscriminatorMeasurement17, RowsAreTheTightRows) {
  const Scene sc = scene();
  const DiscriminatorEpochMeasurement17 m(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b,
                                          Eigen::VectorXd::Zero(2 * sc.sats.size()), 5.0, 0.1, true);
  const EpochMeasurement17 tight(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b, true);
  const StateVector<17> x = small_error(), zero = StateVector<17>::Zero();
  const auto Hd = m.H(x);
  const auto Ht = tight.H(x);
  const int n = static_cast<int>(sc.sats.size());
  for (int i = 0; i < n; ++i) {
    EXPECT_NEAR((Hd.row(2 * i) + Ht.row(i)).norm(), 0.0, 1e-9);
    EXPECT_NEAR((Hd.row(2 * i + 1) + Ht.row(n + i)).norm(), 0.0, 1e-9);
    EXPECT_NEAR(m.h(x)(2 * i), -(tight.h(x)(i) - tight.h(zero)(i)), 1e-6);
    EXPECT_NEAR(m.R()(2 * i, 2 * i), 25.0, 0.0);
    EXPECT_NEAR(m.R()(2 * i + 1, 2 * i + 1), 0.01, 1e-15);
  }
  const DiscriminatorEpochMeasurement17 code_only(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b,
                                                  Eigen::VectorXd::Zero(2 * n), 5.0, 0.1, false);
  EXPECT_EQ(code_only.size(), n);
  EXPECT_NEAR((code_only.H(x).row(2) + Ht.row(2)).norm(), 0.0, 1e-9);
}

// With the absolute carrier phase (eq. 8b read literally) the phase column joins the chain rule.
TEST(IqMeasurement17, AbsolutePhaseJacobianMatchesNumericalDifferentiation) {
  const Scene sc = scene();
  IqSettings s = settings(45.0, 0.02, 0.5);
  s.absolute_carrier_phase = true;
  const std::vector<IqTaps> taps(sc.sats.size(), expected_iq(TrackingErrors{}, s));
  const IqEpochMeasurement17 m(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b, s, taps);
  StateVector<17> x = StateVector<17>::Zero();
  x(15) = 0.03;  // 0.16 cycle of start phase
  x(16) = -0.4;
  const auto H = m.H(x);
  for (int c : {15, 16, 3, 4}) {
    const double step = 1e-5;
    StateVector<17> p = x, q = x;
    p(c) += step;
    q(c) -= step;
    const Eigen::VectorXd num = (m.h(p) - m.h(q)) / (2 * step);
    for (int r = 0; r < m.size(); ++r)
      EXPECT_NEAR(H(r, c), num(r), 1e-4 * std::max(1.0, std::abs(num(r)))) << "row " << r << " col " << c;
  }
  // The phase dominates the range sensitivity: the prompt turns by 2 pi / lambda per metre, so |d(I_P, Q_P)/d
  // clock bias| = A sinc(pi df T) 2 pi / lambda = 1174 * 0.997 per metre (df = 0.4 m/s / lambda = 2.1 Hz),
  // against A / 293 m = 0.12 per metre through the code.
  const double x_f = kPi * (0.4 / signals::kL1Wavelength_m) * 0.02;
  EXPECT_NEAR(std::hypot(H(1, 15), H(4, 15)),
              iq_amplitude(s) * std::sin(x_f) / x_f * 2.0 * kPi / signals::kL1Wavelength_m, 1e-3 * 1174.0);
}

TEST(IqMeasurement17, BadSettingsAreInputErrors) {
  EXPECT_ANY_THROW(expected_iq(TrackingErrors{}, settings(45.0, 0.0, 0.5)));
  EXPECT_ANY_THROW(iq_noise_covariance(settings(45.0, 0.02, 0.7)));
  IqSettings bad_r1 = settings();
  bad_r1.code_lag1_correlation = 1.0;  // the tap covariance would be singular
  EXPECT_ANY_THROW(iq_noise_covariance(bad_r1));
  const Scene sc = scene();
  EXPECT_ANY_THROW(IqEpochMeasurement17(sc.nominal, sc.sats, sc.lever_b, sc.w_ib_b, settings(), {}));
}

// The taps' code correlation against a brute-force correlation of the C/A chips sampled as the simulator makes
// them (signals::synth::add_code_carrier: rectangular chips, no band limit, chip = floor(code phase), 2.6 MHz) with
// a replica made the same way x chips later. At exactly 2600 samples per 1023-chip period the grid repeats every
// millisecond, so one start samples each chip at the same 2-3 fractions and the result depends on where the chip
// transitions fall (off by up to 0.01 from one start, 0.0096 for PRN 8 at x = 0.2). In the receiver code Doppler
// moves the grid; here the correlation is averaged over M evenly spaced grid offsets (start + j q / M, q = 1023 /
// 2600 chip the sample step), which together form one uniform grid of spacing h = q / M over the period. Bound (exact,
// from that grid, for |x| <= 1): the replica is in the neighbouring chip for the samples of chip i that lie in an
// interval of length |x|, whose count is |x| / h +- less than 1, so the mean differs from 1 - |x| (1 - R1) by less than
// h (1 - R1) (1.6e-3 at M = 256). The ideal triangle is off by 0.031 at the E/L offset for PRN 15 and 24
// (+63/1023 at one chip), which the bound excludes.
TEST(IqModel, CodeCorrelationMatchesTheSampledCaCode) {
  const double fs = 2.6e6, q = signals::kCaChipRate_hz / fs;  // chips per sample
  const int per_period = 2600, M = 256;
  const double h = q / M;
  EXPECT_NEAR(ca_code_lag1_correlation(15), 63.0 / 1023.0, 1e-12);
  EXPECT_NEAR(ca_code_lag1_correlation(24), 63.0 / 1023.0, 1e-12);
  EXPECT_NEAR(ca_code_lag1_correlation(7), 63.0 / 1023.0, 1e-12);
  EXPECT_NEAR(ca_code_lag1_correlation(8), -65.0 / 1023.0, 1e-12);
  EXPECT_NEAR(ca_code_lag1_correlation(22), -65.0 / 1023.0, 1e-12);
  EXPECT_NEAR(ca_code_lag1_correlation(1), -1.0 / 1023.0, 1e-12);
  EXPECT_EQ(ca_code_lag1_correlation(0), 0.0);
  EXPECT_EQ(ca_code_lag1_correlation(33), 0.0);
  std::vector<std::complex<float>> sig(per_period), rep(per_period);
  for (int prn : {1, 8, 15, 24}) {
    const auto& c = signals::ca_code(prn);
    std::vector<float> chips(c.begin(), c.end());
    const double r1 = ca_code_lag1_correlation(prn);
    for (double x : {-1.0, -0.75, -0.5, -0.3, 0.0, 0.2, 0.5, 0.8, 1.0}) {
      double sum = 0.0;
      for (int j = 0; j < M; ++j) {
        const double start = 123.4567 + j * h;  // chips
        std::fill(sig.begin(), sig.end(), std::complex<float>{});
        std::fill(rep.begin(), rep.end(), std::complex<float>{});
        signals::synth::add_code_carrier(sig.data(), sig.size(), chips.data(), 1.0f, start, q, 0.0, 0.0, true);
        const double replica_start = std::fmod(start + x + 1023.0, 1023.0);
        signals::synth::add_code_carrier(rep.data(), rep.size(), chips.data(), 1.0f, replica_start, q, 0.0, 0.0, true);
        for (int k = 0; k < per_period; ++k) sum += static_cast<double>(sig[k].real()) * rep[k].real();
      }
      const double brute = sum / (static_cast<double>(M) * per_period);
      EXPECT_NEAR(code_correlation(x, r1), brute, h * (1.0 - r1)) << "PRN " << prn << " x " << x;
      if ((prn == 15 || prn == 24) && std::abs(x) == 0.5) {
        EXPECT_GT(std::abs(triangle_correlation(x) - brute), 0.025) << "PRN " << prn << " x " << x;
      }
    }
  }
  // lag1 = 0 is the triangle, slopes included.
  for (double x : {-2.5, -1.0, -0.4, 0.0, 0.3, 1.0, 1.7}) {
    EXPECT_EQ(code_correlation(x, 0.0), triangle_correlation(x)) << x;
    EXPECT_EQ(code_correlation_slope(x, 0.0), triangle_slope(x)) << x;
  }
  // Slope against central differences inside the pieces.
  for (double x : {-1.5, -0.6, 0.4, 1.3})
    EXPECT_NEAR(code_correlation_slope(x, 0.06),
                (code_correlation(x + 1e-6, 0.06) - code_correlation(x - 1e-6, 0.06)) / 2e-6, 1e-8);
}

}  // namespace
