// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/odometer_error_model.hpp"

#include <cmath>
#include <stdexcept>

namespace ultratrack::fusion {

bool OdometerAidingOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  auto non_negative = [](double x) { return x >= 0.0 && std::isfinite(x); };
  if (!non_negative(yaw_rate_threshold_rad_s)) return fail("odometer: the yaw-rate threshold must be >= 0");
  if (!non_negative(min_speed_mps)) return fail("odometer: the minimum speed must be >= 0");
  if (!positive(update_rate_hz)) return fail("odometer: the update rate must be positive");
  if (!lever_arm_b.allFinite()) return fail("odometer: the lever arm must be finite");
  if (!positive(sigma_scale_factor) || !positive(sigma_misalignment_rad) || !positive(sigma_delay_s))
    return fail("odometer: the initial sigmas must be positive");
  if (!non_negative(scale_factor_psd) || !non_negative(misalignment_psd) || !non_negative(delay_psd))
    return fail("odometer: the random-walk PSDs must be >= 0");
  if (!positive(sigma_forward_mps) || !positive(sigma_lateral_mps) || !positive(sigma_vertical_mps))
    return fail("odometer: the measurement sigmas must be positive");
  return true;
}

OdometerNominal corrected(const OdometerNominal& n, const StateVector<19>& dx) {
  OdometerNominal out = n;
  out.delay_s -= dx(ix::kOdoDelay);
  out.pitch_rad -= dx(ix::kOdoPitch);
  out.yaw_rad -= dx(ix::kOdoYaw);
  out.scale_factor -= dx(ix::kOdoScale);
  return out;
}

OdometerAugmentedModel::OdometerAugmentedModel(const InsErrorModelOptions& options,
                                               const OdometerAidingOptions& odometer)
    : ins_(options), odo_(odometer) {
  if (std::string why; !odometer.IsValid(&why)) throw std::invalid_argument(why);
  set_linearisation(InsLinearisation{});
}

void OdometerAugmentedModel::set_linearisation(const InsLinearisation& lin) {
  ins_.set_linearisation(lin);
  F_.setZero();
  F_.topLeftCorner<15, 15>() = ins_.F(StateVector<15>::Zero());
  cached_dt_ = -1.0;
}

const StateMatrix<19>& OdometerAugmentedModel::transition(double dt) const {
  if (dt != cached_dt_) {
    cached_phi_.setIdentity();
    cached_phi_.topLeftCorner<15, 15>() = ins_.transition(dt);  // the odometer states are constant
    cached_dt_ = dt;
  }
  return cached_phi_;
}

StateVector<19> OdometerAugmentedModel::f(const StateVector<19>& x, double dt) const { return transition(dt) * x; }

auto OdometerAugmentedModel::G(const StateVector<19>&) const -> Eigen::Matrix<double, 19, kNoiseSize> {
  Eigen::Matrix<double, 19, kNoiseSize> g = Eigen::Matrix<double, 19, kNoiseSize>::Zero();
  g.topLeftCorner<15, kNoiseSize - 4>() = ins_.G(StateVector<15>::Zero());
  g.bottomRightCorner<4, 4>().setIdentity();
  return g;
}

auto OdometerAugmentedModel::Qc() const -> Eigen::Matrix<double, kNoiseSize, kNoiseSize> {
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> q = Eigen::Matrix<double, kNoiseSize, kNoiseSize>::Zero();
  q.topLeftCorner<kNoiseSize - 4, kNoiseSize - 4>() = ins_.Qc();
  const int o = kNoiseSize - 4;
  q(o + 0, o + 0) = odo_.delay_psd;
  q(o + 1, o + 1) = odo_.misalignment_psd;
  q(o + 2, o + 2) = odo_.misalignment_psd;
  q(o + 3, o + 3) = odo_.scale_factor_psd;
  return q;
}

StateMatrix<19> OdometerAugmentedModel::initial_covariance(const Eigen::Vector3d& sp, const Eigen::Vector3d& sv,
                                                           const Eigen::Vector3d& sa) const {
  StateMatrix<19> P = StateMatrix<19>::Zero();
  P.topLeftCorner<15, 15>() = ins_.initial_covariance(sp, sv, sa);
  P(ix::kOdoDelay, ix::kOdoDelay) = odo_.sigma_delay_s * odo_.sigma_delay_s;
  P(ix::kOdoPitch, ix::kOdoPitch) = odo_.sigma_misalignment_rad * odo_.sigma_misalignment_rad;
  P(ix::kOdoYaw, ix::kOdoYaw) = odo_.sigma_misalignment_rad * odo_.sigma_misalignment_rad;
  P(ix::kOdoScale, ix::kOdoScale) = odo_.sigma_scale_factor * odo_.sigma_scale_factor;
  return P;
}

}  // namespace ultratrack::fusion
