// SPDX-License-Identifier: GPL-3.0-or-later
// Seed 001 ultra-tight covariance analysis (issue 7): the discriminator form reduces exactly to the tight
// pseudorange analysis when its noise and rate are those of the tight one; the linearised I&Q taps give the
// EKF the same covariance as the first-order discriminators (equal information); ultra-tight beats tight on
// the same trajectory; the UKF on the taps departs from the EKF only while its sigma points reach the
// nonlinear part of the frequency response and joins it once the covariance is small.
#include <gtest/gtest.h>

#include <cmath>

#include "fusion/covariance_analysis.hpp"

namespace {

using namespace ultratrack::fusion;

// Closed-form equivalence: 1 Hz discriminator range errors with sigma 5 m and no rates are the tight
// pseudoranges of eq. 38 (rows differ only in sign), so every sample of the history must agree.
TEST(UltraTightCovariance, DiscriminatorFormWithPseudorangeNoiseEqualsTight) {
  auto tight = seed001_covariance_options("circle", FilterKind::Ekf);
  tight.duration_s = 20.0;
  auto ultra = tight;
  ultra.coupling = Coupling::kUltraTight;
  ultra.iq_form = IqForm::Discriminator;
  ultra.discriminator_sigma_range_m = 5.0;
  ultra.discriminator_use_rate = false;
  const auto a = run_covariance_analysis(tight);
  const auto b = run_covariance_analysis(ultra);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t k = 0; k < a.samples.size(); ++k)
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(b.samples[k].sigma_pos_ned_m[i], a.samples[k].sigma_pos_ned_m[i],
                  1e-9 * a.samples[k].sigma_pos_ned_m[i]);
}

// The linearised six taps per satellite carry exactly the information of the first-order discriminators
// (tests/fusion/iq_measurements_test.cpp), so the EKF covariances agree to rounding.
TEST(UltraTightCovariance, EkfOnTapsEqualsEkfOnFirstOrderDiscriminators) {
  auto iq = seed001_ultratight_options("s", FilterKind::Ekf, IqForm::Iq);
  iq.duration_s = 3.0;
  auto disc = seed001_ultratight_options("s", FilterKind::Ekf, IqForm::Discriminator);
  disc.duration_s = 3.0;
  disc.discriminator_squaring_loss = false;
  const auto a = run_covariance_analysis(iq);
  const auto b = run_covariance_analysis(disc);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  ASSERT_GT(a.samples.size(), 100u);
  for (std::size_t k = 0; k < a.samples.size(); ++k)
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(a.samples[k].sigma_pos_ned_m[i] / b.samples[k].sigma_pos_ned_m[i], 1.0, 1e-6) << k;
}

// Information: per satellite and second the 50 Hz code discriminators (5.8 m each at 45 dB-Hz, 20 ms) alone
// carry 50 / 5.8^2 = 1.5 m^-2 against 1 / 5^2 = 0.04 m^-2 for the tight pseudorange, and the rates add more,
// so the ultra-tight position 1-sigma must be below the tight one at every report time.
TEST(UltraTightCovariance, UltraTightIsBelowTight) {
  for (const char* name : {"straight", "circle"}) {
    auto t = seed001_covariance_options(name, FilterKind::Ekf);
    t.duration_s = 30.0;
    auto u = seed001_ultratight_options(name, FilterKind::Ekf, IqForm::Iq);
    u.duration_s = 30.0;
    const auto a = run_covariance_analysis(t);
    const auto b = run_covariance_analysis(u);
    for (double time : {1.0, 10.0, 30.0})
      for (int i = 0; i < 3; ++i)
        EXPECT_LT(b.at(time).sigma_pos_ned_m[i], a.at(time).sigma_pos_ned_m[i]) << name << " t " << time;
    // Not merely below: with 37x the code information the 30 s sigma drops by more than sqrt(37) / 2 = 3.
    for (int i = 0; i < 3; ++i) EXPECT_LT(3.0 * b.at(30.0).sigma_pos_ned_m[i], a.at(30.0).sigma_pos_ned_m[i]) << name;
  }
}

// UKF on the taps: with alpha -> 0 the sigma points become central differences at the truth, i.e. the EKF;
// with alpha = 1 they reach 4 sigma (frequency errors of tens of Hz where sinc(pi df T) sin(pi df T) is far from
// linear) and the first updates differ from the EKF; once the covariance has shrunk (sigma of df ~ 0.1 Hz after
// a few seconds) the two agree.
TEST(UltraTightCovariance, UkfOnTapsJoinsTheEkfAsTheCovarianceShrinks) {
  auto e = seed001_ultratight_options("circle", FilterKind::Ekf, IqForm::Iq);
  e.duration_s = 5.0;
  auto u = e;
  u.filter = FilterKind::Ukf;
  auto u0 = u;
  u0.ukf.alpha = 1e-3;
  const auto a = run_covariance_analysis(e);
  const auto b = run_covariance_analysis(u);
  const auto c = run_covariance_analysis(u0);
  double first_diff = 0.0;
  for (int i = 0; i < 3; ++i) {
    first_diff = std::max(first_diff, std::abs(b.samples[5].sigma_pos_ned_m[i] / a.samples[5].sigma_pos_ned_m[i] - 1));
    EXPECT_NEAR(c.at(0.1).sigma_pos_ned_m[i] / a.at(0.1).sigma_pos_ned_m[i], 1.0, 1e-3);
    EXPECT_NEAR(c.at(5.0).sigma_pos_ned_m[i] / a.at(5.0).sigma_pos_ned_m[i], 1.0, 1e-3);
    EXPECT_NEAR(b.at(5.0).sigma_pos_ned_m[i] / a.at(5.0).sigma_pos_ned_m[i], 1.0, 5e-3);
  }
  EXPECT_GT(first_diff, 1e-2);  // the nonlinearity is really exercised at the start
}

TEST(UltraTightCovariance, BadIqSettingsAreInputErrors) {
  auto o = seed001_ultratight_options("straight", FilterKind::Ekf, IqForm::Iq);
  o.duration_s = 1.0;
  o.iq.tap_offset_chips = 0.0;
  EXPECT_ANY_THROW(run_covariance_analysis(o));
}

}  // namespace

namespace {

// Eq. 8b read literally (absolute carrier phase, integer known): each 20 ms prompt is then a range with
// lambda / (2 pi A) = 0.85 mm noise at 45 dB-Hz, and the linearised filter reaches millimetres within a second,
// two orders below the code-and-frequency model: the size of what that idealisation claims.
TEST(UltraTightCovariance, AbsoluteCarrierPhaseGivesMillimetres) {
  auto o = ultratrack::fusion::seed001_ultratight_options("circle", ultratrack::fusion::FilterKind::Ekf,
                                                          ultratrack::fusion::IqForm::Iq);
  o.duration_s = 1.0;
  const auto code = ultratrack::fusion::run_covariance_analysis(o);
  o.iq.absolute_carrier_phase = true;
  const auto phase = ultratrack::fusion::run_covariance_analysis(o);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(phase.at(1.0).sigma_pos_ned_m[i], 2e-3);
    EXPECT_LT(100.0 * phase.at(1.0).sigma_pos_ned_m[i], code.at(1.0).sigma_pos_ned_m[i]);
  }
}

}  // namespace
