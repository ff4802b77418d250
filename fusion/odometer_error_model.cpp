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

OdometerNominal corrected(const OdometerNominal& n, const Eigen::Vector4d& dx) {
  OdometerNominal out = n;
  out.delay_s -= dx(0);
  out.pitch_rad -= dx(1);
  out.yaw_rad -= dx(2);
  out.scale_factor -= dx(3);
  return out;
}

OdometerNominal corrected(const OdometerNominal& n, const StateVector<19>& dx) {
  static_assert(ix::kOdoPitch == ix::kOdoDelay + 1 && ix::kOdoYaw == ix::kOdoDelay + 2 &&
                ix::kOdoScale == ix::kOdoDelay + 3);
  return corrected(n, Eigen::Vector4d(dx.segment<4>(ix::kOdoDelay)));
}

template <int NB>
OdometerAugmentedModel<NB>::OdometerAugmentedModel(const InsErrorModelOptions& options,
                                                   const OdometerAidingOptions& odometer)
    : ins_(options), odo_(odometer) {
  if (std::string why; !odometer.IsValid(&why)) throw std::invalid_argument(why);
  set_linearisation(InsLinearisation{});
}

template <int NB>
void OdometerAugmentedModel<NB>::set_linearisation(const InsLinearisation& lin) {
  ins_.set_linearisation(lin);
  F_.setZero();
  F_.template topLeftCorner<NB, NB>() = ins_.F(StateVector<NB>::Zero());
  cached_dt_ = -1.0;
}

template <int NB>
auto OdometerAugmentedModel<NB>::transition(double dt) const -> const StateMatrix<N>& {
  if (dt != cached_dt_) {
    cached_phi_.setIdentity();
    cached_phi_.template topLeftCorner<NB, NB>() = ins_.transition(dt);  // the odometer states are constant
    cached_dt_ = dt;
  }
  return cached_phi_;
}

template <int NB>
auto OdometerAugmentedModel<NB>::f(const StateVector<N>& x, double dt) const -> StateVector<N> {
  return transition(dt) * x;
}

template <int NB>
auto OdometerAugmentedModel<NB>::G(const StateVector<N>&) const -> Eigen::Matrix<double, N, kNoiseSize> {
  Eigen::Matrix<double, N, kNoiseSize> g = Eigen::Matrix<double, N, kNoiseSize>::Zero();
  g.template topLeftCorner<NB, kNoiseSize - 4>() = ins_.G(StateVector<NB>::Zero());
  g.template bottomRightCorner<4, 4>().setIdentity();
  return g;
}

template <int NB>
auto OdometerAugmentedModel<NB>::Qc() const -> Eigen::Matrix<double, kNoiseSize, kNoiseSize> {
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> q = Eigen::Matrix<double, kNoiseSize, kNoiseSize>::Zero();
  q.template topLeftCorner<kNoiseSize - 4, kNoiseSize - 4>() = ins_.Qc();
  const int o = kNoiseSize - 4;
  q(o + 0, o + 0) = odo_.delay_psd;
  q(o + 1, o + 1) = odo_.misalignment_psd;
  q(o + 2, o + 2) = odo_.misalignment_psd;
  q(o + 3, o + 3) = odo_.scale_factor_psd;
  return q;
}

template <int NB>
auto OdometerAugmentedModel<NB>::initial_covariance(const Eigen::Vector3d& sp, const Eigen::Vector3d& sv,
                                                    const Eigen::Vector3d& sa) const -> StateMatrix<N> {
  StateMatrix<N> P = StateMatrix<N>::Zero();
  P.template topLeftCorner<NB, NB>() = ins_.initial_covariance(sp, sv, sa);
  const Eigen::Vector4d sigma(odo_.sigma_delay_s, odo_.sigma_misalignment_rad, odo_.sigma_misalignment_rad,
                              odo_.sigma_scale_factor);
  P.template bottomRightCorner<4, 4>() = sigma.cwiseAbs2().asDiagonal();
  return P;
}

template class OdometerAugmentedModel<15>;
template class OdometerAugmentedModel<17>;

}  // namespace ultratrack::fusion
