// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/trajectory_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::ins {
namespace {

constexpr double kG0 = 9.80665;  // only sets the bank angle of coordinated turns

// Quintic blend 0 -> 1 on x in [0, 1] with zero first and second derivative at both ends.
inline double blend(double x) { return x * x * x * (10.0 + x * (-15.0 + 6.0 * x)); }
inline double blend_rate(double x) { return 30.0 * x * x * (1.0 - x) * (1.0 - x); }

}  // namespace

TrajectoryGenerator::TrajectoryGenerator(TrajectorySpec spec, double imu_rate_hz) : spec_(std::move(spec)) {
  if (!(imu_rate_hz > 0.0) || !std::isfinite(imu_rate_hz)) throw std::invalid_argument("IMU rate must be positive");
  if (spec_.segments.empty()) throw std::invalid_argument("trajectory has no segments");
  dt_ = 1.0 / imu_rate_hz;
  // Sub-steps of at most 2.5 ms, and 40 per period of the fastest vibration (RK4 and the increments' quadrature
  // then resolve it to ~1e-6 of its amplitude).
  double h_max = 0.0025;
  for (const auto& v : spec_.vibrations) {
    if (!(v.frequency_hz > 0.0) || !std::isfinite(v.frequency_hz))
      throw std::invalid_argument("vibration frequency must be positive");
    h_max = std::min(h_max, 1.0 / (40.0 * v.frequency_hz));
  }
  substeps_ = std::max(1, static_cast<int>(std::ceil(dt_ / h_max - 1e-9)));
  n_steps_ = static_cast<long long>(std::llround(spec_.duration_s() * imu_rate_hz));
  double t = 0.0;
  for (const auto& s : spec_.segments) {
    seg_start_.push_back(t);
    t += s.duration_s;
  }
  y_.fill(0.0);
  y_[0] = spec_.speed0_mps;
  y_[1] = spec_.heading0_rad;
  y_[2] = spec_.lat0_rad;
  y_[3] = spec_.lon0_rad;
  y_[4] = spec_.height0_m;
  fill_truth(0.0, y_, truth_);
}

bool TrajectoryGenerator::done() const { return k_ >= n_steps_; }

TrajectoryGenerator::Commands TrajectoryGenerator::commands(double t) const {
  // Segment i holds its commands; during its first `ramp` seconds they blend from segment i-1's.
  const auto it = std::upper_bound(seg_start_.begin(), seg_start_.end(), t);
  const std::size_t i = it == seg_start_.begin() ? 0 : static_cast<std::size_t>(it - seg_start_.begin()) - 1;
  const Segment& cur = spec_.segments[i];
  const Segment prev = i == 0 ? Segment{} : spec_.segments[i - 1];
  const double ramp = std::min(spec_.ramp_s, 0.5 * cur.duration_s);
  double w = 1.0, dw = 0.0;
  const double x = (t - seg_start_[i]) / ramp;
  if (ramp > 0.0 && x < 1.0) {
    const double xc = std::max(x, 0.0);
    w = blend(xc);
    dw = blend_rate(xc) / ramp;
  }
  auto mix = [&](double p, double c) { return p + (c - p) * w; };
  auto rate = [&](double p, double c) { return (c - p) * dw; };
  return Commands{mix(prev.accel_mps2, cur.accel_mps2),          mix(prev.turn_rate_rps, cur.turn_rate_rps),
                  mix(prev.climb_rate_mps, cur.climb_rate_mps),  mix(prev.grade_rad, cur.grade_rad),
                  rate(prev.accel_mps2, cur.accel_mps2),         rate(prev.turn_rate_rps, cur.turn_rate_rps),
                  rate(prev.climb_rate_mps, cur.climb_rate_mps), rate(prev.grade_rad, cur.grade_rad)};
}

// Kinematics shared by the derivative and the truth sample.
namespace {

struct Kinematics {
  Eigen::Vector3d v_n, dv_n;  // velocity and its rate
  EulerAngles e;
  Eigen::Vector3d euler_rate;  // roll, pitch, yaw rates
};

Kinematics kinematics(double s, double psi, double a, double r, double c, double gr, double dr, double dc, double dgr,
                      const TrajectorySpec& spec) {
  const bool coordinated = spec.coordinated_turns;
  Kinematics k;
  const double cp = std::cos(psi), sp = std::sin(psi);
  const double tg = std::tan(gr), sec2 = 1.0 + tg * tg;
  const double v_up = c + s * tg;
  k.v_n = {s * cp, s * sp, -v_up};
  k.dv_n = {a * cp - s * r * sp, a * sp + s * r * cp, -(dc + a * tg + s * sec2 * dgr)};
  // pitch: road grade plus the flight-path angle of the climb (speed softened near rest)
  const double w = std::sqrt(s * s + 1.0);
  const double dw = s * a / w;
  k.e.pitch_rad = gr + std::atan2(c, w) + spec.pitch0_rad;
  const double dpitch = dgr + (w * dc - c * dw) / (c * c + w * w);
  double roll = 0.0, droll = 0.0;
  if (coordinated) {
    const double u = s * r / kG0;
    roll = std::atan(u);
    droll = (a * r + s * dr) / kG0 / (1.0 + u * u);
  }
  k.e.roll_rad = roll + spec.roll0_rad;
  k.e.yaw_rad = psi;
  k.euler_rate = {droll, dpitch, r};
  return k;
}

// The vibration tones at t added to the smooth kinematics: displacement -(a / w^2) sin, velocity -(a / w) cos,
// acceleration a sin (local level), angles and their rates.
void add_vibrations(const std::vector<Vibration>& tones, double t, Kinematics& k) {
  for (const Vibration& v : tones) {
    const double w = 2.0 * std::numbers::pi * v.frequency_hz;
    const double s = std::sin(w * t + v.phase_rad), c = std::cos(w * t + v.phase_rad);
    const Eigen::Vector3d a(v.accel_amplitude_n_mps2[0], v.accel_amplitude_n_mps2[1], v.accel_amplitude_n_mps2[2]);
    const Eigen::Vector3d theta(v.angle_amplitude_rad[0], v.angle_amplitude_rad[1], v.angle_amplitude_rad[2]);
    k.v_n += -(c / w) * a;
    k.dv_n += s * a;
    k.e.roll_rad += s * theta.x();
    k.e.pitch_rad += s * theta.y();
    k.e.yaw_rad += s * theta.z();
    k.euler_rate += (w * c) * theta;
  }
}

Eigen::Vector3d w_nb_b(const EulerAngles& e, const Eigen::Vector3d& rate) {
  const double sf = std::sin(e.roll_rad), cf = std::cos(e.roll_rad);
  const double st = std::sin(e.pitch_rad), ct = std::cos(e.pitch_rad);
  return {rate.x() - rate.z() * st, rate.y() * cf + rate.z() * sf * ct, -rate.y() * sf + rate.z() * cf * ct};
}

}  // namespace

TrajectoryGenerator::State TrajectoryGenerator::derivative(double t, const State& y) const {
  const Commands u = commands(t);
  Kinematics k = kinematics(y[0], y[1], u.a, u.r, u.climb, u.grade, u.dr, u.dclimb, u.dgrade, spec_);
  const double path_rate = k.v_n.norm();  // the smooth ride's: an odometer does not count the vibration
  add_vibrations(spec_.vibrations, t, k);
  const double lat = y[2], h = y[4];
  const Eigen::Vector3d pos_rate = geodetic_rates(lat, h, k.v_n);
  const Eigen::Vector3d w_ie = earth_rate_n(lat);
  const Eigen::Vector3d w_en = transport_rate_n(lat, h, k.v_n);
  const Eigen::Matrix3d C_bn = quaternion_from_euler(k.e).toRotationMatrix().transpose();
  const Eigen::Vector3d f_n = k.dv_n + (2.0 * w_ie + w_en).cross(k.v_n) - gravity_n(lat, h);
  const Eigen::Vector3d f_b = C_bn * f_n;
  const Eigen::Vector3d w_ib = w_nb_b(k.e, k.euler_rate) + C_bn * (w_ie + w_en);
  State d;
  d[0] = u.a;
  d[1] = u.r;
  d[2] = pos_rate.x();
  d[3] = pos_rate.y();
  d[4] = pos_rate.z();
  d[5] = path_rate;
  for (int i = 0; i < 3; ++i) {
    d[6 + i] = w_ib[i];
    d[9 + i] = f_b[i];
  }
  return d;
}

void TrajectoryGenerator::fill_truth(double t, const State& y, TruthSample& out) const {
  const Commands u = commands(t);
  Kinematics k = kinematics(y[0], y[1], u.a, u.r, u.climb, u.grade, u.dr, u.dclimb, u.dgrade, spec_);
  add_vibrations(spec_.vibrations, t, k);
  out.t_s = t;
  out.lat_rad = y[2];
  out.lon_rad = y[3];
  out.height_m = y[4];
  out.v_n = k.v_n;
  out.q_nb = quaternion_from_euler(k.e);
  const Eigen::Vector3d w_ie = earth_rate_n(y[2]);
  const Eigen::Vector3d w_en = transport_rate_n(y[2], y[4], k.v_n);
  const Eigen::Matrix3d C_bn = out.q_nb.toRotationMatrix().transpose();
  out.f_b = C_bn * (k.dv_n + (2.0 * w_ie + w_en).cross(k.v_n) - gravity_n(y[2], y[4]));
  out.w_ib_b = w_nb_b(k.e, k.euler_rate) + C_bn * (w_ie + w_en);
  out.distance_m = y[5];
}

ImuIncrement TrajectoryGenerator::advance() {
  const double t0 = static_cast<double>(k_) * dt_;
  const double h = dt_ / substeps_;
  for (int i = 6; i < 12; ++i) y_[i] = 0.0;
  auto axpy = [](const State& y, double s, const State& d) {
    State o;
    for (std::size_t i = 0; i < o.size(); ++i) o[i] = y[i] + s * d[i];
    return o;
  };
  for (int j = 0; j < substeps_; ++j) {
    const double t = t0 + j * h;
    const State k1 = derivative(t, y_);
    const State k2 = derivative(t + 0.5 * h, axpy(y_, 0.5 * h, k1));
    const State k3 = derivative(t + 0.5 * h, axpy(y_, 0.5 * h, k2));
    const State k4 = derivative(t + h, axpy(y_, h, k3));
    for (std::size_t i = 0; i < y_.size(); ++i) y_[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  ++k_;
  const double t1 = static_cast<double>(k_) * dt_;
  fill_truth(t1, y_, truth_);
  ImuIncrement inc;
  inc.t_s = t1;
  inc.dtheta_b = {y_[6], y_[7], y_[8]};
  inc.dv_b = {y_[9], y_[10], y_[11]};
  return inc;
}

SimulatedRun simulate(const TrajectorySpec& spec, double imu_rate_hz) {
  TrajectoryGenerator gen(spec, imu_rate_hz);
  SimulatedRun run;
  run.truth.push_back(gen.truth());
  while (!gen.done()) {
    run.imu.push_back(gen.advance());
    run.truth.push_back(gen.truth());
  }
  return run;
}

}  // namespace ultratrack::ins
