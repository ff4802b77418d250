// SPDX-License-Identifier: GPL-3.0-or-later
// In-motion coarse alignment for a MEMS IMU (which cannot gyrocompass): heading from the GNSS track once
// the vehicle moves (no sideslip assumed: body x along the horizontal velocity), roll and pitch from the
// accelerometers with the GNSS-measured acceleration removed: f_n = dv_n/dt - g_n + (2 w_ie + w_en) x v_n.
// Units SI, NED; times on the IMU's time line.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <span>

#include "ins/attitude.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::fusion {

struct GnssVelocitySample {
  double t_s = 0.0;
  double lat_rad = 0.0, height_m = 0.0;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  double sigma_horizontal_mps = 0.0;  // 1-sigma of each horizontal component (0: not known)
};

struct MotionAlignmentOptions {
  double min_speed_mps = 5.0;  // both ends of the window at least this fast horizontally
  double window_s = 2.0;       // GNSS velocity difference span (longer: less velocity noise in the tilt)
  // Gyro biases already known (a standstill before the motion, ins/standstill_gyro_bias.hpp), removed from the
  // increments; the sensitivities below are then to the residual bias.
  Eigen::Vector3d gyro_bias_b = Eigen::Vector3d::Zero();
};

struct MotionAlignment {
  double t_s = 0.0;        // end of the window: the attitude and velocity hold here
  double t_start_s = 0.0;  // start of the window (the first GNSS velocity's time)
  ins::EulerAngles euler;
  Eigen::Quaterniond q_nb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  double sigma_heading_rad = 0.0;  // from the end velocity's sigma_horizontal_mps and speed (0: not known)
  Eigen::Vector3d mean_f_b = Eigen::Vector3d::Zero();  // measured over the window [m/s^2]
  Eigen::Vector3d f_n = Eigen::Vector3d::Zero();       // the same specific force from GNSS [m/s^2]
  // First-order sensitivities of the attitude error psi (NED, rad; C_nb_est = (I - [psi x]) C_nb_true) to an
  // accelerometer bias [rad per m/s^2] and a gyro bias [rad per rad/s] (body axes, constant over the window), and
  // to an error of the GNSS velocity at the window's start and at its end [rad per m/s, NED]: central
  // differences of the same levelling.
  Eigen::Matrix3d psi_per_accel_bias = Eigen::Matrix3d::Zero(), psi_per_gyro_bias = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d psi_per_velocity_start = Eigen::Matrix3d::Zero(), psi_per_velocity_end = Eigen::Matrix3d::Zero();
};

// Roll and pitch such that C_nb(roll, pitch, heading) f_b = f_n, for a known heading; of the two solutions
// the one with the smaller |pitch|. Returns nothing when no attitude with this heading can map f_b to f_n
// (their norms or the geometry disagree by more than the accelerometer could explain).
std::optional<ins::EulerAngles> level_with_heading(const Eigen::Vector3d& f_b, const Eigen::Vector3d& f_n,
                                                   double heading_rad);

// The first window of GNSS velocities [t_i, t_j] (t_j - t_i >= window_s, both fast enough) that the IMU
// covers, aligned as above. The IMU increments must be sorted; nothing when no such window exists.
std::optional<MotionAlignment> align_in_motion(std::span<const ins::ImuIncrement> imu,
                                               std::span<const GnssVelocitySample> gnss,
                                               const MotionAlignmentOptions& options = {});

}  // namespace ultratrack::fusion
