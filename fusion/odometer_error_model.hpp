// SPDX-License-Identifier: GPL-3.0-or-later
// The 19-state land-navigation error model of [KimVMS] (sec. 2-1): the 15 INS error states of
// fusion/ins_error_state.hpp plus four odometer (VMS) states, each estimate minus truth:
//   [15] VMS time delay error, s         [16] mounting misalignment pitch error, rad (about the vehicle's y)
//   [17] mounting misalignment yaw error, rad (about z)          [18] VMS scale-factor error, ratio
// The tight coupling keeps its clock states at [15, 17) and appends the same four at [17, 21): the model is a
// template on the base size NB (15, or 17 with the clock) and the odometer states sit at [NB, NB + 4) in that order.
// The ix::kOdo* indices below are those of the 19-state order, in which fusion/vms_measurement.hpp is written.
// The odometer states are random constants with an optional random walk (tyre wear, load). The options hold
// the odometer aiding's settings too: the gating rule of eqs. 16-17 (fusion/vms_measurement.hpp), its rate,
// the lever arm to the wheels' non-holonomic point and the measurement sigmas.
// Satisfies ProcessModel<NB + 4> (filter_types.hpp): the EKF and the UKF take it as they take the 15-state model.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

namespace ix {
inline constexpr int kOdoDelay = 15;
inline constexpr int kOdoPitch = 16;
inline constexpr int kOdoYaw = 17;
inline constexpr int kOdoScale = 18;
}  // namespace ix

enum class OdometerMode {
  kGated,   // [KimVMS]: update only while the heading change rate and the VMS speed pass their thresholds
  kAlways,  // every update interval, turns and stops included (the always-on non-holonomic constraint)
};

struct OdometerAidingOptions {
  bool enabled = false;
  OdometerMode mode = OdometerMode::kGated;
  double yaw_rate_threshold_rad_s = 1.5 * 3.14159265358979323846 / 180.0;  // eq. 16 (|heading change| per second)
  double min_speed_mps = 5.0;                                              // eq. 17 (VMS speed)
  double update_rate_hz = 1.0;  // one update per 1 / rate: the VMS speed is the distance over that window / window
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // IMU -> wheels' non-holonomic point, body axes [m]
  // Initial 1-sigma of the odometer states (their nominal starts at zero).
  double sigma_scale_factor = 0.01;
  double sigma_misalignment_rad = 0.5 * 3.14159265358979323846 / 180.0;
  double sigma_delay_s = 0.05;
  // Random-walk PSDs of the odometer states [unit^2 / s] (0: random constants).
  double scale_factor_psd = 1e-12;
  double misalignment_psd = 0.0;
  double delay_psd = 0.0;
  // Measurement 1-sigmas: forward speed (pulse quantisation, wheel radius ripple), lateral and vertical
  // body velocity (sideslip, suspension).
  double sigma_forward_mps = 0.05;
  double sigma_lateral_mps = 0.1;
  double sigma_vertical_mps = 0.1;

  bool IsValid(std::string* why) const;
};

// The odometer's nominal parameters (what the filter's corrections are folded into).
struct OdometerNominal {
  double delay_s = 0.0;
  double pitch_rad = 0.0, yaw_rad = 0.0;  // mounting misalignment, ins::C_bv_from_misalignment
  double scale_factor = 0.0;              // measured speed = (1 + scale_factor) true speed
};

// Estimates with their 1-sigma (the filter's output).
struct OdometerEstimate {
  OdometerNominal value;
  OdometerNominal sigma;
};

// The nominal with the error state's odometer part removed (truth = nominal - dx); dx_odometer holds the four
// odometer states in the order delay, pitch, yaw, scale factor.
OdometerNominal corrected(const OdometerNominal& nominal, const Eigen::Vector4d& dx_odometer);
// The same from a 19-state vector (odometer states at ix::kOdo*).
OdometerNominal corrected(const OdometerNominal& nominal, const StateVector<19>& dx);

// NB = 15: the INS errors (loose); NB = 17: the INS and receiver clock errors (tight). N = NB + 4.
template <int NB>
class OdometerAugmentedModel {
 public:
  static constexpr int N = NB + 4;
  static constexpr int kIndex = NB;  // first odometer state (the delay)
  static constexpr int kNoiseSize = InsErrorModel<NB>::kNoiseSize + 4;

  OdometerAugmentedModel(const InsErrorModelOptions& options, const OdometerAidingOptions& odometer);

  void set_linearisation(const InsLinearisation& lin);
  StateVector<N> f(const StateVector<N>& x, double dt) const;
  const StateMatrix<N>& transition(double dt) const;
  StateMatrix<N> F(const StateVector<N>& /*x*/) const { return F_; }
  Eigen::Matrix<double, N, kNoiseSize> G(const StateVector<N>& x) const;
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const;
  // The base model's covariance and the odometer sigmas, uncorrelated.
  StateMatrix<N> initial_covariance(const Eigen::Vector3d& sigma_pos_ned_m, const Eigen::Vector3d& sigma_vel_n_mps,
                                    const Eigen::Vector3d& sigma_att_rad) const;

 private:
  InsErrorModel<NB> ins_;
  OdometerAidingOptions odo_;
  StateMatrix<N> F_ = StateMatrix<N>::Zero();
  mutable double cached_dt_ = -1.0;
  mutable StateMatrix<N> cached_phi_ = StateMatrix<N>::Identity();
};

extern template class OdometerAugmentedModel<15>;
extern template class OdometerAugmentedModel<17>;

// A measurement written for the 19-state order (INS errors, then the odometer's four: VmsMeasurement) as a filter
// of N states takes it whose odometer states start at Offset (the other states do not enter it).
template <class M, int Offset, int N>
class OdometerStatesAt {
 public:
  static constexpr int kMeasurementSize = measurement_size_v<M>;
  explicit OdometerStatesAt(M m) : m_(std::move(m)) {}
  Eigen::VectorXd z() const { return m_.z(); }
  Eigen::VectorXd h(const StateVector<N>& dx) const { return m_.h(gather(dx)); }
  MeasurementJacobian<N> H(const StateVector<N>& dx) const {
    const MeasurementJacobian<19> h19 = m_.H(gather(dx));
    MeasurementJacobian<N> out = MeasurementJacobian<N>::Zero(h19.rows(), N);
    out.leftCols(15) = h19.leftCols(15);
    out.middleCols(Offset, 4) = h19.rightCols(4);
    return out;
  }
  Eigen::MatrixXd R() const { return m_.R(); }

 private:
  static StateVector<19> gather(const StateVector<N>& dx) {
    StateVector<19> x;
    x << dx.template head<15>(), dx.template segment<4>(Offset);
    return x;
  }
  M m_;
};

}  // namespace ultratrack::fusion
