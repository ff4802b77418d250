// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's epochs: at each common receive epoch (every observation_interval_s, in samples) the channels'
// measurements become observables (pseudorange from the receiver clock, carrier phase, Doppler, C/N0; the
// clock itself started from the first measurements), carrier-smoothed pseudoranges go to PVT with the known
// ephemerides, a receiver clock off GPS time by more than clock_jump_threshold_s is jumped, and with several
// antennas every antenna's phase per satellite follows. Results go to the observer, counts to the stats.
// Units: samples, seconds, metres.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "receiver/antenna_phase.hpp"
#include "receiver/carrier_smoothing.hpp"
#include "receiver/navigation_store.hpp"
#include "receiver/observables.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_channel.hpp"
#include "receiver/receiver_clock.hpp"
#include "receiver/receiver_options.hpp"
#include "receiver/receiver_results.hpp"

namespace ultratrack::receiver {

class EpochSolver final {
 public:
  explicit EpochSolver(const ReceiverOptions& options);

  // The observation epoch at sample over the channels in slot order (nullptr: free).
  void observation_epoch(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                         const NavigationStore& navigation, ReceiverStats& stats, ReceiverObserver& observer);

  // The receiver clock (none before the first measurement) and the latest valid fix.
  const std::optional<ReceiverClock>& clock() const { return clock_; }
  const std::optional<PvtSolution>& last_fix() const { return last_fix_; }
  // The sum of the clock jumps so far (s), and that sum when last_fix was solved (before its own jump).
  double clock_corrections_s() const { return clock_corrections_s_; }
  double fix_clock_corrections_s() const { return fix_clock_corrections_s_; }

 private:
  void solve(const ObservationEpoch& epoch, const NavigationStore& navigation, ReceiverStats& stats,
             ReceiverObserver& observer);
  void antenna_phases(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                      const NavigationStore& navigation, ReceiverObserver& observer);

  ReceiverOptions options_;
  std::optional<ReceiverClock> clock_;
  std::optional<PvtSolution> last_fix_;
  CarrierSmoothing smoothing_;
  std::array<double, 33> smoothed_m_{};       // this epoch's smoothed pseudorange per PRN
  std::int64_t epoch_index_ = 0;              // observation epochs since the start (for the smoothing's gap test)
  ObservationEpoch epoch_;                    // reused every epoch
  std::vector<ChannelMeasurement> measured_;  // reused
  std::vector<SatelliteMeasurement> pvt_input_;
  AntennaPhaseEpoch antenna_epoch_;
  double clock_corrections_s_ = 0.0;
  double fix_clock_corrections_s_ = 0.0;  // clock_corrections_s_ when last_fix_ was solved
};

}  // namespace ultratrack::receiver
