// SPDX-License-Identifier: GPL-3.0-or-later
// The vector tracking filter's models (fusion/vector_tracking.hpp) against independent truth: its measurement
// Jacobians against central differences of its own h (the EKF's linearisation), its replica prediction against
// a pseudorange computed here from the broadcast orbit by light-time iteration (satellite_state, Sagnac) and
// differentiated numerically, and the closed-form discriminator variances against Monte Carlo runs of the
// receiver's own discriminators on correlator sums with Gaussian noise at a known C/N0.
#include "fusion/vector_tracking.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <optional>
#include <random>

#include "receiver/discriminators.hpp"
#include "signals/gps_constants.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/satellite_state.hpp"

namespace {

using namespace ultratrack;
using fusion::VectorState;

const signals::GpsTime kT0{2190, 518772.0};
const Eigen::Vector3d kRx(-3813409.0, 3554350.0, 3662785.0);  // near Nagoya, ~100 m height

// The true pseudorange at receive time t (GPS time) for a receiver at r_rx(t) = r0 + v dt with clock bias
// b0 + d dt (m): light time by iteration, satellite position rotated into the receive-time frame, SV clock.
double true_pseudorange(const signals::Ephemeris& eph, const signals::GpsTime& t, const Eigen::Vector3d& r0,
                        const Eigen::Vector3d& v, double b0, double d, double dt) {
  const Eigen::Vector3d r_rx = r0 + v * dt;
  double tau = 0.07;
  for (int i = 0; i < 10; ++i) {
    const signals::SatelliteState s = signals::satellite_state(eph, signals::add_seconds(t, -tau));
    tau = (signals::rotate_to_receive_frame(s.r_e_m, tau) - r_rx).norm() / signals::kSpeedOfLight_mps;
  }
  const signals::GpsTime t_tx = signals::add_seconds(t, -tau);
  const double dt_sv = signals::l1_ca_clock_correction_s(eph, t_tx);
  return signals::kSpeedOfLight_mps * (tau - dt_sv) + b0 + d * dt;
}

// The satellite observable the filter builds, via prepare_satellites (no atmosphere), at receive time t.
std::optional<fusion::SatelliteObservable> observable(const std::vector<signals::Ephemeris>& ephs, int prn,
                                                      const signals::GpsTime& t, double pseudorange_m,
                                                      const Eigen::Vector3d& r) {
  receiver::ObservationEpoch e;
  e.receive_time = t;
  receiver::Observation o;
  o.prn = prn;
  o.pseudorange_m = pseudorange_m;
  o.doppler_hz = NAN;
  e.observations.push_back(o);
  fusion::TightOptions opt;
  opt.ionosphere = opt.troposphere = false;
  opt.elevation_mask_rad = -1.0;
  opt.use_range_rate = false;
  const auto sats = fusion::prepare_satellites(e, ephs, {}, r, opt);
  if (sats.empty()) return std::nullopt;
  return sats.front();
}

VectorState state(const Eigen::Vector3d& r, const Eigen::Vector3d& v, double b, double d) {
  VectorState x;
  x << r, v, b, d;
  return x;
}

TEST(VectorTracking, MeasurementJacobiansMatchCentralDifferences) {
  const auto nc = signals::nominal_constellation(kT0);
  int checked = 0;
  for (const auto& eph : nc.ephemerides) {
    const auto found = observable(nc.ephemerides, eph.prn, kT0, 2.2e7, kRx);
    if (!found || found->elevation_rad < 0.1) continue;
    const fusion::SatelliteObservable& sat = *found;
    const int prn = eph.prn;
    ++checked;
    const VectorState x = state(kRx, Eigen::Vector3d(120.0, -80.0, 30.0), 1500.0, 3.0);
    for (bool rate : {false, true}) {
      for (double delta : {0.0, 0.03}) {
        const fusion::VectorRangeMeasurement m(sat, delta, rate, 0.0, 1.0);
        const auto H = m.H(x);
        for (int j = 0; j < 8; ++j) {
          const double h = j < 3 ? 1.0 : (j < 6 ? 0.01 : 1.0);  // metres, m/s, m, m/s
          VectorState xp = x, xm = x;
          xp(j) += h;
          xm(j) -= h;
          const double numeric = (m.h(xp)(0) - m.h(xm)(0)) / (2.0 * h);
          // Differences of ~2e7 m in double: rounding ~4e-9 m / 2h; the curvature of the range over 1 m is 1e-7.
          const double tol = rate ? 1e-8 : 1e-6;
          EXPECT_NEAR(H(0, j), numeric, tol) << "prn " << prn << " rate " << rate << " delta " << delta << " col " << j;
        }
      }
    }
  }
  EXPECT_GE(checked, 5);
}

// The prediction from the state against the pseudorange truth above, static and moving (140 m/s), with a
// clock bias and drift: pseudorange to a millimetre, its rate (and so the Doppler and the code rate) to
// 1 mm/s (the central difference over +-0.05 s errs by rho''' h^2 / 6, far below that).
TEST(VectorTracking, ReplicaPredictionMatchesLightTimePseudorangeAndItsRate) {
  const auto nc = signals::nominal_constellation(kT0);
  const double b0 = 3000.0, d = 12.0;  // m, m/s (a 40 ns/s TCXO offset)
  for (const Eigen::Vector3d& v : {Eigen::Vector3d::Zero().eval(), Eigen::Vector3d(-60.0, 110.0, 55.0)}) {
    int checked = 0;
    for (const auto& eph : nc.ephemerides) {
      const double pr = true_pseudorange(eph, kT0, kRx, v, b0, d, 0.0);
      // The filter works on the receiver clock's time, which reads b0 / c ahead of GPS time.
      const auto found =
          observable(nc.ephemerides, eph.prn, signals::add_seconds(kT0, b0 / signals::kSpeedOfLight_mps), pr, kRx);
      // Visible satellites only (the others pass through the earth).
      if (!found || found->elevation_rad < 0.1) continue;
      const fusion::SatelliteObservable& sat = *found;
      const double h = 0.05;
      const double rate = (true_pseudorange(eph, signals::add_seconds(kT0, h), kRx, v, b0, d, h) -
                           true_pseudorange(eph, signals::add_seconds(kT0, -h), kRx, v, b0, d, -h)) /
                          (2.0 * h);
      const fusion::ReplicaPrediction p = fusion::predict_replica(sat, state(kRx, v, b0, d));
      EXPECT_NEAR(p.pseudorange_m, pr, 1e-3) << eph.prn;
      EXPECT_NEAR(p.pseudorange_rate_mps, rate, 1e-3) << eph.prn;
      EXPECT_NEAR(p.doppler_hz, -rate / signals::kL1Wavelength_m, 0.006) << eph.prn;
      EXPECT_NEAR(p.code_rate_chips_per_s, 1.023e6 * (1.0 - rate / signals::kSpeedOfLight_mps), 1e-5) << eph.prn;
      // The textbook closed form: Doppler = -(u . (v_sat - v_rx) + d - c * SV drift) / lambda (to the 1e-6
      // relative travel-time terms, ~0.01 Hz).
      const signals::SatelliteState s =
          signals::satellite_state(eph, signals::add_seconds(kT0, -pr / signals::kSpeedOfLight_mps));
      const Eigen::Vector3d u = (s.r_e_m - kRx).normalized();
      const double closed =
          -(u.dot(s.v_e_mps - v) + d - signals::kSpeedOfLight_mps * s.clock_drift_sps) / signals::kL1Wavelength_m;
      EXPECT_NEAR(p.doppler_hz, closed, 0.05) << eph.prn;
      ++checked;
    }
    EXPECT_GE(checked, 5);
  }
}

// Monte Carlo of the receiver's normalised early-minus-late envelope DLL (E, L at +-0.5 chip: uncorrelated noise)
// and Costas arctangent on sums with complex Gaussian noise, signal aligned: the empirical variances against the
// closed forms with T = 20 ms. 20000 draws: the sample variance is within +-4 % of the model at 40 and 45 dB-Hz
// (2 sigma of sqrt(2/n) = 2 %, plus the formulas' neglected higher-order terms). At 30 dB-Hz the DLL formula (of
// the early-minus-late power discriminator) overstates the normalised envelope's variance by ~13 %: the filter's
// code noise is then conservative, which the test pins (ratio 0.8 to 0.95).
TEST(VectorTracking, DiscriminatorVariancesMatchMonteCarlo) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  const double t = 0.02;
  for (double cn0_dbhz : {30.0, 40.0, 45.0}) {
    const double cn0 = std::pow(10.0, cn0_dbhz / 10.0);
    // Noise per component sigma = 1; prompt amplitude A with A^2 / (2 sigma^2) = C T / N0.
    const double a = std::sqrt(2.0 * cn0 * t);
    const double phase = 0.3;
    double code2 = 0.0, phase2 = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const std::complex<double> rot = std::polar(1.0, phase);
      const std::complex<double> ne(g(rng), g(rng)), nl(g(rng), g(rng)), np(g(rng), g(rng));
      const auto e = std::complex<float>(0.5 * a * rot + ne), l = std::complex<float>(0.5 * a * rot + nl);
      const auto p = std::complex<float>(a * rot + np);
      const double c = receiver::dll_nelp_chips(e, l, 0.5);
      const double f = receiver::costas_atan_cycles(p) - phase / (2.0 * M_PI);
      code2 += c * c;
      phase2 += f * f;
    }
    const double code_model = fusion::code_discriminator_variance_chips2(cn0, t, 1.0);
    const double phase_model = fusion::costas_phase_variance_cycles2(cn0, t);
    std::printf("%.0f dB-Hz: code variance / model %.3f, phase variance / model %.3f\n", cn0_dbhz,
                code2 / n / code_model, phase2 / n / phase_model);
    if (cn0_dbhz < 35.0) {
      EXPECT_GT(code2 / n / code_model, 0.8);
      EXPECT_LT(code2 / n / code_model, 0.95);
    } else {
      EXPECT_NEAR(code2 / n / code_model, 1.0, 0.04) << cn0_dbhz;
    }
    EXPECT_NEAR(phase2 / n / phase_model, 1.0, 0.04) << cn0_dbhz;
  }
}

// The same Monte Carlo where filter-driven vector channels now update the filter (below the 25 dB-Hz at which the
// scalar loss test used to stop them): 18-24 dB-Hz, 20 ms. Both discriminators are bounded there (the normalised
// envelope DLL within +-0.5 chip, the Costas arctangent within +-1/4 cycle). The DLL's gain g (its mean output per
// chip of true code error, from offsets of +-0.1 chip) falls as the noise fills the E + L normaliser, and its
// variance with it: the closed form is then the variance of the gain-normalised output (var / g^2) within
// +4..+27 % (g = 0.63 at 24 dB-Hz, 0.33 at 20; pinned: [0.95, 1.35]), while the raw output's variance is far below it
// (0.41 at 24 dB-Hz, 0.07 at 18). So the filter's code weights are conservative, and its code update moves the state by
// g of what the weights imply (a slower code loop, not a wrong one). The Costas formula is within 6 % at 22-24 dB-Hz
// and overstates from 20 dB-Hz down (the wrap folds the tails: 0.74 at 18): [0.6, 1.1]. 20000 draws per point: sampling
// sigma of a variance ratio ~1-2 %, of g ~2 %.
TEST(VectorTracking, WeakSignalDiscriminatorVariancesAgainstMonteCarlo) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  const double t = 0.02;
  double last_gain = 1.0;
  for (double cn0_dbhz : {24.0, 22.0, 20.0, 18.0}) {
    const double cn0 = std::pow(10.0, cn0_dbhz / 10.0);
    const double a = std::sqrt(2.0 * cn0 * t);
    const int n = 20000;
    // Mean and variance of the DLL output with the signal `offset` chips later than the replica (E at -0.5, L at
    // +0.5 chip: triangle correlations), and of the Costas phase at zero phase error.
    const auto dll = [&](double offset, double& mean, double& var) {
      double s = 0.0, s2 = 0.0;
      for (int i = 0; i < n; ++i) {
        const double ea = a * std::max(0.0, 1.0 - std::abs(offset + 0.5)),
                     la = a * std::max(0.0, 1.0 - std::abs(offset - 0.5));
        const auto e = std::complex<float>(std::complex<double>(ea + g(rng), g(rng)));
        const auto l = std::complex<float>(std::complex<double>(la + g(rng), g(rng)));
        const double c = receiver::dll_nelp_chips(e, l, 0.5);
        s += c;
        s2 += c * c;
      }
      mean = s / n;
      var = s2 / n - mean * mean;
    };
    double m_minus, m_plus, m0, var0, unused;
    dll(-0.1, m_minus, unused);
    dll(0.1, m_plus, unused);
    dll(0.0, m0, var0);
    const double gain = std::abs(m_plus - m_minus) / 0.2;
    double phase2 = 0.0;
    for (int i = 0; i < n; ++i) {
      const double f = receiver::costas_atan_cycles(std::complex<float>(std::complex<double>(a + g(rng), g(rng))));
      phase2 += f * f;
    }
    const double code_model = fusion::code_discriminator_variance_chips2(cn0, t, 1.0);
    const double phase_ratio = phase2 / n / fusion::costas_phase_variance_cycles2(cn0, t);
    std::printf(
        "%.0f dB-Hz: DLL gain %.3f, variance / model %.3f, variance / gain^2 / model %.3f; phase variance / "
        "model %.3f\n",
        cn0_dbhz, gain, var0 / code_model, var0 / (gain * gain) / code_model, phase_ratio);
    // The closed-form gain (first order in the ratio of means) against the Monte Carlo's: its standard error is
    // ~0.01 (two means of 20000 draws with sd <= 0.2 chip, over 0.2 chip); the first-order form is within 0.015
    // of the exact mean at these C/N0 but 0.035 at 20 dB-Hz (0.62 / 0.49 / 0.36 / 0.25 against 0.63 / 0.47 /
    // 0.33 / 0.25). Tolerance: that 0.035 plus one standard error.
    const double closed_gain = fusion::code_discriminator_gain(cn0, t);
    std::printf("%.0f dB-Hz: DLL gain Monte Carlo %.3f, closed form %.3f\n", cn0_dbhz, gain, closed_gain);
    EXPECT_NEAR(closed_gain, gain, 0.045) << cn0_dbhz;
    EXPECT_LT(gain, last_gain) << cn0_dbhz;
    EXPECT_LT(var0 / code_model, 0.5) << cn0_dbhz;  // raw: conservative weights
    EXPECT_GT(var0 / (gain * gain) / code_model, 0.95) << cn0_dbhz;
    EXPECT_LT(var0 / (gain * gain) / code_model, 1.35) << cn0_dbhz;
    EXPECT_GT(phase_ratio, 0.6) << cn0_dbhz;
    EXPECT_LT(phase_ratio, 1.1) << cn0_dbhz;
    last_gain = gain;
  }
}

// The DLL gain's limits: 1 for a strong signal (45 dB-Hz, 20 ms: nu = 79, gain 1 - O(1 / nu)); for a weak one
// (nu -> 0) the envelope's noise mean dominates: gain -> nu (I0 + I1) 2 / 1 ~ 2 nu = C/N0 T / 4; it rises with
// C/N0 T, so 100 ms at 22 dB-Hz is worth 20 ms at 29 dB-Hz.
TEST(VectorTracking, DllGainClosedFormLimits) {
  EXPECT_NEAR(fusion::code_discriminator_gain(std::pow(10.0, 4.5), 0.02), 1.0, 0.01);
  EXPECT_NEAR(fusion::code_discriminator_gain(1e9, 0.02), 1.0, 1e-6);
  const double small = 0.01;  // C/N0 T
  // The next term is -1.5 nu of it: 0.2 % here.
  EXPECT_NEAR(fusion::code_discriminator_gain(small / 0.02, 0.02), small / 4.0, 0.01 * small / 4.0);
  EXPECT_NEAR(fusion::code_discriminator_gain(std::pow(10.0, 2.2), 0.1),
              fusion::code_discriminator_gain(std::pow(10.0, 2.9), 0.02), 0.01);
  double last = 0.0;
  for (double db = 10.0; db <= 60.0; db += 1.0) {  // 48 dB-Hz: past the switch to the series
    const double g = fusion::code_discriminator_gain(std::pow(10.0, db / 10.0), 0.02);
    EXPECT_GT(g, last) << db;
    EXPECT_LE(g, 1.0) << db;
    last = g;
  }
}

// Process model: f is the discretisation of F (x(t + dt) = Phi x), and the clock's noise densities are the
// Allan-coefficient forms (c^2 h0 / 2, c^2 2 pi^2 h-2).
TEST(VectorTracking, ProcessModelIsConstantVelocityWithAllanClockNoise) {
  fusion::VectorProcessModel m;
  const VectorState x = state(kRx, Eigen::Vector3d(1.0, 2.0, 3.0), 10.0, 0.5);
  const VectorState y = m.f(x, 2.0);
  EXPECT_NEAR((y.segment<3>(0) - kRx - Eigen::Vector3d(2.0, 4.0, 6.0)).norm(), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(y(6), 11.0);
  const double c2 = signals::kSpeedOfLight_mps * signals::kSpeedOfLight_mps;
  EXPECT_NEAR(m.Qc()(3, 3), c2 * 1e-19, 1e-6);
  EXPECT_NEAR(m.Qc()(4, 4), c2 * 2.0 * M_PI * M_PI * 2e-20, 1e-6);
  const fusion::StateMatrix<8> Phi = fusion::StateMatrix<8>::Identity() + 2.0 * m.F(x);  // F nilpotent: exp(F dt)
  EXPECT_NEAR((Phi * x - y).norm(), 0.0, 1e-6);
}

}  // namespace
