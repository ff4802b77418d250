// SPDX-License-Identifier: GPL-3.0-or-later
// The 12-state stationary alignment filter of [KimAlign] (eqs. 2-17): the error model of a strapdown INS at rest
// and its two measurements, zero velocity and the GPS Euler attitude through H_G.
//   [0,3)  dv_n  velocity error, NED m/s             [3,6)  psi  attitude error, NED rad (psi-angle, the
//          convention of ins/nav_state.hpp: C_nb_est = (I - [psi x]) C_nb_true)
//   [6,9)  ba    residual accelerometer bias, body m/s^2      [9,12) bg  residual gyro bias, body rad/s
// Position is not a state (the alignment runs on a surveyed point, [KimAlign] section III.1). Errors are estimate
// minus truth; a residual bias is what remains in the compensated IMU output (fusion/ins_error_state.hpp).
// The model is linear and time invariant while the vehicle is at rest: A = [F T; 0 0] with F = [F11 F12; 0 F22]
// (eqs. 5-8, Omega = earth rate in NED, g = gravity) and T = diag(C_nb, -C_nb) (eq. 9). Noise: accelerometer and
// gyro white noise (VRW^2, ARW^2 PSDs) drive dv and psi; the biases are random constants with an optional small
// random walk.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fusion/filter_types.hpp"
#include "ins/attitude.hpp"
#include "ins/imu_error_model.hpp"

namespace ultratrack::fusion {

inline constexpr int kAlignmentStates = 12;
using AlignmentVector = StateVector<kAlignmentStates>;
using AlignmentMatrix = StateMatrix<kAlignmentStates>;

namespace align_ix {
inline constexpr int kVel = 0;
inline constexpr int kAtt = 3;
inline constexpr int kAccelBias = 6;
inline constexpr int kGyroBias = 9;
}  // namespace align_ix

// Where the alignment runs and what it assumes of the sensors.
struct StationaryAlignmentModelOptions {
  double lat_rad = 0.0;
  double gravity_mps2 = 9.80665;
  double accel_white_psd = 0.0;      // VRW^2, (m/s)^2/s
  double gyro_white_psd = 0.0;       // ARW^2, rad^2/s
  double accel_bias_walk_psd = 0.0;  // (m/s^2)^2/s
  double gyro_bias_walk_psd = 0.0;   // (rad/s)^2/s
};

// The model's noise from an IMU spec (random walks -> white PSDs; bias instability as a random walk of PSD
// 2 sigma^2 / tau, its short-term growth).
StationaryAlignmentModelOptions alignment_model_options(const ins::ImuErrorSpec& spec, double lat_rad,
                                                        double gravity_mps2);

// A = [F T; 0 0] of eqs. 2-9 at attitude C_nb.
AlignmentMatrix stationary_error_dynamics(const Eigen::Matrix3d& C_nb, const StationaryAlignmentModelOptions& o);

// H_G of eq. 16: (d roll, d pitch, d yaw) = H_G psi for the Euler angles of C_nb_est against C_nb_true.
// Singular at pitch +-90 deg (1 / cos pitch).
Eigen::Matrix3d euler_error_from_psi(const ins::EulerAngles& e);

// The process model (fusion/filter_types.hpp ProcessModel, linear) at a fixed attitude.
class StationaryAlignmentModel {
 public:
  static constexpr int kNoiseSize = 12;  // accel white, gyro white, accel bias walk, gyro bias walk

  StationaryAlignmentModel(const Eigen::Matrix3d& C_nb, const StationaryAlignmentModelOptions& o);

  AlignmentVector f(const AlignmentVector& x, double dt) const { return transition(dt) * x; }
  AlignmentMatrix transition(double dt) const;
  AlignmentMatrix F(const AlignmentVector&) const { return A_; }
  Eigen::Matrix<double, 12, kNoiseSize> G(const AlignmentVector&) const { return G_; }
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const { return Qc_; }

 private:
  AlignmentMatrix A_;
  Eigen::Matrix<double, 12, kNoiseSize> G_;
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc_;
};

// Zero velocity (eq. 17, first row): the INS velocity of a vehicle at rest is its velocity error.
class ZeroVelocityMeasurement {
 public:
  static constexpr int kMeasurementSize = 3;
  ZeroVelocityMeasurement(const Eigen::Vector3d& v_n_ins, double sigma_mps) : v_(v_n_ins), sigma_(sigma_mps) {}
  Eigen::Vector3d z() const { return v_; }
  Eigen::Vector3d h(const AlignmentVector& x) const { return x.segment<3>(align_ix::kVel); }
  Eigen::Matrix<double, 3, 12> H(const AlignmentVector&) const;
  Eigen::Matrix3d R() const { return Eigen::Matrix3d::Identity() * sigma_ * sigma_; }

 private:
  Eigen::Vector3d v_;
  double sigma_;
};

// GPS Euler attitude (eq. 17, second row): z = Euler(C_nb_ins) - Euler(C_nb_gps) (yaw wrapped to +-pi), the
// GPS attitude being the array's through the known mounting. h(x) = Euler(C_nb_ins) - Euler(C_nb_ins corrected
// by psi) exactly (for the UKF's sigma points); its Jacobian at x = 0 is H_G (eq. 16), which the EKF uses.
class EulerAttitudeMeasurement {
 public:
  static constexpr int kMeasurementSize = 3;
  EulerAttitudeMeasurement(const Eigen::Quaterniond& q_nb_ins, const Eigen::Quaterniond& q_nb_gps,
                           const Eigen::Vector3d& sigma_euler_rad);
  Eigen::Vector3d z() const { return z_; }
  Eigen::Vector3d h(const AlignmentVector& x) const;
  Eigen::Matrix<double, 3, 12> H(const AlignmentVector&) const;
  Eigen::Matrix3d R() const { return R_; }

 private:
  Eigen::Quaterniond q_ins_;
  ins::EulerAngles e_ins_;
  Eigen::Vector3d z_;
  Eigen::Matrix3d R_;
  Eigen::Matrix3d H_G_;
};

}  // namespace ultratrack::fusion
