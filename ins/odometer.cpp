// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/odometer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ultratrack::ins {

Eigen::Matrix3d C_bv_from_misalignment(double pitch_rad, double yaw_rad) {
  const double cp = std::cos(pitch_rad), sp = std::sin(pitch_rad), cy = std::cos(yaw_rad), sy = std::sin(yaw_rad);
  Eigen::Matrix3d Rz, Ry;
  Rz << cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0;
  Ry << cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp;
  return Rz * Ry;
}

namespace {

// Odometer distance (before quantisation) at time t: truth distance at t - delay, linearly interpolated, with
// the slip events' extra or missing distance accumulated.
class WheelDistance {
 public:
  WheelDistance(std::span<const TruthSample> truth, const OdometerOptions& o) : truth_(truth), o_(o) {
    dt_ = truth[1].t_s - truth[0].t_s;
  }
  double at(double t) const {
    const double tt = t - o_.delay_s;
    double d = truth_distance(tt);
    for (const auto& s : o_.slips) {
      const double a = std::clamp(tt, s.start_s, s.start_s + s.duration_s);
      d += s.ratio * (truth_distance(a) - truth_distance(s.start_s));
    }
    return d;
  }

 private:
  double truth_distance(double t) const {
    const double x = (t - truth_.front().t_s) / dt_;
    if (x <= 0.0) return truth_.front().distance_m;
    const auto i = static_cast<std::size_t>(std::floor(x));
    if (i + 1 >= truth_.size()) return truth_.back().distance_m;
    const double w = x - static_cast<double>(i);
    return truth_[i].distance_m + w * (truth_[i + 1].distance_m - truth_[i].distance_m);
  }
  std::span<const TruthSample> truth_;
  const OdometerOptions& o_;
  double dt_ = 0.0;
};

}  // namespace

std::vector<OdometerSample> simulate_odometer(std::span<const TruthSample> truth, const OdometerOptions& o) {
  if (truth.size() < 2) throw std::invalid_argument("simulate_odometer: need at least two truth samples");
  if (!(o.rate_hz > 0.0) || !(o.meters_per_pulse > 0.0) || !(o.delay_s >= 0.0))
    throw std::invalid_argument("simulate_odometer: bad options");
  for (const auto& s : o.slips)
    if (!(s.duration_s > 0.0) || !(s.ratio >= -1.0)) throw std::invalid_argument("simulate_odometer: bad slip event");
  const double truth_dt = truth[1].t_s - truth[0].t_s;
  const long long stride = std::llround(1.0 / (o.rate_hz * truth_dt));
  if (stride < 1 || std::fabs(stride * truth_dt * o.rate_hz - 1.0) > 1e-6)
    throw std::invalid_argument("simulate_odometer: odometer rate must divide the truth rate");
  const bool exact_truth = o.delay_s == 0.0 && o.slips.empty();  // the original counting, bit for bit
  const WheelDistance wheel(truth, o);
  auto count = [&](std::size_t i) {
    const double d = exact_truth ? truth[i].distance_m : wheel.at(truth[i].t_s);
    return static_cast<std::int64_t>(std::floor(d * (1.0 + o.scale_factor_error) / o.meters_per_pulse));
  };
  std::vector<OdometerSample> out;
  std::int64_t prev = count(0);
  for (std::size_t i = static_cast<std::size_t>(stride); i < truth.size(); i += static_cast<std::size_t>(stride)) {
    const std::int64_t c = std::max(count(i), prev);  // a wheel count never runs backwards
    out.push_back({truth[i].t_s, c - prev, static_cast<double>(c - prev) * o.meters_per_pulse});
    prev = c;
  }
  return out;
}

}  // namespace ultratrack::ins
