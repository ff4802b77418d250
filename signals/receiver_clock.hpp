// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's oscillator as the synthesiser models it: clock error b (receiver clock minus GPS time,
// seconds) as a function of receiver time tau (seconds since the first sample = sample index / fs):
// b(tau) = bias + drift * tau + random walks (white frequency noise on b, random-walk frequency on the
// drift), evolved on a 1 ms grid from a seeded generator and linear between grid nodes.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

namespace ultratrack::signals {

struct ReceiverClockModel {
  double bias_s = 0.0;                      // b at tau = 0
  double drift_sps = 0.0;                   // db/dtau at tau = 0 (s/s); +1e-6 = 1 ppm fast
  double bias_noise_s_per_sqrt_s = 0.0;     // white frequency noise: b random walk, s/sqrt(s)
  double drift_noise_sps_per_sqrt_s = 0.0;  // random-walk frequency: drift random walk, (s/s)/sqrt(s)
};

struct ReceiverClockState {
  double bias_s = 0.0;
  double drift_sps = 0.0;
};

// State is the lazily grown grid of the random walk; queries may come in any order (the grid is grown
// up to the latest time asked for, with amortised allocation: once per 64k nodes).
class ReceiverClock {
 public:
  ReceiverClock(ReceiverClockModel model, std::uint64_t seed);
  // Clock error and drift at receiver time tau_s >= 0.
  ReceiverClockState at(double tau_s);
  const ReceiverClockModel& model() const { return model_; }

  static constexpr double kGridStep_s = 1e-3;

 private:
  void grow_to(std::size_t node);
  ReceiverClockModel model_;
  bool noisy_;
  std::mt19937_64 rng_;
  std::vector<ReceiverClockState> grid_;
};

}  // namespace ultratrack::signals
