// SPDX-License-Identifier: GPL-3.0-or-later
// Long coherent integration with data wipe-off on the independent test signal: a channel locked on a strong
// signal that then fades to 20 dB-Hz keeps lock (phase within the Costas range of the truth, code within a
// tenth of a chip) with known bits and 100 ms coherent, and loses it with 20 ms; the choice of the integration
// time against the thermal-jitter thresholds, with hysteresis.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <random>
#include <vector>

#include "channel_feed.hpp"
#include "io/why_invalid.hpp"
#include "receiver/scalar_tracking.hpp"

using namespace ultratrack;
using namespace ultratrack::receiver;

namespace {
constexpr double kFs = 2.5e6;

struct Outcome {
  bool lost = false;
  double lost_at_s = -1.0;
  int max_loop_ms = 0;
  int switches = 0;  // changes of the loops' integration time after the fade settles (t > 6 s)
  std::vector<double> phase_error_cycles, code_error_chips;  // after the fade settles (t > 6 s)
};

// 45 dB-Hz until fade_s, weak_dbhz after (one phase-continuous signal); known bits from the truth when `known`.
Outcome run(const ScalarTrackingOptions& opt_in, bool known, double weak_dbhz, double fade_s, double duration_s,
            std::uint64_t seed = 11, double doppler_rate_hzps = 0.5) {
  const ScalarTrackingOptions& opt = opt_in;
  test::TestSatellite strong;
  strong.prn = 7;
  strong.cn0_dbhz = 45.0;
  strong.doppler_hz = -900.0;
  strong.doppler_rate_hzps = doppler_rate_hzps;
  strong.code_phase_chips = 511.7;
  strong.carrier_phase_cycles = 0.21;
  std::mt19937 rng(7);
  for (int k = 0; k < 1000; ++k) strong.bits.push_back(rng() & 1u ? 1 : -1);
  strong.bit_offset_periods = 6;
  strong.stop_s = fade_s;
  test::TestSatellite weak = strong;
  weak.cn0_dbhz = weak_dbhz;
  weak.start_s = fade_s;
  weak.stop_s = 1e30;

  ChannelStart start;
  start.code_phase_chips = std::fmod(strong.code_phase_chips - 0.15, 1023.0);
  start.carrier_frequency_hz = strong.doppler_hz + 25.0;
  TrackingChannel channel(channel_config(opt, strong.prn, kFs), start);
  ScalarTracking loop(opt, channel.current_command());
  const test::TestSignal sig{kFs, true, seed};
  // the signal's bit (+1/-1) during the 20 ms epoch starting at time t (on a bit edge)
  const auto true_bit = [&](double t_mid) {
    const double period = test::true_code_phase_chips(strong, t_mid) / 1023.0;
    const auto k = static_cast<std::int64_t>(std::floor((period + strong.bit_offset_periods) / 20.0));
    return strong.bits[static_cast<std::size_t>(k % static_cast<std::int64_t>(strong.bits.size()))];
  };
  int polarity = 0;  // the Costas loop's half-cycle: resolved by the first bit-synced prompt (45 dB-Hz)
  Outcome out;
  int last_loop_ms = 0;
  const std::int64_t block = 125000;
  test::feed_generated(
      channel, {strong, weak}, sig, static_cast<std::int64_t>(duration_s * kFs), block, [&](const CorrelationEpoch& e) {
        const double t = e.first_sample / kFs;
        KnownBits k;
        const int wanted = loop.known_bits_wanted();
        if (known && polarity != 0 && wanted > 0 && e.num_code_periods == 20) {
          k.sign = polarity * true_bit(t + 0.01);
          k.ahead = wanted;
        }
        const TrackingReport r = loop.update(e, k);
        if (r.state == TrackingState::kBitSynced && polarity == 0 && t < fade_s - 0.1)
          polarity = (e.master().prompt.real() >= 0.0f ? 1 : -1) * true_bit(t + 0.01);
        channel.command(r.command);
        if (r.set_coherent) channel.set_coherent_periods(r.coherent_periods, r.aligned_period);
        out.max_loop_ms = std::max(out.max_loop_ms, r.loop_integration_ms);
        if (r.state == TrackingState::kLost) {
          out.lost = true;
          out.lost_at_s = t;
          return false;
        }
        if (t > 6.0 && r.state == TrackingState::kBitSynced) {
          out.switches += last_loop_ms != 0 && r.loop_integration_ms != last_loop_ms;
          last_loop_ms = r.loop_integration_ms;
          out.phase_error_cycles.push_back(test::costas_phase_error_cycles(strong, e, kFs));
          // the epoch starts where the replica crosses a period start: the truth's phase there is the code error
          out.code_error_chips.push_back(
              std::remainder(test::true_code_phase_chips(strong, t) - e.code_phase_start_chips, 1023.0));
        }
        return true;
      });
  return out;
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return v.empty() ? NAN : std::sqrt(s / static_cast<double>(v.size()));
}
}  // namespace

TEST(LongCoherent, KeepsLockAt20DbHzWithKnownBitsAndLosesItAt20Ms) {
  ScalarTrackingOptions opt;              // defaults: up to 100 ms, adaptive
  set_tracking_oscillator(opt, "ideal");  // the test signal's clock is perfect
  const Outcome longer = run(opt, true, 20.0, 3.0, 14.0);
  EXPECT_FALSE(longer.lost) << "lost at " << longer.lost_at_s << " s";
  EXPECT_EQ(longer.max_loop_ms, 100);
  ASSERT_GT(longer.phase_error_cycles.size(), 300u);
  // Thermal jitter of the 2 Hz loop at 20 dB-Hz, T = 0.1 s: sqrt(2 / 100 (1 + 1 / 20)) = 0.145 rad = 0.023
  // cycles; the digital loop at Bn T = 0.2 is ~55 % wider (0.029), and 20 ms epochs read the phase between updates.
  EXPECT_LT(rms(longer.phase_error_cycles), 0.05);
  EXPECT_LT(rms(longer.code_error_chips), 0.1);

  ScalarTrackingOptions plain = opt;
  plain.max_coherent_ms = 20;
  const Outcome short_only = run(plain, false, 20.0, 3.0, 14.0);
  EXPECT_TRUE(short_only.lost);
  EXPECT_EQ(short_only.max_loop_ms, 20);
  // Without known bits the adaptive choice cannot take effect: 20 ms, and lock is lost as well.
  const Outcome unknown = run(opt, false, 20.0, 3.0, 14.0);
  EXPECT_TRUE(unknown.lost);
  EXPECT_EQ(unknown.max_loop_ms, 20);
}

// At 30 dB-Hz, next to the 20 / 100 ms choice (30.2 dB-Hz, 2 dB hysteresis), the 0.2 s C/N0 estimates (spread
// ~1.5 dB) switch the loops between 20 ms (5 Hz) and 100 ms (2 Hz) every second or so. A Doppler ramp of 4 Hz/s
// (0.76 m/s^2 along the line of sight: issue 7's accelerating test bed) must not turn the switches into phase
// excursions. Before the fix each switch to 100 ms started the narrow loop 0.32 Hz off (its frequency state was
// referenced to the 20 ms update) and held the last 20 ms command, proportional-term noise included, for 100 ms:
// excursions of 40-65 deg, RMS 14-21 deg against the truth, and 5 of 30 satellite-runs lost at 30 dB-Hz in the
// issue-7 threshold runs while every one was kept at 26-28 dB-Hz.
TEST(LongCoherent, SwitchingTheCoherentTimeOnADopplerRampKeepsThePhase) {
  ScalarTrackingOptions opt;              // defaults: adaptive, up to 100 ms
  set_tracking_oscillator(opt, "ideal");  // the test signal's clock is perfect
  const Outcome o = run(opt, true, 30.0, 3.0, 20.0, 100, 4.0);
  EXPECT_FALSE(o.lost) << "lost at " << o.lost_at_s << " s";
  EXPECT_GE(o.switches, 6) << "the test needs switches between the integration times";
  ASSERT_GT(o.phase_error_cycles.size(), 300u);
  // Thermal jitter at 30 dB-Hz (sqrt(Bn / c (1 + 1 / (2 T c)))): 4.1 deg for the 5 Hz loop at 20 ms (x1.2 for
  // the digital loop at Bn T = 0.1: 4.9 deg), 2.6 deg for the 2 Hz loop at 100 ms (x1.55: 4.0 deg). Allowed: twice
  // the wider loop's, 10 deg RMS (measured 4.6-8.0 over 37 s on four seeds after the fix, 14-21 before).
  EXPECT_LT(rms(o.phase_error_cycles) * 360.0, 10.0);
  // The phase lock indicator's loss threshold 0.3 = cos(2 x 36.3 deg): no excursion may reach it.
  double worst = 0.0;
  for (const double p : o.phase_error_cycles) worst = std::max(worst, std::abs(p) * 360.0);
  EXPECT_LT(worst, 36.0);
}

TEST(LongCoherent, StrongSignalStaysOn20Ms) {
  ScalarTrackingOptions opt;
  const Outcome strong = run(opt, true, 45.0, 3.0, 7.0);
  EXPECT_FALSE(strong.lost);
  EXPECT_EQ(strong.max_loop_ms, 20);
}

TEST(LongCoherent, ChoiceFollowsTheJitterThresholdsWithHysteresis) {
  ScalarTrackingOptions o;              // 5 Hz at 20 ms, Bn T <= 0.2, 4 deg, 2 dB, up to 100 ms
  set_tracking_oscillator(o, "ideal");  // thermal jitter only
  // Kaplan's thermal jitter sqrt(Bn / c (1 + 1 / (2 T c))) reaches 4 deg at 30.21 dB-Hz (20 ms, 5 Hz), 30.16
  // (40 ms, 5 Hz), 26.18 (100 ms, 2 Hz), 23.17 (200 ms, 1 Hz) and 20.16 (400 ms, 0.5 Hz).
  EXPECT_NEAR(pll_thermal_jitter_rad(5.0, 0.02, 30.21) * 180 / M_PI, 4.0, 0.01);
  EXPECT_NEAR(pll_thermal_jitter_rad(2.0, 0.1, 26.18) * 180 / M_PI, 4.0, 0.01);
  EXPECT_DOUBLE_EQ(long_coherent_pll_bw_hz(o, 1), 5.0);
  EXPECT_DOUBLE_EQ(long_coherent_pll_bw_hz(o, 5), 2.0);
  EXPECT_EQ(choose_coherent_epochs(o, 30.4, 1), 1);
  EXPECT_EQ(choose_coherent_epochs(o, 30.19, 1), 2);
  EXPECT_EQ(choose_coherent_epochs(o, 29.0, 1), 5);
  EXPECT_EQ(choose_coherent_epochs(o, 15.0, 1), 5);  // below every threshold: the longest allowed
  // back up only 2 dB above the threshold
  EXPECT_EQ(choose_coherent_epochs(o, 31.0, 5), 5);
  EXPECT_EQ(choose_coherent_epochs(o, 32.1, 5), 5);
  EXPECT_EQ(choose_coherent_epochs(o, 32.3, 5), 1);
  EXPECT_EQ(choose_coherent_epochs(o, 32.1, 2), 2);
  o.max_coherent_ms = 400;
  EXPECT_EQ(choose_coherent_epochs(o, 25.0, 5), 10);
  EXPECT_EQ(choose_coherent_epochs(o, 22.0, 5), 20);
  EXPECT_EQ(choose_coherent_epochs(o, 24.5, 20), 20);
  EXPECT_EQ(choose_coherent_epochs(o, 27.0, 20), 10);
  EXPECT_EQ(choose_coherent_epochs(o, 28.3, 20), 5);
  o.adaptive_coherent = false;
  EXPECT_EQ(choose_coherent_epochs(o, 45.0, 1), 20);
  o.max_coherent_ms = 20;
  EXPECT_EQ(choose_coherent_epochs(o, 10.0, 1), 1);
  o.max_coherent_ms = 60;
  EXPECT_NE(io::why_invalid(o), "");
}

// The oscillator's jitter in closed form against a numerical integration of the analogue loop's error response
// (trapezoid on a log grid, independent of the closed form), for both loop orders; and a TCXO's figures.
TEST(LongCoherent, OscillatorJitterMatchesTheLoopsErrorResponse) {
  constexpr double kTwoPiL1 = 2.0 * M_PI * 1575.42e6;
  for (const int order : {2, 3}) {
    for (const double bn : {2.0, 5.0, 15.0}) {
      const double w0 = bn / (order == 2 ? 0.53 : 0.7845);
      // |E(jw) / (clock phase driver)|^2 for white frequency (phase = W / s) and random-walk frequency (W / s^2).
      const auto response = [&](double w, int driver_order) {
        const std::complex<double> s(0.0, w);
        const std::complex<double> d = order == 2 ? s * s + std::sqrt(2.0) * w0 * s + w0 * w0
                                                  : s * s * s + 2.4 * w0 * s * s + 1.1 * w0 * w0 * s + w0 * w0 * w0;
        const std::complex<double> e = (order == 2 ? s * s : s * s * s) / d;  // error / phase
        return std::norm(e / std::pow(s, driver_order));
      };
      const auto integral = [&](int driver_order) {
        double sum = 0.0;
        for (double w = 1e-5 * w0; w < 1e5 * w0; w *= 1.001)
          sum += 0.5 * (response(w, driver_order) + response(w * 1.001, driver_order)) * w * 0.001;
        return 2.0 * sum / (2.0 * M_PI);  // both signs of w
      };
      const double h0 = 2e-19, h2 = 2e-20;
      const double q_w = kTwoPiL1 * kTwoPiL1 * h0 / 2.0, q_rw = kTwoPiL1 * kTwoPiL1 * 2.0 * M_PI * M_PI * h2;
      const double numeric = std::sqrt(q_w * integral(1) + q_rw * integral(2));
      EXPECT_NEAR(pll_oscillator_jitter_rad(bn, order, h0, h2) / numeric, 1.0, 2e-3) << order << " " << bn;
    }
  }
  // Brown & Hwang's TCXO random-walk frequency alone: 48 deg in a 2 Hz third-order loop, 12 deg at 5 Hz.
  EXPECT_NEAR(pll_oscillator_jitter_rad(2.0, 3, 0.0, 2e-20) * 180 / M_PI, 48.4, 0.2);
  EXPECT_NEAR(pll_oscillator_jitter_rad(5.0, 3, 0.0, 2e-20) * 180 / M_PI, 12.2, 0.1);
}

// With the oscillator known, N minimises the total jitter: a TCXO keeps the 5 Hz loop of 20 ms at any C/N0, its
// clock jitter (12 deg at 5 Hz, 48 deg at 2 Hz) growing faster than the thermal falls as the loop narrows (40 ms at
// 5 Hz gains < 5 %: not worth its bits); an OCXO (2.3 deg at 2 Hz) leaves the thermal choice.
TEST(LongCoherent, ChoiceWithAnOscillatorMinimisesTheTotalJitter) {
  ScalarTrackingOptions o;  // the default: a TCXO (oscillator_signal_preset)
  EXPECT_EQ(tracking_oscillator_name(o), "tcxo");
  EXPECT_NEAR(o.oscillator_h0, 9.36e-23, 0.01e-23);
  EXPECT_DOUBLE_EQ(o.oscillator_h_minus2, 2e-20);
  EXPECT_EQ(choose_coherent_epochs(o, 45.0, 1), 1);
  EXPECT_EQ(choose_coherent_epochs(o, 29.0, 1), 1);
  EXPECT_EQ(choose_coherent_epochs(o, 20.0, 1), 1);
  EXPECT_EQ(choose_coherent_epochs(o, 29.0, 5), 1);
  EXPECT_TRUE(set_tracking_oscillator(o, "ocxo"));
  EXPECT_EQ(tracking_oscillator_name(o), "ocxo");
  EXPECT_NEAR(o.oscillator_h0, 2.0e-23, 0.01e-23);
  EXPECT_DOUBLE_EQ(o.oscillator_h_minus2, 4e-23);
  EXPECT_EQ(choose_coherent_epochs(o, 29.0, 1), 5);
  EXPECT_TRUE(set_tracking_oscillator(o, "none"));  // a perfect clock, as "ideal"
  EXPECT_EQ(tracking_oscillator_name(o), "ideal");
  EXPECT_FALSE(set_tracking_oscillator(o, "rubidium"));
  EXPECT_EQ(tracking_oscillator_name(o), "ideal");  // unchanged
  o.oscillator_h0 = 1e-22;
  EXPECT_EQ(tracking_oscillator_name(o), "custom");
  o.oscillator_h_minus2 = 1e-16;
  EXPECT_NE(io::why_invalid(o), "");
}

// The measurement of docs/validation.md (issue 7, long coherent integration): locked at 45 dB-Hz for 3 s, then
// faded to each level for 12 s; the fraction of runs that keep lock, 20 ms against up to 100 ms with known bits.
// Run with --gtest_also_run_disabled_tests --gtest_filter=LongCoherent.DISABLED_FadeSweep (minutes of CPU).
TEST(LongCoherent, DISABLED_FadeSweep) {
  ScalarTrackingOptions on, off;
  set_tracking_oscillator(on, "ideal");  // the test signal's clock is perfect
  set_tracking_oscillator(off, "ideal");
  off.max_coherent_ms = 20;
  for (const double level : {14.0, 16.0, 18.0, 20.0, 22.0, 24.0, 26.0}) {
    int kept_on = 0, kept_off = 0;
    constexpr int kSeeds = 5;
    for (int seed = 0; seed < kSeeds; ++seed) {
      kept_on += !run(on, true, level, 3.0, 15.0, 100 + seed).lost;
      kept_off += !run(off, false, level, 3.0, 15.0, 100 + seed).lost;
    }
    std::printf("fade to %.0f dB-Hz: kept 12 s with 20 ms %d/%d, with known bits up to 100 ms %d/%d\n", level, kept_off,
                kSeeds, kept_on, kSeeds);
  }
}
