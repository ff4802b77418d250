// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/truth_interpolator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ins/earth_model.hpp"

namespace ultratrack::ins {

EcefMotion antenna_motion_at_sample(const TruthSample& s, const Eigen::Vector3d& l_b) {
  const Eigen::Matrix3d Cen = C_en(s.lat_rad, s.lon_rad);
  const Eigen::Matrix3d Cnb = s.q_nb.toRotationMatrix();
  const Eigen::Vector3d w_eb_b = s.w_ib_b - Cnb.transpose() * earth_rate_n(s.lat_rad);
  EcefMotion m;
  m.r_e = ecef_from_geodetic(s.lat_rad, s.lon_rad, s.height_m) + Cen * (Cnb * l_b);
  m.v_e = Cen * (s.v_n + Cnb * w_eb_b.cross(l_b));
  return m;
}

TruthInterpolator::TruthInterpolator(std::vector<TruthSample> samples) : samples_(std::move(samples)) {
  if (samples_.size() < 2) throw std::invalid_argument("TruthInterpolator needs at least two samples");
  for (std::size_t i = 1; i < samples_.size(); ++i)
    if (!(samples_[i].t_s > samples_[i - 1].t_s)) throw std::invalid_argument("truth times must increase");
  const double dt = (samples_.back().t_s - samples_.front().t_s) / static_cast<double>(samples_.size() - 1);
  bool uniform = true;
  for (std::size_t i = 0; i < samples_.size() && uniform; ++i)
    uniform = std::fabs(samples_[i].t_s - (samples_.front().t_s + static_cast<double>(i) * dt)) < 1e-6 * dt;
  if (uniform) uniform_dt_ = dt;
}

std::size_t TruthInterpolator::index(double t) const {
  if (uniform_dt_ > 0.0) {
    const double x = std::floor((t - samples_.front().t_s) / uniform_dt_);
    auto i = static_cast<std::size_t>(std::clamp(x, 0.0, static_cast<double>(samples_.size() - 2)));
    // rounding at a sample time: step to the interval that really holds t
    if (i > 0 && t < samples_[i].t_s) --i;
    if (i + 2 < samples_.size() && t >= samples_[i + 1].t_s) ++i;
    return i;
  }
  const auto it =
      std::upper_bound(samples_.begin(), samples_.end(), t, [](double v, const TruthSample& s) { return v < s.t_s; });
  const std::size_t i = it == samples_.begin() ? 0 : static_cast<std::size_t>(it - samples_.begin()) - 1;
  return std::min(i, samples_.size() - 2);
}

EcefMotion TruthInterpolator::antenna(double t, const Eigen::Vector3d& l_b) const {
  t = std::clamp(t, start_s(), end_s());
  const std::size_t i = index(t);
  const TruthSample& a = samples_[i];
  const TruthSample& b = samples_[i + 1];
  const EcefMotion ma = antenna_motion_at_sample(a, l_b);
  const EcefMotion mb = antenna_motion_at_sample(b, l_b);
  const double h = b.t_s - a.t_s;
  const double x = (t - a.t_s) / h;
  const double x2 = x * x, x3 = x2 * x;
  // Cubic Hermite basis and its derivative.
  const double h00 = 2 * x3 - 3 * x2 + 1, h10 = x3 - 2 * x2 + x, h01 = -2 * x3 + 3 * x2, h11 = x3 - x2;
  const double d00 = 6 * x2 - 6 * x, d10 = 3 * x2 - 4 * x + 1, d01 = -6 * x2 + 6 * x, d11 = 3 * x2 - 2 * x;
  EcefMotion m;
  m.r_e = h00 * ma.r_e + h10 * h * ma.v_e + h01 * mb.r_e + h11 * h * mb.v_e;
  m.v_e = (d00 * ma.r_e + d01 * mb.r_e) / h + d10 * ma.v_e + d11 * mb.v_e;
  return m;
}

Eigen::Quaterniond TruthInterpolator::attitude(double t) const {
  t = std::clamp(t, start_s(), end_s());
  const std::size_t i = index(t);
  const double x = (t - samples_[i].t_s) / (samples_[i + 1].t_s - samples_[i].t_s);
  return samples_[i].q_nb.slerp(x, samples_[i + 1].q_nb);
}

}  // namespace ultratrack::ins
