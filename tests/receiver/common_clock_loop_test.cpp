// SPDX-License-Identifier: GPL-3.0-or-later
// The common clock loop (receiver/common_clock_loop.hpp) against closed forms: a second-order loop follows a
// frequency step with no standing phase error; combining N channels' prompts divides the noise variance by N (the
// loop's output spread by sqrt(N)); prompts combine by their amplitudes (maximal-ratio: the combined phasor of
// two groups is their A^2-weighted sum); a frequency step through the serial loop's delay settles and rings through
// the pipelined one's; the data bit, known or decided by the in-phase sign, does not turn the
// sum; too few channels hold the loop; and a steered channel chooses its coherent time on thermal jitter alone.
#include "receiver/common_clock_loop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "receiver/long_coherent.hpp"
#include "receiver/scalar_tracking_options.hpp"

using namespace ultratrack::receiver;

namespace {

// A 20 ms prompt of a channel at cn0_dbhz whose replica is error_rad behind the signal (unit noise per arm; no noise
// added here).
ChannelPrompt prompt(double error_rad, double cn0_dbhz, int bit = 1, int bit_sign = 0) {
  const double a = std::sqrt(2.0 * std::pow(10.0, cn0_dbhz / 10.0) * 0.02);
  return {bit * a * std::cos(error_rad), bit * a * std::sin(error_rad), bit_sign, cn0_dbhz};
}

// Standard deviation of the loop's frequency over `updates` updates of a closed loop on a perfect clock whose n
// channels' prompts carry unit white noise per arm (35 dB-Hz each).
double frequency_spread_hz(int n, int updates, std::uint64_t seed) {
  CommonClockLoop loop;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<ChannelPrompt> prompts(static_cast<std::size_t>(n));
  double sum = 0.0, sum2 = 0.0, replica_rad = 0.0;
  int counted = 0;
  for (int k = 0; k < updates; ++k) {
    for (auto& p : prompts) {
      p = prompt(-replica_rad, 35.0);
      p.i += noise(rng);
      p.q += noise(rng);
    }
    const double f = loop.update(prompts);
    replica_rad += 2.0 * std::numbers::pi * f * loop.options().period_s;
    if (k < 200) continue;  // the start
    sum += f;
    sum2 += f * f;
    ++counted;
  }
  const double mean = sum / counted;
  return std::sqrt(sum2 / counted - mean * mean);
}

// The loop closed through a delay: the frequency computed from epoch n's prompts runs from epoch n + delay on, the
// signal's frequency steps by 1 Hz at the start; noise-free prompts of 6 channels at 30 dB-Hz carry each epoch's mean
// phase error. Returns the NCO's largest frequency overshoot beyond the step and its largest error 1-2 s after it (Hz).
std::pair<double, double> step_through_delay(int delay) {
  CommonClockLoop loop;
  const double T = loop.options().period_s, step_hz = 1.0;
  std::vector<double> in_flight(static_cast<std::size_t>(delay), 0.0);  // in_flight[0] runs in this epoch
  double signal_rad = 0.0, replica_rad = 0.0, overshoot_hz = 0.0, late_hz = 0.0;
  for (int k = 0; k < 150; ++k) {
    const double nco_hz = in_flight.front();
    const double mean_error_rad = signal_rad - replica_rad + std::numbers::pi * T * (step_hz - nco_hz);
    signal_rad += 2.0 * std::numbers::pi * step_hz * T;
    replica_rad += 2.0 * std::numbers::pi * nco_hz * T;
    overshoot_hz = std::max(overshoot_hz, nco_hz - step_hz);
    if (k >= 50 && k < 100) late_hz = std::max(late_hz, std::abs(nco_hz - step_hz));
    const std::vector<ChannelPrompt> prompts(6, prompt(mean_error_rad, 30.0));
    in_flight.erase(in_flight.begin());
    in_flight.push_back(loop.update(prompts));
  }
  return {overshoot_hz, late_hz};
}

}  // namespace

TEST(CommonClockLoop, FollowsAFrequencyStepWithNoStandingPhaseError) {
  CommonClockLoop loop;  // 5 Hz, 20 ms
  const double step_hz = 2.0, T = loop.options().period_s;
  double replica_rad = 0.0, worst_rad = 0.0;
  for (int k = 0; k < 150; ++k) {  // 3 s
    const double error_rad = 2.0 * std::numbers::pi * step_hz * k * T - replica_rad;
    worst_rad = std::max(worst_rad, std::abs(error_rad));
    const std::vector<ChannelPrompt> prompts(6, prompt(error_rad, 30.0));
    replica_rad += 2.0 * std::numbers::pi * loop.update(prompts) * T;
  }
  // Transient peak well inside the Costas range (a 2 Hz step against w0 = 9.4 rad/s), then none left.
  EXPECT_LT(worst_rad, 0.8);
  EXPECT_NEAR(2.0 * std::numbers::pi * step_hz * 150 * T - replica_rad, 0.0, 1e-3);
  EXPECT_NEAR(loop.frequency_hz(), step_hz, 1e-3);
  EXPECT_EQ(loop.channels_used(), 6);
  EXPECT_EQ(loop.updates(), 150);
}

// Why the ultra-tight loop runs serially by default (pipelines/receive_options.hpp): its commands run two epochs after
// the prompts they came from, the pipelined loop's three, and that epoch nearly undamps the 5 Hz loop. Against the
// discrete model benchmarks/validation/clock_loop_model.py `delay` (independent of this code): a 1 Hz step overshoots
// by 0.274, 0.520 and 0.983 Hz at delays 1, 2 and 3, and 1-2 s after it 0.0001, 0.0000 and 0.053 Hz remain.
TEST(CommonClockLoop, AStepThroughTheSerialLoopsDelaySettlesAndThroughOneMoreEpochRings) {
  const auto [overshoot1, late1] = step_through_delay(1);
  const auto [overshoot2, late2] = step_through_delay(2);
  const auto [overshoot3, late3] = step_through_delay(3);
  EXPECT_NEAR(overshoot1, 0.274, 0.005);
  EXPECT_NEAR(overshoot2, 0.520, 0.005);
  EXPECT_NEAR(overshoot3, 0.983, 0.005);
  EXPECT_LT(late1, 0.001);
  EXPECT_LT(late2, 0.001);
  EXPECT_NEAR(late3, 0.053, 0.002);
}

TEST(CommonClockLoop, CombiningNChannelsDividesTheSpreadBySqrtN) {
  // ~60 000 updates with a ~7-update correlation time: each spread to ~1.5 %, the ratio to ~2 %.
  const double four = frequency_spread_hz(4, 60000, 3), sixteen = frequency_spread_hz(16, 60000, 4);
  EXPECT_NEAR(four / sixteen, 2.0, 0.1);
}

TEST(CommonClockLoop, PromptsCombineByTheirAmplitudes) {
  CommonClockLoop loop;
  std::vector<ChannelPrompt> prompts;
  for (int i = 0; i < 4; ++i) prompts.push_back(prompt(0.0, 45.0));
  for (int i = 0; i < 4; ++i) prompts.push_back(prompt(0.4, 35.0));
  loop.update(prompts);
  // Weights A: the sum is 4 A45^2 (1, 0) + 4 A35^2 (cos 0.4, sin 0.4), A35^2 = A45^2 / 10.
  EXPECT_NEAR(loop.mean_phase_rad(), std::atan2(0.1 * std::sin(0.4), 1.0 + 0.1 * std::cos(0.4)), 1e-12);
  EXPECT_EQ(loop.channels_used(), 8);
  const double a45_2 = 2.0 * std::pow(10.0, 4.5) * 0.02;
  EXPECT_NEAR(loop.mean_phase_sigma_rad(), 1.0 / std::sqrt(4.4 * a45_2), 1e-12);
}

TEST(CommonClockLoop, TheDataBitDoesNotTurnTheSum) {
  // Inverted bits, decided by the in-phase sign or given as known, leave the same combined phase; a known bit
  // keeps the four-quadrant phase that an in-phase decision folds into (-pi/2, pi/2].
  CommonClockLoop decided, known;
  std::vector<ChannelPrompt> mixed, given;
  for (int i = 0; i < 6; ++i) {
    const int bit = i % 2 == 0 ? 1 : -1;
    mixed.push_back(prompt(0.3, 30.0, bit));
    given.push_back(prompt(2.0, 30.0, bit, bit));
  }
  decided.update(mixed);
  known.update(given);
  EXPECT_NEAR(decided.mean_phase_rad(), 0.3, 1e-12);
  EXPECT_NEAR(known.mean_phase_rad(), 2.0, 1e-12);
}

TEST(CommonClockLoop, HoldsWithTooFewChannelsAndIgnoresNonFiniteEntries) {
  CommonClockLoop loop;
  const std::vector<ChannelPrompt> warm(5, prompt(0.3, 30.0));
  const double f = loop.update(warm);
  EXPECT_NE(f, 0.0);
  std::vector<ChannelPrompt> few(3, prompt(0.5, 30.0));
  few.push_back({NAN, 1.0, 0, 30.0});
  few.push_back({1.0, 1.0, 0, NAN});
  EXPECT_EQ(loop.update(few), f);
  EXPECT_EQ(loop.channels_used(), 3);
  EXPECT_EQ(loop.updates(), 1);
}

TEST(CommonClockLoop, RejectsBadOptions) {
  EXPECT_THROW(CommonClockLoop({0.0, 0.02, 4}), std::invalid_argument);
  EXPECT_THROW(CommonClockLoop({15.0, 0.02, 4}), std::invalid_argument);  // Bn T = 0.3
  EXPECT_THROW(CommonClockLoop({5.0, 0.0, 4}), std::invalid_argument);
  EXPECT_THROW(CommonClockLoop({5.0, 0.02, 0}), std::invalid_argument);
  EXPECT_THROW(CommonClockLoop({NAN, 0.02, 4}), std::invalid_argument);
}

// A steered channel (its oscillator tracked by the common loop) chooses as if its clock were perfect: with the TCXO
// default, 100 ms below 30.2 dB-Hz instead of 20 ms at every level.
TEST(CommonClockLoop, SteeredChannelsChooseTheirCoherentTimeOnThermalJitter) {
  const ScalarTrackingOptions tcxo;  // the default oscillator
  ScalarTrackingOptions ideal;
  ASSERT_TRUE(set_tracking_oscillator(ideal, "ideal"));
  for (const double cn0 : {20.0, 25.0, 29.0, 35.0, 45.0})
    EXPECT_EQ(choose_coherent_epochs(tcxo, cn0, 1, true), choose_coherent_epochs(ideal, cn0, 1)) << cn0;
  EXPECT_EQ(choose_coherent_epochs(tcxo, 25.0, 1, true), 5);
  EXPECT_EQ(choose_coherent_epochs(tcxo, 25.0, 1, false), 1);
}
