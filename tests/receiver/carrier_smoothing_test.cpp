// SPDX-License-Identifier: GPL-3.0-or-later
// Hatch filter against closed forms: a range ramp with white code noise of sigma and a clean carrier must come
// out with the noise reduced to about sigma / sqrt(n) (exactly: the filter's steady-state gain for n epochs),
// follow the ramp without lag, restart on a cycle slip or a new track, and shift with a receiver clock jump.
#include "receiver/carrier_smoothing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "receiver/loop_filters.hpp"
#include "signals/gps_constants.hpp"

using ultratrack::receiver::CarrierSmoothing;
using ultratrack::signals::kL1Wavelength_m;

namespace {
double range_at(int k) { return 2.2e7 + 650.0 * k * 0.1; }  // 650 m/s range rate, 10 Hz epochs
}  // namespace

TEST(CarrierSmoothing, ReducesCodeNoiseWithoutLag) {
  CarrierSmoothing filter(100);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);  // 1 m code noise
  double sum2 = 0.0;
  int count = 0;
  for (int k = 0; k < 1000; ++k) {
    const double r = range_at(k);
    const double s = filter.update(9, k, r + noise(rng), r / kL1Wavelength_m + 12345.0, k == 0);
    if (k >= 300) {  // well after the window filled
      sum2 += (s - r) * (s - r);
      ++count;
    }
  }
  // Steady state n = 100: an exponential average with gain 1/n has variance sigma^2 / (2n - 1) = 1/199.
  const double rms = std::sqrt(sum2 / count);
  EXPECT_NEAR(rms, std::sqrt(1.0 / 199.0), 0.25 * std::sqrt(1.0 / 199.0));
}

TEST(CarrierSmoothing, RestartsOnSlipNewTrackAndGap) {
  CarrierSmoothing filter(100, 20.0);
  for (int k = 0; k < 50; ++k)
    filter.update(4, k, range_at(k) + (k % 2 ? 3.0 : -3.0), range_at(k) / kL1Wavelength_m, k == 0);
  // A 1000-cycle slip (190 m) in the carrier: restart, so the output is the raw pseudorange.
  EXPECT_DOUBLE_EQ(filter.update(4, 50, range_at(50) + 3.0, range_at(50) / kL1Wavelength_m + 1000.0, false),
                   range_at(50) + 3.0);
  EXPECT_DOUBLE_EQ(filter.update(4, 51, range_at(51) - 3.0, range_at(51) / kL1Wavelength_m + 1000.0, true),
                   range_at(51) - 3.0);  // new track
  EXPECT_DOUBLE_EQ(filter.update(4, 60, range_at(60) + 3.0, range_at(60) / kL1Wavelength_m + 1000.0, false),
                   range_at(60) + 3.0);  // epochs 52-59 missing
}

TEST(CarrierSmoothing, ClockJumpShiftsTheSmoothedRange) {
  CarrierSmoothing filter(100);
  for (int k = 0; k < 20; ++k) filter.update(2, k, range_at(k), range_at(k) / kL1Wavelength_m, k == 0);
  const double dt = 1.5e-3;
  filter.clock_jump(dt);
  const double c = ultratrack::signals::kSpeedOfLight_mps;
  // After the jump the raw pseudorange is c dt shorter; no restart, and the output stays on the new range.
  const double s = filter.update(2, 20, range_at(20) - c * dt, range_at(20) / kL1Wavelength_m, false);
  EXPECT_NEAR(s, range_at(20) - c * dt, 1e-6);
}

// At 28 dB-Hz the DLL's thermal noise is ~9 m (dll_thermal_jitter_chips: 1 Hz, 1 chip E-L, 20 ms). A fixed 20 m
// jump test (2.2 sigma) restarted the filter every few epochs, so the PVT saw nearly raw pseudoranges; with the
// expected sigma the threshold is 6 sigma, the noise averages down as at 45 dB-Hz, and a gross jump still restarts.
TEST(CarrierSmoothing, CodeNoiseAtLowCn0DoesNotRestartTheFilter) {
  const double sigma_m = ultratrack::receiver::dll_thermal_jitter_chips(1.0, 1.0, 0.02, 28.0) *
                         ultratrack::signals::kSpeedOfLight_mps / ultratrack::signals::kCaChipRate_hz;
  EXPECT_NEAR(sigma_m, 8.9, 0.1);  // Kaplan eq. 5.72 by hand: 0.0303 chip
  const auto run = [&](double code_sigma_m) {
    CarrierSmoothing filter(100, 20.0);
    std::mt19937 rng(5);
    std::normal_distribution<double> noise(0.0, sigma_m);
    double sum2 = 0.0;
    int count = 0;
    for (int k = 0; k < 4000; ++k) {
      const double r = range_at(k);
      const double s = filter.update(9, k, r + noise(rng), r / kL1Wavelength_m + 777.0, k == 0, code_sigma_m);
      if (k >= 300) {
        sum2 += (s - r) * (s - r);
        ++count;
      }
    }
    return std::sqrt(sum2 / count);
  };
  // Steady state as above: sigma / sqrt(2n - 1) = 0.63 m. The RMS over 3700 epochs of an error correlated over
  // ~100 has ~37 independent samples: relative spread 1 / sqrt(2 x 37) = 12 %; 25 % is 2 sigma.
  EXPECT_NEAR(run(sigma_m), sigma_m / std::sqrt(199.0), 0.25 * sigma_m / std::sqrt(199.0));
  // The fixed 20 m test alone (no sigma given) restarts on the noise: several times the steady-state error.
  EXPECT_GT(run(0.0), 4.0 * sigma_m / std::sqrt(199.0));
  // A gross jump (a 1000-cycle carrier slip, 190 m) still restarts the filter at this sigma (6 sigma = 53 m).
  CarrierSmoothing filter(100, 20.0);
  for (int k = 0; k < 50; ++k) filter.update(4, k, range_at(k), range_at(k) / kL1Wavelength_m, k == 0, sigma_m);
  EXPECT_DOUBLE_EQ(filter.update(4, 50, range_at(50) + 3.0, range_at(50) / kL1Wavelength_m + 1000.0, false, sigma_m),
                   range_at(50) + 3.0);
}
