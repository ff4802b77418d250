// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/standstill_gyro_bias.hpp"

#include <algorithm>
#include <cmath>

#include "ins/earth_model.hpp"

namespace ultratrack::ins {
namespace {

// Floors for units whose datasheet has no noise (the `ideal` preset) or data rounded to a few digits.
constexpr double kRateFloor_rps = 1e-6, kForceFloor_mps2 = 1e-5;

// One sample's white noise, rate [rad/s] or specific force [m/s^2], over an interval dt: the random walk, the
// output's white noise and its quantisation (both differenced by the increments).
double sample_sigma(const SensorErrorSpec& s, double dt, double floor) {
  const double v = s.random_walk * s.random_walk / dt + 2.0 * s.output_white_noise * s.output_white_noise / (dt * dt) +
                   s.quantum * s.quantum / (6.0 * dt * dt);
  return std::max(std::sqrt(v), floor);
}

// Sums over a run of samples: means and per-axis variances.
struct Moments {
  Eigen::Vector3d sum_w = Eigen::Vector3d::Zero(), sum_f = Eigen::Vector3d::Zero();
  Eigen::Vector3d sq_w = Eigen::Vector3d::Zero(), sq_f = Eigen::Vector3d::Zero();
  long n = 0;

  void add(const Eigen::Vector3d& w, const Eigen::Vector3d& f) {
    sum_w += w;
    sum_f += f;
    sq_w += w.cwiseAbs2();
    sq_f += f.cwiseAbs2();
    ++n;
  }
  void add(const Moments& o) {
    sum_w += o.sum_w;
    sum_f += o.sum_f;
    sq_w += o.sq_w;
    sq_f += o.sq_f;
    n += o.n;
  }
  Eigen::Vector3d mean_w() const { return sum_w / double(n); }
  Eigen::Vector3d mean_f() const { return sum_f / double(n); }
  Eigen::Vector3d var_w() const { return (sq_w / double(n) - mean_w().cwiseAbs2()) * double(n) / double(n - 1); }
  Eigen::Vector3d var_f() const { return (sq_f / double(n) - mean_f().cwiseAbs2()) * double(n) / double(n - 1); }
};

}  // namespace

std::optional<StandstillGyroBias> initial_standstill_gyro_bias(std::span<const ImuIncrement> imu, double lat_rad,
                                                               const ImuErrorSpec& spec, double end_by_s,
                                                               const StandstillOptions& o) {
  if (imu.size() < 2 || !(o.window_s > 0.0)) return std::nullopt;
  const double dt = imu[1].t_s - imu[0].t_s;
  if (!(dt > 0.0)) return std::nullopt;
  const double t0 = imu[0].t_s - dt;  // the first interval's start
  const double sigma_w = sample_sigma(spec.gyro, dt, kRateFloor_rps);
  const double sigma_f = sample_sigma(spec.accel, dt, kForceFloor_mps2);

  Moments accepted, previous;  // previous: the last window that passed (dropped as the margin)
  double accepted_end = t0, previous_end = t0;
  std::size_t k = 0;
  for (int w = 0;; ++w) {
    const double window_end = t0 + (w + 1) * o.window_s;
    if (window_end > end_by_s + 1e-9) break;
    Moments m;
    double t_prev = k > 0 ? imu[k - 1].t_s : t0;
    for (; k < imu.size() && imu[k].t_s <= window_end + 1e-9; ++k) {
      const double h = imu[k].t_s - t_prev;
      t_prev = imu[k].t_s;
      if (!(h > 0.0)) return std::nullopt;  // unsorted: the caller's input check says so
      m.add(imu[k].dtheta_b / h, imu[k].dv_b / h);
    }
    if (k == imu.size() || m.n < 3) break;  // the record ends inside the standstill window: keep what passed
    const bool quiet = (m.var_w().array() <= o.variance_factor * sigma_w * sigma_w).all() &&
                       (m.var_f().array() <= o.variance_factor * sigma_f * sigma_f).all();
    bool steady = true;
    Moments so_far = accepted;
    so_far.add(previous);
    if (so_far.n > 0) {
      // The noise measured (an idling engine's vibration), never below the datasheet's.
      const double spread = std::sqrt(1.0 / double(m.n) + 1.0 / double(so_far.n));
      const Eigen::ArrayXd noise_w = m.var_w().cwiseMax(sigma_w * sigma_w).array().sqrt();
      const Eigen::ArrayXd noise_f = m.var_f().cwiseMax(sigma_f * sigma_f).array().sqrt();
      steady = ((m.mean_w() - so_far.mean_w()).array().abs() <=
                o.mean_sigmas * spread * noise_w + 2.0 * spec.gyro.bias_instability_sigma)
                   .all() &&
               ((m.mean_f() - so_far.mean_f()).array().abs() <=
                o.mean_sigmas * spread * noise_f + 2.0 * spec.accel.bias_instability_sigma)
                   .all();
    }
    if (!quiet || !steady) break;
    if (previous.n > 0) {
      accepted.add(previous);
      accepted_end = previous_end;
    }
    previous = m;
    previous_end = window_end;
  }
  if (accepted.n < 3 || accepted_end - t0 < o.min_duration_s - 1e-9) return std::nullopt;

  StandstillGyroBias r;
  r.t_start_s = t0;
  r.t_end_s = accepted_end;
  r.mean_f_b = accepted.mean_f();
  if (!(r.mean_f_b.norm() > 0.0)) return std::nullopt;
  // At rest the specific force points up: the body's down axis is -f / |f|; the earth rate's down component is
  // -W sin L (NED: [W cos L, 0, -W sin L]).
  const Eigen::Vector3d down_b = -r.mean_f_b.normalized();
  r.gyro_bias_rps = accepted.mean_w() + kEarthRate_rps * std::sin(lat_rad) * down_b;
  const double horizontal_earth = kEarthRate_rps * std::cos(lat_rad);
  const Eigen::Vector3d noise_var = accepted.var_w().cwiseMax(sigma_w * sigma_w);  // measured, at least the datasheet's
  r.sigma_rps = (noise_var / double(accepted.n)).array() + horizontal_earth * horizontal_earth +
                spec.gyro.bias_instability_sigma * spec.gyro.bias_instability_sigma;
  r.sigma_rps = r.sigma_rps.cwiseSqrt();
  return r;
}

}  // namespace ultratrack::ins
