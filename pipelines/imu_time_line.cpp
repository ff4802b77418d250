// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/imu_time_line.hpp"

#include <fmt/core.h>

#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kWeek_s = 604800.0;
constexpr double kClockJumpDetect_s = 1e-7;  // receiver clock offsets change only by jumps (>= 1 ms in practice)

}  // namespace

std::string to_string(const ImuTimeOrigin& origin) {
  switch (origin.kind) {
    case ImuTimeOrigin::Kind::Sample0:
      return "sample0";
    case ImuTimeOrigin::Kind::WeekStart:
      return "tow";
    case ImuTimeOrigin::Kind::Tow:
      return fmt::format("{}", origin.tow_s);
  }
  return "?";
}

signals::GpsTime imu_time_origin_gps(const ImuTimeOrigin& origin, const signals::GpsTime& g, std::int64_t sample,
                                     double fs_hz) {
  switch (origin.kind) {
    case ImuTimeOrigin::Kind::Sample0:
      return signals::add_seconds(g, -static_cast<double>(sample) / fs_hz);
    case ImuTimeOrigin::Kind::WeekStart:
      return signals::GpsTime{g.week, 0.0};
    case ImuTimeOrigin::Kind::Tow:
      break;
  }
  signals::GpsTime o{g.week, origin.tow_s};
  const double d = signals::seconds_between(g, o);
  if (d < -0.5 * kWeek_s) o.week -= 1;
  if (d > 0.5 * kWeek_s) o.week += 1;
  return o;
}

receiver::ObservationEpoch ReceiverClockJumps::continuous(const receiver::ObservationEpoch& e) {
  if (!have_reference_) {
    have_reference_ = true;
    reference_ = e.receive_time;
    base_offset_s_ = -static_cast<double>(e.sample_index) / fs_hz_;
  }
  const double offset =
      signals::seconds_between(e.receive_time, reference_) - static_cast<double>(e.sample_index) / fs_hz_;
  const double jump = offset - base_offset_s_;  // -(sum of the corrections applied so far)
  if (std::abs(jump - jump_s_) > kClockJumpDetect_s) ++jumps_;
  jump_s_ = jump;
  receiver::ObservationEpoch out = e;
  out.receive_time = signals::add_seconds(e.receive_time, -jump);
  for (auto& o : out.observations) o.pseudorange_m -= signals::kSpeedOfLight_mps * jump;
  return out;
}

}  // namespace ultratrack::pipelines
