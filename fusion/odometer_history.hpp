// SPDX-License-Identifier: GPL-3.0-or-later
// The INS heading and velocity over the last odometer windows: what the gate of [KimVMS] eqs. 16-17 (the heading
// change over the window) and the VMS measurement (the vehicle's mean acceleration over it, fusion/vms_measurement.hpp)
// need at a window's start. Recorded after every INS step by the filters that take odometer speeds (the loose and
// tight cores of fusion/gnss_ins_core_impl.hpp, the ultra-tight driver). Units: s, rad, m/s, m/s^2.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <optional>

#include "fusion/vms_measurement.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::fusion {

class OdometerHistory {
 public:
  // After an INS step: its state; points older than keep_s before it are dropped (one kept before that span).
  void record(const ins::NavState& nav, double keep_s);

  struct Window {
    OdometerGate gate;    // the rules of eqs. 16-17 for this window
    Eigen::Vector3d a_b;  // the vehicle's mean acceleration over the window, body axes at `now`
  };
  // The window (now.t_s - speed.window_s, now.t_s]: nothing when the history does not reach back to its start.
  std::optional<Window> window(const ins::NavState& now, const OdometerSpeed& speed,
                               const OdometerAidingOptions& options) const;
  // The window if it passes the gate, else nothing; counted (unusable, gated_yaw_rate, gated_speed).
  std::optional<Window> gated_window(const ins::NavState& now, const OdometerSpeed& speed,
                                     const OdometerAidingOptions& options, OdometerCounters& counters) const {
    const auto w = window(now, speed, options);
    if (!w) {
      ++counters.unusable;
      return std::nullopt;
    }
    if (!w->gate.yaw_rate_ok) ++counters.gated_yaw_rate;
    if (!w->gate.speed_ok) ++counters.gated_speed;
    if (!w->gate.update()) return std::nullopt;
    return w;
  }

 private:
  struct Point {
    double t_s, yaw_rad;
    Eigen::Vector3d v_n;
  };
  std::deque<Point> points_;
};

}  // namespace ultratrack::fusion
