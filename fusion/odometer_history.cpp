// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/odometer_history.hpp"

#include <iterator>

#include "ins/attitude.hpp"

namespace ultratrack::fusion {

void OdometerHistory::record(const ins::NavState& nav, double keep_s) {
  points_.push_back({nav.t_s, ins::euler_from_quaternion(nav.q_nb).yaw_rad, nav.v_n});
  while (points_.size() > 2 && points_[1].t_s < nav.t_s - keep_s) points_.pop_front();
}

std::optional<OdometerHistory::Window> OdometerHistory::window(const ins::NavState& now, const OdometerSpeed& speed,
                                                               const OdometerAidingOptions& options) const {
  const double t0 = now.t_s - speed.window_s;
  if (points_.empty() || points_.front().t_s > t0 + 1e-6) return std::nullopt;
  auto it = points_.begin();  // the last point at or before the window's start
  while (std::next(it) != points_.end() && std::next(it)->t_s <= t0 + 1e-9) ++it;
  Window w;
  const double yaw_now = ins::euler_from_quaternion(now.q_nb).yaw_rad;
  w.gate = odometer_gate(options, yaw_now - it->yaw_rad, speed.window_s, speed.speed_mps);
  const double span = now.t_s - it->t_s;
  const Eigen::Vector3d a_n = span > 0.0 ? Eigen::Vector3d((now.v_n - it->v_n) / span) : Eigen::Vector3d::Zero();
  w.a_b = now.q_nb.conjugate() * a_n;
  return w;
}

}  // namespace ultratrack::fusion
