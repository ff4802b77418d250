// SPDX-License-Identifier: GPL-3.0-or-later
// Test support: a TrackingChannel fed with the independent test signal (test_signal.hpp) block by block, and the
// replica's carrier phase error against that signal's truth. Samples, seconds, cycles.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "receiver/tracking_channel.hpp"
#include "test_signal.hpp"

namespace ultratrack::test {

// Generates `sats` over [0, total_samples) in blocks of `block` samples, feeds them to `channel` and calls
// on_epoch(epoch) for every completed correlation epoch; stops when on_epoch returns false.
template <class OnEpoch>
void feed_generated(receiver::TrackingChannel& channel, const std::vector<TestSatellite>& sats, const TestSignal& sig,
                    std::int64_t total_samples, std::int64_t block, OnEpoch&& on_epoch) {
  for (std::int64_t first = 0; first < total_samples; first += block) {
    const auto x = generate(sats, sig, first, block);
    receiver::SampleBlockView v;
    v.first_sample = first;
    v.num_samples = static_cast<int>(block);
    v.antenna[0] = x.data();
    int offset = 0;
    while (offset < v.num_samples) {
      const auto fed = channel.feed(v, offset);
      offset += fed.consumed;
      if (fed.epoch_ready && !on_epoch(channel.epoch())) return;
    }
  }
}

// Truth minus the replica's mean carrier phase over the epoch (at its middle), folded into [-1/4, 1/4] cycles:
// the Costas loop's phase error, blind to the half-cycle data ambiguity.
inline double costas_phase_error_cycles(const TestSatellite& sat, const receiver::CorrelationEpoch& e, double fs_hz) {
  const double mid_s = (static_cast<double>(e.first_sample) + 0.5 * e.num_samples) / fs_hz;
  double d = true_carrier_phase_cycles(sat, mid_s) - 0.5 * (e.carrier_phase_start_cycles + e.carrier_phase_end_cycles);
  return d - 0.5 * std::round(d / 0.5);
}

}  // namespace ultratrack::test
