// SPDX-License-Identifier: GPL-3.0-or-later
// Tracking channel: epoch boundaries at code-period starts, block-size independence, 20 ms epochs aligned to
// a given period, phase jumps, the phase-accurate NCO over 300 s against the closed form, and antennas.
#include "receiver/tracking_channel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "signals/gps_constants.hpp"
#include "test_signal.hpp"

using namespace ultratrack;
using namespace ultratrack::receiver;

namespace {
constexpr double kFs = 4e6;

double code_rate(double doppler_hz) { return signals::kCaChipRate_hz * (1.0 + doppler_hz / signals::kL1Frequency_hz); }

ChannelStart start_at_truth(const test::TestSatellite& sat, std::int64_t sample) {
  ChannelStart s;
  s.sample_index = sample;
  const double t = sample / kFs;
  s.code_phase_chips = std::fmod(test::true_code_phase_chips(sat, t), 1023.0);
  s.carrier_frequency_hz = test::true_doppler_hz(sat, t);
  s.carrier_phase_cycles = test::true_carrier_phase_cycles(sat, t);
  return s;
}

std::vector<CorrelationEpoch> run(TrackingChannel& ch, const std::vector<std::complex<float>>& x, std::int64_t first,
                                  int block) {
  std::vector<CorrelationEpoch> out;
  for (std::size_t b = 0; b < x.size(); b += block) {
    SampleBlockView v;
    v.first_sample = first + static_cast<std::int64_t>(b);
    v.num_samples = static_cast<int>(std::min<std::size_t>(block, x.size() - b));
    v.antenna[0] = x.data() + b;
    for (int off = 0; off < v.num_samples;) {
      const auto r = ch.feed(v, off);
      off += r.consumed;
      if (r.epoch_ready) out.push_back(ch.epoch());
    }
  }
  return out;
}
}  // namespace

TEST(TrackingChannel, EpochsStartAtCodePeriodStartsAndMatchTruth) {
  test::TestSatellite sat;
  sat.prn = 12;
  sat.doppler_hz = 3000.0;
  sat.code_phase_chips = 700.4;
  sat.carrier_phase_cycles = 0.2;
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, 40000);
  TrackingChannel ch(ChannelConfig{12, kFs, 1, {}}, start_at_truth(sat, 0));
  const auto epochs = run(ch, x, 0, 1234);
  ASSERT_GE(epochs.size(), 8u);
  for (const auto& e : epochs) {
    // The epoch starts at the first sample at or after the true code-period start.
    const double chips_at_first = test::true_code_phase_chips(sat, e.first_sample / kFs);
    const double chips_before = test::true_code_phase_chips(sat, (e.first_sample - 1) / kFs);
    EXPECT_GE(chips_at_first, 1023.0 * (e.first_code_period) - 1e-6);
    EXPECT_LT(chips_before, 1023.0 * (e.first_code_period) + 1e-6);
    EXPECT_NEAR(e.code_phase_start_chips, chips_at_first - 1023.0 * e.first_code_period, 1e-6);
    EXPECT_NEAR(e.num_samples, 1023.0 / code_rate(sat.doppler_hz) * kFs, 1.0);
    // Replica on the truth: prompt = N (amplitude 1), phase 0; E and L on the triangle's shoulders.
    EXPECT_NEAR(std::abs(e.master().prompt), e.num_samples, 1e-3 * e.num_samples);
    EXPECT_NEAR(std::arg(e.master().prompt), 0.0, 1e-4);
    EXPECT_NEAR(std::abs(e.master().early), std::abs(e.master().late), 0.01 * e.num_samples);
    EXPECT_NEAR(std::abs(e.prompt_halves[0] + e.prompt_halves[1] - e.master().prompt), 0.0, 1e-2);
    EXPECT_NEAR(e.carrier_phase_start_cycles, test::true_carrier_phase_cycles(sat, e.first_sample / kFs), 1e-6);
  }
  EXPECT_EQ(epochs[1].first_sample, epochs[0].first_sample + epochs[0].num_samples);
}

TEST(TrackingChannel, BlockSizeDoesNotChangeEpochs) {
  test::TestSatellite sat;
  sat.prn = 3;
  sat.doppler_hz = -1500.0;
  sat.code_phase_chips = 10.0;
  const auto x = test::generate({sat}, {kFs, true, 7}, 0, 30000);
  TrackingChannel a(ChannelConfig{3, kFs, 1, {}}, start_at_truth(sat, 0));
  TrackingChannel b(ChannelConfig{3, kFs, 1, {}}, start_at_truth(sat, 0));
  const auto ea = run(a, x, 0, 30000);
  const auto eb = run(b, x, 0, 777);
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t k = 0; k < ea.size(); ++k) {
    EXPECT_EQ(ea[k].first_sample, eb[k].first_sample);
    EXPECT_EQ(ea[k].num_samples, eb[k].num_samples);
    EXPECT_LT(std::abs(ea[k].master().prompt - eb[k].master().prompt), 1e-5 * ea[k].num_samples);
    EXPECT_LT(std::abs(ea[k].master().noise - eb[k].master().noise), 1e-5 * ea[k].num_samples);
  }
}

TEST(TrackingChannel, CoherentEpochsAlignToTheGivenPeriod) {
  test::TestSatellite sat;
  sat.prn = 21;
  sat.doppler_hz = 100.0;  // off 0 Hz so that no sample falls exactly on a chip edge (a tie either side may take)
  sat.code_phase_chips = 100.0;
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, 4000 * 70);
  TrackingChannel ch(ChannelConfig{21, kFs, 1, {}}, start_at_truth(sat, 0));
  ch.set_coherent_periods(20, 7);
  const auto epochs = run(ch, x, 0, 5000);
  int long_epochs = 0;
  for (const auto& e : epochs) {
    if (e.num_code_periods == 20) {
      ++long_epochs;
      EXPECT_EQ((e.first_code_period - 7) % 20, 0);
      EXPECT_EQ(e.num_samples, 80000);
      EXPECT_NEAR(std::abs(e.master().prompt), 80000.0, 1.0);
      EXPECT_NEAR(e.code_phase_end_chips, 20 * 1023.0, code_rate(0) / kFs);
    } else {
      EXPECT_EQ(e.num_code_periods, 1);
      EXPECT_NE((e.first_code_period - 7) % 20, 0);
    }
  }
  EXPECT_GE(long_epochs, 2);
}

TEST(TrackingChannel, PhaseJumpsMoveTheReplica) {
  test::TestSatellite sat;
  sat.prn = 30;
  sat.code_phase_chips = 5.0;
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, 4000 * 4);
  TrackingChannel ch(ChannelConfig{30, kFs, 1, {}}, start_at_truth(sat, 0));
  NcoCommand cmd = ch.current_command();
  cmd.code_phase_jump_chips = 0.25;
  cmd.carrier_phase_jump_cycles = 0.25;
  ch.command(cmd);
  const auto epochs = run(ch, x, 0, 4000);
  ASSERT_GE(epochs.size(), 3u);
  // The command was given before the first epoch began, so the first epoch carries the jumps.
  const auto& e = epochs[0];
  const double step = code_rate(0.0) / kFs;
  EXPECT_GE(e.code_phase_start_chips, 0.25);
  EXPECT_LT(e.code_phase_start_chips, 0.25 + step);
  // The replica leads the signal by 0.25 chip: the late tap is now on the peak side.
  EXPECT_GT(std::abs(e.master().late), std::abs(e.master().early));
  EXPECT_NEAR(std::abs(e.master().prompt), 0.75 * e.num_samples, 0.02 * e.num_samples);
  EXPECT_NEAR(std::arg(e.master().prompt), -M_PI / 2, 1e-3);
  // Jumps are consumed once: the next epochs start on the period edge and keep the same carrier offset.
  for (std::size_t k = 1; k < epochs.size(); ++k) {
    EXPECT_GE(epochs[k].code_phase_start_chips, 0.0);
    EXPECT_LT(epochs[k].code_phase_start_chips, step);
    EXPECT_NEAR(std::arg(epochs[k].master().prompt), -M_PI / 2, 1e-3);
  }
  EXPECT_EQ(ch.current_command().code_phase_jump_chips, 0.0);
}

TEST(CarrierNco, PhaseAfter300SecondsMatchesClosedForm) {
  // 300 s at 4 MHz in 1 ms blocks with a Doppler that changes every block (a ramp), against the exact sum.
  CarrierPhase nco;
  const std::int64_t n = 4000;
  long double truth = 0.0L;
  for (int k = 0; k < 300000; ++k) {
    const double f = 4321.123456 + 0.37 * (k % 1000) - 0.001 * k;
    nco.set_step(f / kFs);
    nco.advance(n);
    truth += static_cast<long double>(f) * n / static_cast<long double>(kFs);
  }
  const long double whole = std::floor(truth);
  const double err = static_cast<double>(static_cast<long double>(nco.whole()) - whole) +
                     (nco.fraction() - static_cast<double>(truth - whole));
  EXPECT_LT(std::abs(err), 1e-3);
  EXPECT_LT(std::abs(err), 1e-6);  // what the 2^-62 fixed point actually gives
}

TEST(TrackingChannel, ReplicaPhaseAfter300SecondsMatchesClosedForm) {
  // The channel dead-reckons 300 s, then correlates against the closed-form signal: the prompt phase is the
  // accumulated replica phase error.
  test::TestSatellite sat;
  sat.prn = 8;
  sat.doppler_hz = 2345.678;
  sat.code_phase_chips = 0.5;
  TrackingChannel ch(ChannelConfig{8, kFs, 1, {}}, start_at_truth(sat, 0));
  const std::int64_t first = static_cast<std::int64_t>(300.0 * kFs);
  const auto x = test::generate({sat}, {kFs, false, 1}, first, 12000);
  const auto epochs = run(ch, x, first, 12000);
  ASSERT_GE(epochs.size(), 2u);
  for (const auto& e : epochs) {
    EXPECT_LT(std::abs(std::arg(e.master().prompt)) / (2 * M_PI), 1e-3);
    EXPECT_NEAR(std::abs(e.master().prompt), e.num_samples, 1e-3 * e.num_samples);
    EXPECT_NEAR(e.first_code_period, std::floor(test::true_code_phase_chips(sat, e.first_sample / kFs) / 1023.0), 0.0);
  }
}

TEST(TrackingChannel, AntennasShareTheReplica) {
  test::TestSatellite sat;
  sat.prn = 14;
  sat.doppler_hz = 500.0;
  sat.code_phase_chips = 300.0;
  auto offset = sat;
  offset.carrier_phase_cycles = -0.15;
  const auto x0 = test::generate({sat}, {kFs, true, 11}, 0, 12000);
  const auto x2 = test::generate({offset}, {kFs, false, 11}, 0, 12000);
  const auto clean = test::generate({sat}, {kFs, false, 11}, 0, 12000);
  // Default: the slaves get prompt and noise only (their own engine); false: every tap on every antenna. The
  // sums of a tap do not depend on which engine ran it: antenna 1 (the master's own samples) reads the same bits.
  for (const bool prompt_only : {true, false}) {
    ChannelConfig cfg{14, kFs, 4, {}};
    cfg.layout.slaves_prompt_and_noise_only = prompt_only;
    TrackingChannel ch(cfg, start_at_truth(sat, 0));
    SampleBlockView v;
    v.first_sample = 0;
    v.num_samples = 12000;
    v.num_antennas = 4;
    v.antenna = {x0.data(), x0.data(), clean.data(), x2.data()};
    int n = 0;
    for (int off = 0; off < v.num_samples;) {
      const auto r = ch.feed(v, off);
      off += r.consumed;
      if (!r.epoch_ready) continue;
      ++n;
      const auto& e = ch.epoch();
      EXPECT_EQ(e.antenna[0].prompt, e.antenna[1].prompt);
      EXPECT_EQ(e.antenna[0].noise, e.antenna[1].noise);
      EXPECT_NE(e.antenna[1].noise, std::complex<float>{});
      if (prompt_only) {
        EXPECT_EQ(e.antenna[1].early, std::complex<float>{});
        EXPECT_EQ(e.antenna[3].late, std::complex<float>{});
      } else {
        EXPECT_EQ(e.antenna[0].early, e.antenna[1].early);
      }
      EXPECT_NEAR(std::arg(e.antenna[3].prompt * std::conj(e.antenna[2].prompt)) / (2 * M_PI), -0.15, 1e-5);
    }
    EXPECT_GE(n, 2);
  }
}

TEST(TrackingChannel, StartsFromAnAcquisitionCodeStart) {
  test::TestSatellite sat;
  sat.prn = 4;
  sat.doppler_hz = -3210.0;
  sat.code_phase_chips = 123.456;
  // The true code start after sample 1000: where the code phase reaches the next multiple of 1023.
  const double rate = code_rate(sat.doppler_hz);
  const double chips_at_1000 = test::true_code_phase_chips(sat, 1000 / kFs);
  const double samples_to_start = (1023.0 * std::ceil(chips_at_1000 / 1023.0) - chips_at_1000) / rate * kFs;
  const auto start = start_from_code_start(1000, samples_to_start, sat.doppler_hz, kFs);
  EXPECT_NEAR(start.code_phase_chips, std::fmod(chips_at_1000, 1023.0), 1e-6);
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, 12000);
  TrackingChannel ch(ChannelConfig{4, kFs, 1, {}}, start);
  const auto epochs = run(ch, x, 0, 3000);
  ASSERT_GE(epochs.size(), 1u);
  EXPECT_NEAR(epochs[0].first_sample, 1000 + samples_to_start, 1.0);
  EXPECT_NEAR(std::abs(epochs[0].master().prompt), epochs[0].num_samples, 1e-3 * epochs[0].num_samples);
}

TEST(TrackingChannel, VeryEarlyLateAndNoiseTapsLandInTheirFields) {
  test::TestSatellite sat;
  sat.prn = 25;
  sat.doppler_hz = 700.0;
  sat.code_phase_chips = 50.0;
  const auto x = test::generate({sat}, {kFs, false, 1}, 0, 12000);
  ChannelConfig cfg{25, kFs, 1, {}};
  cfg.layout.early_late_offset_chips = 0.25;
  cfg.layout.very_early_late = true;
  cfg.layout.very_early_late_offset_chips = 0.75;
  TrackingChannel ch(cfg, start_at_truth(sat, 0));
  const auto epochs = run(ch, x, 0, 4000);
  ASSERT_GE(epochs.size(), 2u);
  const auto& t = epochs[1].master();
  const double n = epochs[1].num_samples;
  // On the triangle: |E| = |L| ~ 0.75 N, |VE| = |VL| ~ 0.25 N, noise tap ~ 0 (1 % sampling ripple).
  EXPECT_NEAR(std::abs(t.early), 0.75 * n, 0.015 * n);
  EXPECT_NEAR(std::abs(t.late), 0.75 * n, 0.015 * n);
  EXPECT_NEAR(std::abs(t.very_early), 0.25 * n, 0.015 * n);
  EXPECT_NEAR(std::abs(t.very_late), 0.25 * n, 0.015 * n);
  EXPECT_LT(std::abs(t.noise), 0.01 * n);
  // Without the noise tap the field reads zero.
  cfg.layout.noise = false;
  TrackingChannel quiet(cfg, start_at_truth(sat, 0));
  EXPECT_EQ(run(quiet, x, 0, 4000)[1].master().noise, std::complex<float>{});
}

TEST(TrackingChannel, RejectsBadConfiguration) {
  ChannelStart s;
  EXPECT_THROW(TrackingChannel(ChannelConfig{0, kFs, 1, {}}, s), std::invalid_argument);
  EXPECT_THROW(TrackingChannel(ChannelConfig{1, 1e5, 1, {}}, s), std::invalid_argument);
  EXPECT_THROW(TrackingChannel(ChannelConfig{1, kFs, 5, {}}, s), std::invalid_argument);
  ChannelConfig wide{1, kFs, 1, {}};
  wide.layout.early_late_offset_chips = 1.5;
  EXPECT_THROW(TrackingChannel(wide, s), std::invalid_argument);
  s.code_phase_chips = 1023.0;
  EXPECT_THROW(TrackingChannel(ChannelConfig{1, kFs, 1, {}}, s), std::invalid_argument);
}
