// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/ultratight_integration.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

#include "fusion/ultratight_core.hpp"

namespace ultratrack::fusion {

using ultratight_detail::make_core;

bool UltraTightOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  const UltraTightOptions& o = *this;
  auto positive = [](const Eigen::Vector3d& v) { return (v.array() > 0.0).all() && v.allFinite(); };
  if (!positive(o.sigma_pos_ned_m) || !positive(o.sigma_vel_n_mps) || !positive(o.sigma_att_rad))
    return fail("ultra-tight: initial sigmas must be positive");
  if (!(o.tap_offset_chips > 0.0 && o.tap_offset_chips <= 0.5))
    return fail("ultra-tight: tap offset must lie in (0, 0.5] chip");
  if (!(o.gate.probability > 0.0 && o.gate.probability < 1.0))
    return fail("ultra-tight: gate probability must lie in (0, 1)");
  if (!std::isfinite(o.coast_cn0_dbhz)) return fail("ultra-tight: coasting threshold not finite");
  if (std::isnan(o.measurement_mask_rad)) return fail("ultra-tight: measurement mask is NaN");
  if (std::string inner; o.odometer.enabled && !o.odometer.IsValid(&inner)) return fail("ultra-tight: " + inner);
  return true;
}

struct UltraTightIntegration::Impl {
  UltraTightOptions options;
  std::unique_ptr<ultratight_detail::UltraTightCoreBase> core;
};

UltraTightIntegration::UltraTightIntegration(const ins::NavState& initial, std::vector<signals::Ephemeris> eph,
                                             const UltraTightOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument(why);
  impl_->options = options;
  InsErrorModelOptions mo = options.model;
  mo.discretisation = options.discretisation;
  impl_->options.model = mo;
  const StateMatrix<17> P17 =
      InsErrorModel<17>(mo).initial_covariance(options.sigma_pos_ned_m, options.sigma_vel_n_mps, options.sigma_att_rad);
  if (options.odometer.enabled) {
    // The odometer's states after the clock's: their initial sigmas (the given ones, else the options' own),
    // uncorrelated with the rest.
    const OdometerAidingOptions& oo = options.odometer;
    const OdometerNominal& given = options.sigma_initial_odometer;
    const auto pick = [](double g, double fallback) { return g > 0.0 ? g : fallback; };
    const Eigen::Vector4d sigma(pick(given.delay_s, oo.sigma_delay_s), pick(given.pitch_rad, oo.sigma_misalignment_rad),
                                pick(given.yaw_rad, oo.sigma_misalignment_rad),
                                pick(given.scale_factor, oo.sigma_scale_factor));
    StateMatrix<21> P0 = StateMatrix<21>::Zero();
    P0.topLeftCorner<17, 17>() = P17;
    P0.bottomRightCorner<4, 4>() = sigma.cwiseAbs2().asDiagonal();
    impl_->core = make_core<21>(initial, std::move(eph), impl_->options, P0);
  } else {
    impl_->core = make_core<17>(initial, std::move(eph), impl_->options, P17);
  }
}

UltraTightIntegration::~UltraTightIntegration() = default;
UltraTightIntegration::UltraTightIntegration(UltraTightIntegration&&) noexcept = default;
UltraTightIntegration& UltraTightIntegration::operator=(UltraTightIntegration&&) noexcept = default;

void UltraTightIntegration::add_imu(const ins::ImuIncrement& inc) { impl_->core->add_imu(inc); }
void UltraTightIntegration::add_ephemerides(const std::vector<signals::Ephemeris>& eph) {
  impl_->core->add_ephemerides(eph);
}
const std::vector<ReplicaCommand>& UltraTightIntegration::start_period(double T) {
  impl_->core->start_period(T);
  return impl_->core->replicas;
}
void UltraTightIntegration::finish_period(const std::vector<ChannelCorrelation>& c) { impl_->core->finish_period(c); }
const std::vector<ReplicaCommand>& UltraTightIntegration::replicas() const { return impl_->core->replicas; }
const IntegrationOutput& UltraTightIntegration::output() const { return impl_->core->output; }
NominalState UltraTightIntegration::nominal() const { return impl_->core->nominal(); }
Eigen::MatrixXd UltraTightIntegration::covariance() const { return impl_->core->covariance(); }
void UltraTightIntegration::set_covariance(const Eigen::MatrixXd& P) {
  if (P.rows() != 17 || P.cols() != 17 || !P.allFinite() || !P.isApprox(P.transpose()))
    throw std::invalid_argument("ultra-tight: a covariance must be a finite symmetric 17 x 17 matrix");
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(P);
  if (!(eig.eigenvalues().minCoeff() > 0.0))
    throw std::invalid_argument("ultra-tight: a covariance must be positive definite");
  impl_->core->set_covariance(P);
}
void UltraTightIntegration::add_odometer(const OdometerSpeed& speed) { impl_->core->add_odometer(speed); }
const UltraTightCounters& UltraTightIntegration::counters() const { return impl_->core->counters; }
const std::vector<UltraTightSatelliteUpdate>& UltraTightIntegration::last_updates() const {
  return impl_->core->last_updates;
}
const UltraTightOptions& UltraTightIntegration::options() const { return impl_->options; }

}  // namespace ultratrack::fusion
