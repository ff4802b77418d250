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

// Sums over a run of one triad's samples: mean and per-axis variance.
struct Moments {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sq = Eigen::Vector3d::Zero();
  long n = 0;

  void add(const Eigen::Vector3d& x) {
    sum += x;
    sq += x.cwiseAbs2();
    ++n;
  }
  void add(const Moments& o) {
    sum += o.sum;
    sq += o.sq;
    n += o.n;
  }
  Eigen::Vector3d mean() const { return sum / double(n); }
  Eigen::Vector3d var() const { return (sq / double(n) - mean().cwiseAbs2()) * double(n) / double(n - 1); }
};

// The gyros' (rate) and the accelerometers' (specific force) moments over the same samples.
struct ImuMoments {
  Moments w, f;
  long n() const { return w.n; }
  void add(const ImuMoments& o) {
    w.add(o.w);
    f.add(o.f);
  }
};

// A triad quiet in a window (variance within factor times the datasheet's white noise, sigma) and steady against the
// standstill so far (mean within mean_sigmas of the noise measured, at least the datasheet's, plus twice the in-run
// instability).
bool quiet(const Moments& m, double sigma, double factor) { return (m.var().array() <= factor * sigma * sigma).all(); }
bool steady(const Moments& m, const Moments& so_far, double sigma, double instability, double mean_sigmas) {
  const double spread = std::sqrt(1.0 / double(m.n) + 1.0 / double(so_far.n));
  const Eigen::Array3d noise = m.var().cwiseMax(sigma * sigma).array().sqrt();  // an idling engine's vibration
  return ((m.mean() - so_far.mean()).array().abs() <= mean_sigmas * spread * noise + 2.0 * instability).all();
}

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

  ImuMoments accepted, previous;  // previous: the last window that passed (dropped as the margin)
  double accepted_end = t0, previous_end = t0;
  std::size_t k = 0;
  for (int w = 0;; ++w) {
    const double window_end = t0 + (w + 1) * o.window_s;
    if (window_end > end_by_s + 1e-9) break;
    ImuMoments m;
    double t_prev = k > 0 ? imu[k - 1].t_s : t0;
    for (; k < imu.size() && imu[k].t_s <= window_end + 1e-9; ++k) {
      const double h = imu[k].t_s - t_prev;
      t_prev = imu[k].t_s;
      if (!(h > 0.0)) return std::nullopt;  // unsorted: the caller's input check says so
      m.w.add(imu[k].dtheta_b / h);
      m.f.add(imu[k].dv_b / h);
    }
    if (k == imu.size() || m.n() < 3) break;  // the record ends inside the standstill window: keep what passed
    bool ok = quiet(m.w, sigma_w, o.variance_factor) && quiet(m.f, sigma_f, o.variance_factor);
    ImuMoments so_far = accepted;
    so_far.add(previous);
    if (ok && so_far.n() > 0)
      ok = steady(m.w, so_far.w, sigma_w, spec.gyro.bias_instability_sigma, o.mean_sigmas) &&
           steady(m.f, so_far.f, sigma_f, spec.accel.bias_instability_sigma, o.mean_sigmas);
    if (!ok) break;
    if (previous.n() > 0) {
      accepted.add(previous);
      accepted_end = previous_end;
    }
    previous = m;
    previous_end = window_end;
  }
  if (accepted.n() < 3 || accepted_end - t0 < o.min_duration_s - 1e-9) return std::nullopt;

  StandstillGyroBias r;
  r.t_start_s = t0;
  r.t_end_s = accepted_end;
  r.mean_f_b = accepted.f.mean();
  if (!(r.mean_f_b.norm() > 0.0)) return std::nullopt;
  // At rest the specific force points up: the body's down axis is -f / |f|; the earth rate's down component is
  // -W sin L (NED: [W cos L, 0, -W sin L]).
  const Eigen::Vector3d down_b = -r.mean_f_b.normalized();
  r.gyro_bias_rps = accepted.w.mean() + kEarthRate_rps * std::sin(lat_rad) * down_b;
  const double horizontal_earth = kEarthRate_rps * std::cos(lat_rad);
  const Eigen::Vector3d noise_var = accepted.w.var().cwiseMax(sigma_w * sigma_w);  // measured, at least the datasheet's
  r.sigma_rps = (noise_var / double(accepted.n())).array() + horizontal_earth * horizontal_earth +
                spec.gyro.bias_instability_sigma * spec.gyro.bias_instability_sigma;
  r.sigma_rps = r.sigma_rps.cwiseSqrt();
  return r;
}

}  // namespace ultratrack::ins
