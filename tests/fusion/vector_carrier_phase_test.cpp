// SPDX-License-Identifier: GPL-3.0-or-later
// The vector PLL's per-channel carrier states (fusion/vector_carrier_phase.hpp) closed around a simulated signal:
// a carrier whose phase is known exactly (the truth), a prediction that misses its Doppler by a constant, prompt
// correlations with Gaussian noise at a known C/N0 and random data bits, and a replica run as the vector filter
// runs it (each epoch's command computed after the previous epoch, from the states). Checks: the replica's phase
// error against the truth is the closed-form jitter of the loop's own bandwidth, the frequency residual converges
// on the prediction's miss, the Costas discriminator ignores the bits, and the lock test drops a signal-free channel.
#include "fusion/vector_carrier_phase.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "fusion/vector_tracking.hpp"

namespace {

using namespace ultratrack::fusion;

constexpr double kFs = 1.0e6;
constexpr double kT = 0.02;
constexpr std::int64_t kEpoch = 20000;

struct LoopResult {
  double rms_cycles = 0.0, max_cycles = 0.0;
  double nu_hz = 0.0, bn_hz = 0.0;
  double prior_sigma_cycles = 0.0;  // RMS of the loop's own prior sigma over the settled epochs
  bool locked = true;
};

// n epochs of a signal of phase psi0 + (f_pred + miss) t, its prompt I + jQ = A d e^{j 2 pi (psi - replica)} +
// noise with unit variance per component, A = sqrt(2 C/N0 T) (so |A|^2 / E|noise|^2 = C/N0 T). The replica of
// epoch k+1 is commanded after epoch k (frequency and phase at its start), as the filter does one epoch late.
LoopResult run_loop(double cn0_dbhz, double miss_hz, int n, bool signal, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::bernoulli_distribution bit(0.5);
  const double c = std::pow(10.0, cn0_dbhz / 10.0);
  const double amplitude = signal ? std::sqrt(2.0 * c * kT) : 0.0;
  const double f_pred = 1234.5, psi0 = 0.3;
  const auto truth = [&](std::int64_t s) { return psi0 + (f_pred + miss_hz) * static_cast<double>(s) / kFs; };
  VectorCarrierPhase ph{VectorPllOptions{}};
  const double variance = costas_phase_variance_cycles2(c, kT);
  // The replica: start phase and frequency of each epoch.
  double rep_start = psi0 + 0.05, rep_f = f_pred;  // the hand-over leaves it 0.05 cycles off
  LoopResult r;
  double sum2 = 0.0;
  int counted = 0;
  for (int k = 0; k < n; ++k) {
    const std::int64_t first = k * kEpoch, mid = first + kEpoch / 2, next = first + kEpoch;
    const double rep_mid = rep_start + rep_f * kT / 2.0;
    // The prompt over the epoch: the mean of the phasor of a linear phase error (e0 at the middle, slope d).
    const double e_mid = truth(mid) - rep_mid, slope = (f_pred + miss_hz - rep_f) * kT;
    const double sinc = slope == 0.0 ? 1.0 : std::sin(M_PI * slope) / (M_PI * slope);
    const double d = bit(rng) ? 1.0 : -1.0;
    const double i = amplitude * d * sinc * std::cos(2.0 * M_PI * e_mid) + noise(rng);
    const double q = amplitude * d * sinc * std::sin(2.0 * M_PI * e_mid) + noise(rng);
    if (k == 0) {
      ph.start(mid, rep_mid, costas_discriminator_cycles(i, q), 0.0, variance);
    } else {
      const double base = ph.commanded_base_hz((ph.sample() + mid) / 2);
      ph.propagate(mid, kFs, std::isfinite(base) ? base : f_pred);
      ph.update(i, q, rep_mid, variance, kT);
    }
    if (k >= n / 2) {  // settled: the replica's error at the middle of this epoch (modulo the Costas half cycle)
      double e = e_mid - std::round(e_mid / 0.5) * 0.5;
      sum2 += e * e;
      r.prior_sigma_cycles += ph.prior_sigma_phase_cycles() * ph.prior_sigma_phase_cycles();
      r.max_cycles = std::max(r.max_cycles, std::abs(e));
      ++counted;
    }
    // The command for epoch k+1 (the filter's: phase at its start from the states, frequency = prediction + nu).
    const double base = ph.commanded_base_hz((ph.sample() + next) / 2);
    rep_start = ph.phase_at(next, kFs, std::isfinite(base) ? base : f_pred);
    rep_f = f_pred + ph.nu_hz();
    ph.record_command(next, f_pred);
  }
  r.rms_cycles = std::sqrt(sum2 / counted);
  r.prior_sigma_cycles = std::sqrt(r.prior_sigma_cycles / counted);
  r.nu_hz = ph.nu_hz();
  r.bn_hz = ph.last_bandwidth_hz();
  r.locked = ph.locked();
  return r;
}

double jitter_cycles(double bn_hz, double cn0_dbhz) {
  const double c = std::pow(10.0, cn0_dbhz / 10.0);
  return std::sqrt(bn_hz / c * (1.0 + 1.0 / (2.0 * kT * c))) / (2.0 * M_PI);
}

}  // namespace

TEST(VectorCarrierPhase, CostasDiscriminatorIsBitInsensitiveAndBounded) {
  for (double phi : {-0.2, -0.05, 0.0, 0.1, 0.24}) {
    const double i = std::cos(2.0 * M_PI * phi), q = std::sin(2.0 * M_PI * phi);
    EXPECT_NEAR(costas_discriminator_cycles(i, q), phi, 1e-12);
    EXPECT_NEAR(costas_discriminator_cycles(-i, -q), phi, 1e-12);  // a data bit flips both
  }
  EXPECT_DOUBLE_EQ(costas_discriminator_cycles(0.0, 1.0), 0.25);
  EXPECT_DOUBLE_EQ(costas_discriminator_cycles(0.0, 0.0), 0.0);
}

// At 45 and 30 dB-Hz with a 3 Hz prediction miss: the residual nu converges on the miss (its steady-state sigma
// from the gains is ~0.1-0.3 Hz: bound 0.5 Hz), and the replica's phase error RMS (1000 settled epochs: the RMS
// estimate is good to ~3 %) is at most the loop's own prior sigma + 15 % (the replica of an epoch is commanded
// before that epoch's discriminator, so it carries the prior error; here below it by the modelled frequency noise
// that this constant miss does not have: 0.0047 vs 0.0056 cycles at 45 dB-Hz). That is larger than the continuous-loop
// closed form at the same bandwidth (sigma^2 = Bn / C/N0 (1 + 1 / (2 T C/N0))) by the one-epoch delay at Bn T ~
// 0.1-0.3: measured 1.3-1.4 x here (printed); bounded by 1.6 x, and no lower than the closed form. Lock kept, no epoch
// near a slip.
TEST(VectorCarrierPhase, ClosedLoopJitterIsTheLoopsOwnSigmaAndNearTheClosedForm) {
  for (double cn0 : {45.0, 30.0}) {
    const LoopResult r = run_loop(cn0, 3.0, 2000, true, 7);
    const double closed = jitter_cycles(r.bn_hz, cn0);
    std::printf(
        "%.0f dB-Hz: RMS %.4f cycles (loop prior sigma %.4f; closed form %.4f at Bn %.1f Hz), max %.4f, nu "
        "%.3f Hz\n",
        cn0, r.rms_cycles, r.prior_sigma_cycles, closed, r.bn_hz, r.max_cycles, r.nu_hz);
    EXPECT_TRUE(r.locked);
    EXPECT_NEAR(r.nu_hz, 3.0, 0.5);
    EXPECT_LE(r.rms_cycles, 1.15 * r.prior_sigma_cycles);
    EXPECT_LE(r.rms_cycles, 1.6 * closed);
    EXPECT_GE(r.rms_cycles, closed);
    EXPECT_LT(r.max_cycles, 0.2);
    EXPECT_GT(r.bn_hz, 1.0);
    EXPECT_LT(r.bn_hz, 25.0);
  }
}

// Noise alone (the signal gone): the lock indicator's mean falls to ~0 (sigma ~0.14) and the test declares the
// loss after lock_average_s + loss_time_s (0.8 s); a locked 45 dB-Hz signal reads ~1. Several noise seeds.
TEST(VectorCarrierPhase, LockTestDropsANoiseOnlyChannel) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    EXPECT_FALSE(run_loop(45.0, 0.0, 100, false, seed).locked) << seed;  // 2 s
    EXPECT_TRUE(run_loop(45.0, 0.0, 100, true, seed).locked) << seed;
  }
}

TEST(VectorCarrierPhase, LoopBandwidthOfTheGains) {
  // Kaplan & Hegarty: a second-order loop with zeta = 1/sqrt(2), w0: Bn = 0.53 w0. Gains from 2 zeta w0 = k1 / T,
  // w0^2 = k2 / T.
  const double w0 = 30.0, k1 = 2.0 / std::sqrt(2.0) * w0 * kT, k2 = w0 * w0 * kT;
  EXPECT_NEAR(loop_noise_bandwidth_hz(k1, k2, kT), 0.5303 * w0, 0.01 * w0);
  EXPECT_TRUE(std::isnan(loop_noise_bandwidth_hz(0.0, k2, kT)));
}
