// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/gnss_ins_integration.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fusion/gnss_ins_core.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {

bool IntegrationOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  const IntegrationOptions& o = *this;
  if (o.coupling != Coupling::kLoose && o.coupling != Coupling::kTight)
    return fail("integration: the coupling must be loose or tight");
  auto positive = [](const Eigen::Vector3d& v) { return (v.array() > 0.0).all() && v.allFinite(); };
  if (!positive(o.sigma_pos_ned_m) || !positive(o.sigma_vel_n_mps) || !positive(o.sigma_att_rad))
    return fail("integration: initial sigmas must be positive");
  if ((o.sigma_initial_accel_bias_b && !positive(*o.sigma_initial_accel_bias_b)) ||
      (o.sigma_initial_gyro_bias_b && !positive(*o.sigma_initial_gyro_bias_b)) || !o.initial_accel_bias_b.allFinite() ||
      !o.initial_gyro_bias_b.allFinite())
    return fail("integration: initial biases must be finite, their sigmas positive");
  if (!o.attitude_per_bias.allFinite()) return fail("integration: the attitude's bias sensitivity must be finite");
  if (!(o.propagation_interval_s >= 0.0)) return fail("integration: negative propagation interval");
  if (!(o.gate.probability > 0.0 && o.gate.probability < 1.0))
    return fail("integration: gate probability must lie in (0, 1)");
  if (!(o.fix_min_interval_s >= 0.0) || !std::isfinite(o.fix_min_interval_s) || !(o.fix_error_correlation_s >= 0.0) ||
      !std::isfinite(o.fix_error_correlation_s))
    return fail("integration: the fix interval and error correlation time must be >= 0");
  if (std::string inner; !o.recovery.IsValid(&inner)) return fail("integration: " + inner);
  if (std::string inner; o.odometer.enabled && !o.odometer.IsValid(&inner)) return fail("integration: " + inner);
  if (std::string inner; o.fix_error.enabled && !o.fix_error.IsValid(&inner)) return fail("integration: " + inner);
  if (o.fix_error.enabled && o.coupling != Coupling::kLoose)
    return fail("integration: Gauss-Markov fix-error states are for the loose coupling (fixes) only");
  if (o.fix_error.enabled && o.fix_error_correlation_s > 0.0)
    return fail("integration: fix errors either as Gauss-Markov states or by an inflated variance, not both");
  if (o.coupling == Coupling::kTight && o.odometer.enabled && o.height_aiding.enabled)
    return fail("integration: odometer aiding and height aiding are not combined (the odometer bounds the height)");
  if (o.land.nhc &&
      (!(o.land.nhc_sigma_mps > 0.0) || !(o.land.nhc_interval_s >= 0.0) || !o.land.lever_arm_b.allFinite()))
    return fail("integration: non-holonomic constraints need a positive sigma and interval >= 0");
  if (!o.attitude.q_ba.coeffs().allFinite() || std::abs(o.attitude.q_ba.norm() - 1.0) > 1e-6)
    return fail("integration: attitude mounting q_ba must be a unit quaternion");
  if (!(o.attitude.max_abs_pitch_rad > 0.0 && o.attitude.max_abs_pitch_rad <= 0.5 * std::numbers::pi))
    return fail("integration: attitude pitch limit must lie in (0, 90] deg");
  const HeightAidingOptions& h = o.height_aiding;
  if (!(h.sigma0_m > 0.0) || !std::isfinite(h.sigma0_m) || !(h.terrain_sigma_m > 0.0) ||
      !std::isfinite(h.terrain_sigma_m) || !(h.terrain_correlation_s > 0.0) ||
      !std::isfinite(h.terrain_correlation_s) || !(h.min_interval_s >= 0.0) ||
      (h.fixed_height_m && !std::isfinite(*h.fixed_height_m)))
    return fail(
        "integration: height aiding needs positive sigmas and correlation time, interval >= 0, a finite height");
  return true;
}

using namespace gnss_ins_detail;

struct GnssInsIntegration::Impl {
  IntegrationOptions options;
  std::unique_ptr<CoreBase> core;
};

GnssInsIntegration::GnssInsIntegration(const ins::NavState& initial, const IntegrationOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument(why);
  impl_->options = options;
  const bool odometer = options.odometer.enabled, fix_error = options.fix_error.enabled;
  if (options.coupling == Coupling::kTight && odometer)
    impl_->core = make_core<Layout<true, false, true, false>>(initial, options);
  else if (options.coupling == Coupling::kTight)
    impl_->core = options.height_aiding.enabled ? make_core<Layout<true, true, false, false>>(initial, options)
                                                : make_core<Layout<true, false, false, false>>(initial, options);
  else if (odometer && fix_error)
    impl_->core = make_core<Layout<false, false, true, true>>(initial, options);
  else if (odometer)
    impl_->core = make_core<Layout<false, false, true, false>>(initial, options);
  else if (fix_error)
    impl_->core = make_core<Layout<false, false, false, true>>(initial, options);
  else
    impl_->core = make_core<Layout<false, false, false, false>>(initial, options);
}

GnssInsIntegration::~GnssInsIntegration() = default;
GnssInsIntegration::GnssInsIntegration(GnssInsIntegration&&) noexcept = default;
GnssInsIntegration& GnssInsIntegration::operator=(GnssInsIntegration&&) noexcept = default;

void GnssInsIntegration::add_fix(const GnssFix& fix) {
  if (impl_->options.coupling != Coupling::kLoose) throw std::logic_error("add_fix: integration is tightly coupled");
  impl_->core->add_pending(fix.t_s, PendingFix{fix});
}

void GnssInsIntegration::add_observations(const receiver::ObservationEpoch& epoch,
                                          const std::vector<signals::Ephemeris>& ephemerides,
                                          const signals::KlobucharParameters& iono) {
  if (impl_->options.coupling != Coupling::kTight)
    throw std::logic_error("add_observations: integration is loosely coupled");
  const double t_s = signals::seconds_between(epoch.receive_time, impl_->options.gps_time_origin) -
                     impl_->core->nominal().clock_bias_m / signals::kSpeedOfLight_mps;
  impl_->core->add_pending(t_s, PendingEpoch{epoch, ephemerides, iono});
}

void GnssInsIntegration::add_attitude(const GnssAttitude& attitude) {
  impl_->core->add_pending(attitude.t_s, PendingAttitude{attitude});
}

void GnssInsIntegration::add_odometer(const OdometerSpeed& speed) {
  if (!impl_->options.odometer.enabled) throw std::logic_error("add_odometer: odometer aiding is not enabled");
  impl_->core->add_pending(speed.t_s, PendingOdometer{speed});
}

void GnssInsIntegration::add_imu(const ins::ImuIncrement& inc) { impl_->core->add_imu(inc); }
const IntegrationOutput& GnssInsIntegration::output() const { return impl_->core->output; }
NominalState GnssInsIntegration::nominal() const { return impl_->core->nominal(); }
Eigen::MatrixXd GnssInsIntegration::covariance() const { return impl_->core->covariance(); }
const IntegrationCounters& GnssInsIntegration::counters() const { return impl_->core->counters; }
const std::vector<RecoveryEvent>& GnssInsIntegration::recovery_events() const { return impl_->core->recovery_events; }
std::vector<UpdateRecord> GnssInsIntegration::take_update_records() {
  std::vector<UpdateRecord> out;
  out.swap(impl_->core->records);
  return out;
}
const IntegrationOptions& GnssInsIntegration::options() const { return impl_->options; }

}  // namespace ultratrack::fusion
