// SPDX-License-Identifier: GPL-3.0-or-later
// The IMU's time line against the receiver's. An IMU file's t_s is seconds of GPS time since an origin
// (ImuTimeOrigin): the GPS time of the input's first sample (what `simulate` writes), the start of the GPS week
// (t_s is the time of week), or a given time of week. ReceiverClockJumps takes the receiver's clock jumps (whole
// milliseconds the engine steps its clock by) out of observation epochs, so that receive times and pseudoranges
// stay continuous and a filter's clock states need not jump. Units: s, m.
#pragma once

#include <cstdint>
#include <string>

#include "receiver/observables.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::pipelines {

struct ImuTimeOrigin {
  enum class Kind { Sample0, WeekStart, Tow } kind = Kind::Sample0;
  double tow_s = 0.0;  // Kind::Tow, in [0, 604800)
};
// "sample0", "tow" or the time of week (summary.json, messages).
std::string to_string(const ImuTimeOrigin& origin);

// The GPS time of IMU t_s = 0, from the first epoch's GPS time g at receiver sample `sample` (fs_hz: sample rate).
// Kind::Tow picks the week that puts the origin within half a week of g.
signals::GpsTime imu_time_origin_gps(const ImuTimeOrigin& origin, const signals::GpsTime& g, std::int64_t sample,
                                     double fs_hz);

class ReceiverClockJumps {
 public:
  explicit ReceiverClockJumps(double fs_hz) : fs_hz_(fs_hz) {}
  // The epoch with the clock jumps since the first epoch undone (receive time and pseudoranges continuous).
  receiver::ObservationEpoch continuous(const receiver::ObservationEpoch& e);
  // The receive-time offset taken out of the latest epoch (s): minus the sum of the engine's corrections so far.
  double jump_s() const { return jump_s_; }
  int jumps() const { return jumps_; }  // changes seen (each >= 0.1 us; the engine's are >= 1 ms)

 private:
  double fs_hz_;
  bool have_reference_ = false;
  signals::GpsTime reference_;
  double base_offset_s_ = 0.0, jump_s_ = 0.0;
  int jumps_ = 0;
};

}  // namespace ultratrack::pipelines
