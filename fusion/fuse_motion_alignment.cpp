// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/fuse_motion_alignment.hpp"

#include <algorithm>
#include <cmath>

#include "ins/earth_model.hpp"

namespace ultratrack::fusion {

std::optional<ins::EulerAngles> level_with_heading(const Eigen::Vector3d& f_b, const Eigen::Vector3d& f_n,
                                                   double heading_rad) {
  // Remove the heading: f_h = Rz(-heading) f_n must equal Ry(pitch) Rx(roll) f_b. Rx leaves x alone, so
  // f_b.x = cos(pitch) f_h.x - sin(pitch) f_h.z, i.e. A cos + B sin = C.
  const Eigen::Vector3d f_h = Eigen::AngleAxisd(-heading_rad, Eigen::Vector3d::UnitZ()) * f_n;
  const double A = f_h.x(), B = -f_h.z(), C = f_b.x();
  const double R = std::hypot(A, B);
  if (!(R > 0.0)) return std::nullopt;
  const double ratio = C / R;
  if (std::fabs(ratio) > 1.0 + 0.05) return std::nullopt;
  const double base = std::atan2(B, A);
  const double d = std::acos(std::clamp(ratio, -1.0, 1.0));
  const double p1 = ins::wrap_pi(base - d), p2 = ins::wrap_pi(base + d);
  ins::EulerAngles e;
  e.pitch_rad = std::fabs(p1) <= std::fabs(p2) ? p1 : p2;
  if (std::fabs(e.pitch_rad) > 1.5) return std::nullopt;
  // Then Rx(roll) f_b = Ry(-pitch) f_h in the y-z plane.
  const Eigen::Vector3d v = Eigen::AngleAxisd(-e.pitch_rad, Eigen::Vector3d::UnitY()) * f_h;
  e.roll_rad = ins::wrap_pi(std::atan2(v.z(), v.y()) - std::atan2(f_b.z(), f_b.y()));
  e.yaw_rad = ins::wrap_pi(heading_rad);
  return e;
}

namespace {

// IMU biases removed from a window's increments (for the sensitivities; zero for the alignment itself).
struct WindowBias {
  Eigen::Vector3d accel_b = Eigen::Vector3d::Zero(), gyro_b = Eigen::Vector3d::Zero();
};

struct WindowLevel {
  ins::EulerAngles euler;
  Eigen::Vector3d f_b, f_n;
};

// The levelling over one window: rows[0] is the IMU row whose time starts the first interval used, rows[1..] the
// intervals ending in (a.t_s, b.t_s].
std::optional<WindowLevel> level_window(std::span<const ins::ImuIncrement> rows, const GnssVelocitySample& a,
                                        const GnssVelocitySample& b, const WindowBias& bias) {
  // Mean specific force over the rows, every increment rotated by the gyros into the body frame at the window's
  // end (the attitude changes during roll-in or turns).
  Eigen::Vector3d sum_dv = Eigen::Vector3d::Zero();
  Eigen::Matrix3d to_end = Eigen::Matrix3d::Identity();  // body at the end of interval k -> body at the last row
  for (std::size_t k = rows.size() - 1; k >= 1; --k) {
    const double dt = rows[k].t_s - rows[k - 1].t_s;
    const Eigen::Vector3d dtheta = rows[k].dtheta_b - bias.gyro_b * dt;
    const Eigen::Vector3d dv = rows[k].dv_b - bias.accel_b * dt;
    const Eigen::Matrix3d half = ins::quaternion_from_rotation_vector(0.5 * dtheta).toRotationMatrix();
    sum_dv += to_end * half.transpose() * dv;
    to_end = to_end * ins::quaternion_from_rotation_vector(dtheta).toRotationMatrix().transpose();
  }
  const double T = b.t_s - a.t_s;
  const Eigen::Vector3d v_mid = 0.5 * (a.v_n + b.v_n);
  const double lat = 0.5 * (a.lat_rad + b.lat_rad), h = 0.5 * (a.height_m + b.height_m);
  WindowLevel w;
  w.f_n = (b.v_n - a.v_n) / T - ins::gravity_n(lat, h) +
          (2.0 * ins::earth_rate_n(lat) + ins::transport_rate_n(lat, h, v_mid)).cross(v_mid);
  w.f_b = sum_dv / (rows.back().t_s - rows.front().t_s);
  const auto level = level_with_heading(w.f_b, w.f_n, std::atan2(b.v_n.y(), b.v_n.x()));
  if (!level) return std::nullopt;
  w.euler = *level;
  return w;
}

}  // namespace

std::optional<MotionAlignment> align_in_motion(std::span<const ins::ImuIncrement> imu,
                                               std::span<const GnssVelocitySample> gnss,
                                               const MotionAlignmentOptions& o) {
  if (imu.size() < 2 || gnss.size() < 2) return std::nullopt;
  auto fast = [&](const GnssVelocitySample& s) { return s.v_n.head<2>().norm() >= o.min_speed_mps; };
  // The IMU's first interval starts one sample period before its first row.
  const double imu_start = imu[0].t_s - (imu[1].t_s - imu[0].t_s);
  for (std::size_t i = 0; i < gnss.size(); ++i) {
    if (!fast(gnss[i]) || gnss[i].t_s < imu_start) continue;
    std::size_t j = i + 1;
    while (j < gnss.size() && gnss[j].t_s - gnss[i].t_s < o.window_s) ++j;
    if (j == gnss.size()) return std::nullopt;
    if (!fast(gnss[j]) || gnss[j].t_s > imu.back().t_s) continue;
    // The IMU rows whose intervals end in (t_i, t_j].
    std::size_t k_first = 0, k_last = 0;
    int rows = 0;
    for (std::size_t k = 1; k < imu.size(); ++k) {
      if (imu[k].t_s <= gnss[i].t_s) continue;
      if (imu[k].t_s > gnss[j].t_s) break;
      if (rows == 0) k_first = k;
      k_last = k;
      ++rows;
    }
    if (rows < 2) continue;
    const std::span<const ins::ImuIncrement> rows_used = imu.subspan(k_first - 1, k_last - k_first + 2);
    const GnssVelocitySample &a = gnss[i], &b = gnss[j];
    const WindowBias known{Eigen::Vector3d::Zero(), o.gyro_bias_b};
    const auto level = level_window(rows_used, a, b, known);
    if (!level) continue;
    MotionAlignment r;
    r.t_s = b.t_s;
    r.t_start_s = a.t_s;
    r.euler = level->euler;
    r.q_nb = ins::quaternion_from_euler(r.euler);
    r.v_n = b.v_n;
    // The heading is the end velocity's direction: a horizontal velocity error across the track turns it by
    // sigma / speed.
    if (b.sigma_horizontal_mps > 0.0) r.sigma_heading_rad = b.sigma_horizontal_mps / b.v_n.head<2>().norm();
    r.mean_f_b = level->f_b;
    r.f_n = level->f_n;
    // psi of the alignment made with an error d in one input, against the one without: the derivative by central
    // differences (steps small against the levelling's curvature, large against rounding).
    const auto psi_per = [&](auto perturbed, double step) {
      Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
      for (int axis = 0; axis < 3; ++axis) {
        const auto plus = perturbed(axis, step), minus = perturbed(axis, -step);
        if (!plus || !minus) return Eigen::Matrix3d(Eigen::Matrix3d::Zero());
        m.col(axis) = (ins::attitude_error_n(ins::quaternion_from_euler(plus->euler), r.q_nb) -
                       ins::attitude_error_n(ins::quaternion_from_euler(minus->euler), r.q_nb)) /
                      (2.0 * step);
      }
      return m;
    };
    // A bias b in the IMU: the increments measured are the true ones plus b dt, so the truth is the levelling of
    // the increments minus b dt and psi(b) = psi(level(measured), level(measured - b dt)).
    const auto with_bias = [&](bool gyro, int axis, double d) {
      WindowBias bias = known;
      (gyro ? bias.gyro_b : bias.accel_b)[axis] += d;
      return level_window(rows_used, a, b, bias);
    };
    r.psi_per_accel_bias = -psi_per([&](int axis, double d) { return with_bias(false, axis, d); }, 1e-3);
    r.psi_per_gyro_bias = -psi_per([&](int axis, double d) { return with_bias(true, axis, d); }, 1e-4);
    // A GNSS velocity error e: the velocities used are the true ones plus e, the truth the levelling with them minus
    // e, so psi(e) = psi(level(used), level(used - e)): the opposite sign of the bias case.
    const auto with_velocity_error = [&](bool end, int axis, double d) {
      GnssVelocitySample aa = a, bb = b;
      (end ? bb : aa).v_n[axis] += d;
      return level_window(rows_used, aa, bb, known);
    };
    r.psi_per_velocity_start = psi_per([&](int axis, double d) { return with_velocity_error(false, axis, d); }, 1e-3);
    r.psi_per_velocity_end = psi_per([&](int axis, double d) { return with_velocity_error(true, axis, d); }, 1e-3);
    return r;
  }
  return std::nullopt;
}

}  // namespace ultratrack::fusion
