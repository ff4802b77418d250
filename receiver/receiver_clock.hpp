// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's clock: a GPS time attached to one sample index, advanced by the sample counter (never a float
// absolute time). Set once from the first transmit times (latest transmit time + a nominal travel time), then
// corrected by jumps when a fix shows it off by more than a threshold. Units: seconds, samples.
#pragma once

#include <cstdint>

#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

class ReceiverClock {
 public:
  ReceiverClock(signals::GpsTime time_at_sample, std::int64_t sample, double fs_hz)
      : base_(time_at_sample), base_sample_(sample), fs_hz_(fs_hz) {}
  // Seconds from the base time to a sample (exact to double precision of the difference).
  double seconds_since_base(std::int64_t sample) const { return static_cast<double>(sample - base_sample_) / fs_hz_; }
  signals::GpsTime time_at(std::int64_t sample) const {
    return signals::add_seconds(base_, seconds_since_base(sample));
  }
  const signals::GpsTime& base() const { return base_; }
  // The clock reads dt_s too much: remove it (a clock jump of -dt_s).
  void correct(double dt_s) { base_ = signals::add_seconds(base_, -dt_s); }

 private:
  signals::GpsTime base_;
  std::int64_t base_sample_;
  double fs_hz_;
};

}  // namespace ultratrack::receiver
