// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/navigation_initialisation.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fusion/ins_error_model.hpp"
#include "ins/attitude.hpp"
#include "ins/coarse_alignment.hpp"
#include "ins/earth_model.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kG = 9.80665;
// The heading from a track assumes no sideslip: a land vehicle's is of the order of a degree.
constexpr double kSideslipAllowance_rad = 1.0 * io::kRadPerDeg;

}  // namespace

const char* to_string(AlignMode mode) {
  switch (mode) {
    case AlignMode::Static:
      return "static";
    case AlignMode::Motion:
      return "motion";
    case AlignMode::Config:
      return "config";
    case AlignMode::Attitude:
      return "attitude";
  }
  return "?";
}

std::optional<AlignMode> align_mode_from_string(std::string_view name) {
  for (const AlignMode mode : {AlignMode::Static, AlignMode::Motion, AlignMode::Config, AlignMode::Attitude})
    if (name == to_string(mode)) return mode;
  return std::nullopt;
}

std::size_t static_span_end(std::span<const ins::ImuIncrement> imu, double t0_s, const FuseConfig& config,
                            const std::string& imu_name) {
  std::size_t end = 0;
  while (end < imu.size() && imu[end].t_s <= t0_s + config.static_duration_s + 1e-9) ++end;
  if (end < 2 || end == imu.size())
    throw io::InputError(
        imu_name, fmt::format("the static alignment span ({} s) needs IMU data beyond it", config.static_duration_s));
  return end;
}

AttitudeStart align_static(std::span<const ins::ImuIncrement> span, double t0_s, double lat_rad,
                           const ins::ImuErrorSpec& preset) {
  const ins::AlignmentResult a = ins::coarse_align(span, t0_s, lat_rad);
  AttitudeStart s;
  s.t_s = span.back().t_s;
  s.q_nb = a.q_nb;
  s.sigma_vel_n_mps = Eigen::Vector3d::Constant(0.1);
  const Eigen::Vector3d noise = ins::alignment_noise_sigma(preset, a.duration_s, lat_rad, kG);
  const double tilt = std::hypot(preset.accel.bias_sigma / kG, noise.x());
  s.heading_sigma_rad = std::hypot(preset.gyro.bias_sigma / (ins::kEarthRate_rps * std::cos(lat_rad)), noise.z());
  s.sigma_att_rad = {std::max(2.0 * tilt, 0.05 * io::kRadPerDeg), std::max(2.0 * tilt, 0.05 * io::kRadPerDeg),
                     std::clamp(2.0 * s.heading_sigma_rad, 0.5 * io::kRadPerDeg, 60.0 * io::kRadPerDeg)};
  s.note = fmt::format("static over {:.1f} s", a.duration_s);
  return s;
}

std::optional<AttitudeStart> align_moving(std::span<const ins::ImuIncrement> imu,
                                          std::span<const fusion::GnssVelocitySample> velocities,
                                          const FuseConfig& config, double window_s, bool position_only,
                                          const std::optional<ins::StandstillGyroBias>& standstill) {
  const Eigen::Vector3d gyro_bias_b = standstill ? standstill->gyro_bias_rps : Eigen::Vector3d::Zero();
  const auto a = fusion::align_in_motion(imu, velocities, {config.motion_min_speed_mps, window_s, gyro_bias_b});
  if (!a) return std::nullopt;
  AttitudeStart s;
  s.standstill = standstill;
  s.t_s = a->t_s;
  s.q_nb = a->q_nb;
  s.v_n = a->v_n;
  s.sigma_vel_n_mps = Eigen::Vector3d::Constant(position_only ? 1.0 : config.velocity_sigma_mps * 2.0);
  s.attitude_per_bias << a->psi_per_accel_bias, a->psi_per_gyro_bias;
  if (position_only) {
    const double heading =
        a->sigma_heading_rad > 0.0 ? std::max(a->sigma_heading_rad, kSideslipAllowance_rad) : 5.0 * io::kRadPerDeg;
    s.sigma_att_rad = Eigen::Vector3d(3.0 * io::kRadPerDeg, 3.0 * io::kRadPerDeg, heading);
  } else {  // white velocity noise at both ends of the window, independent of the biases
    const double v2 = config.velocity_sigma_mps * config.velocity_sigma_mps;
    const Eigen::Matrix3d P_e = v2 * (a->psi_per_velocity_start * a->psi_per_velocity_start.transpose() +
                                      a->psi_per_velocity_end * a->psi_per_velocity_end.transpose());
    s.sigma_att_rad = P_e.diagonal().cwiseSqrt();
    // A levelling that failed when perturbed (sensitivities zero; geometry at its limit): the former margins.
    if (!(s.sigma_att_rad.minCoeff() > 0.0)) s.sigma_att_rad = Eigen::Vector3d(1.0, 1.0, 3.0) * io::kRadPerDeg;
  }
  s.note = fmt::format("in motion at {:.3f} s ({:.1f} m/s)", a->t_s, a->v_n.head<2>().norm());
  if (standstill) {
    constexpr double kDph = io::kRadPerSecPerDegPerHour;
    const Eigen::Vector3d b = standstill->gyro_bias_rps / kDph;
    s.note += fmt::format(", gyro biases from a standstill over {:.1f}-{:.1f} s: {:.0f} {:.0f} {:.0f} +- {:.0f} deg/h",
                          standstill->t_start_s, standstill->t_end_s, b.x(), b.y(), b.z(),
                          standstill->sigma_rps.maxCoeff() / kDph);
  }
  return s;
}

std::optional<ins::StandstillGyroBias> motion_standstill(std::span<const ins::ImuIncrement> imu, double lat_rad,
                                                         const FuseConfig& config, const ins::ImuErrorSpec& preset,
                                                         double end_by_s) {
  if (!config.standstill_gyro_bias) return std::nullopt;
  auto s = ins::initial_standstill_gyro_bias(imu, lat_rad, preset, end_by_s);
  if (s && !(s->sigma_rps.array() < preset.gyro.bias_sigma).all()) s.reset();  // no better than the datasheet
  return s;
}

AttitudeStart align_from_config(double t_s, const FuseConfig& config) {
  AttitudeStart s;
  s.t_s = t_s;
  const Eigen::Vector3d& e = *config.attitude_deg;
  s.q_nb = ins::quaternion_from_euler({e.x() * io::kRadPerDeg, e.y() * io::kRadPerDeg, e.z() * io::kRadPerDeg});
  s.sigma_att_rad = Eigen::Vector3d(1.0, 1.0, 5.0) * io::kRadPerDeg;
  s.sigma_vel_n_mps = Eigen::Vector3d::Constant(1.0);
  s.note = "attitude from the configuration";
  return s;
}

NavigationStart initialise_navigation(const AttitudeStart& a, const GnssPosition* fix, const FuseConfig& c,
                                      const Eigen::Vector3d& sigma_configured_position_m) {
  NavigationStart s;
  s.nav.t_s = a.t_s;
  s.nav.q_nb = a.q_nb;
  s.nav.v_n = a.v_n;
  s.sigma_vel_n_mps = a.sigma_vel_n_mps;
  s.sigma_att_rad = a.sigma_att_rad;
  s.attitude_per_bias = a.attitude_per_bias;
  s.standstill = a.standstill;
  if (c.position_deg_m) {
    s.nav.lat_rad = c.position_deg_m->x() * io::kRadPerDeg;
    s.nav.lon_rad = c.position_deg_m->y() * io::kRadPerDeg;
    s.nav.height_m = c.position_deg_m->z();
    s.sigma_pos_ned_m = sigma_configured_position_m;
  } else {
    // the fix is the antenna's: move to the IMU by the lever arm
    const Eigen::Vector3d l_n = a.q_nb * c.lever_arm_b;
    const ins::Radii r = ins::radii_of_curvature(fix->lat_rad);
    s.nav.lat_rad = fix->lat_rad - l_n.x() / (r.meridian_m + fix->height_m);
    s.nav.lon_rad = fix->lon_rad - l_n.y() / ((r.transverse_m + fix->height_m) * std::cos(fix->lat_rad));
    s.nav.height_m = fix->height_m + l_n.z();
    s.sigma_pos_ned_m = fix->sigma_ned_m;
  }
  if (c.sigma_position_m) s.sigma_pos_ned_m = *c.sigma_position_m;
  if (c.sigma_velocity_mps) s.sigma_vel_n_mps = *c.sigma_velocity_mps;
  if (c.sigma_attitude_deg) {
    s.sigma_att_rad = *c.sigma_attitude_deg * io::kRadPerDeg;
    s.attitude_per_bias.setZero();
  }
  return s;
}

fusion::IntegrationOptions integration_options(const NavigationStart& start, const FuseConfig& c,
                                               fusion::Coupling coupling, fusion::FilterKind filter) {
  fusion::IntegrationOptions o;
  o.coupling = coupling;
  o.filter = filter;
  o.model = fusion::error_model_from_preset(imu_error_spec(c));
  o.lever_arm_b = c.lever_arm_b;
  o.sigma_pos_ned_m = start.sigma_pos_ned_m;
  o.sigma_vel_n_mps = start.sigma_vel_n_mps;
  o.sigma_att_rad = start.sigma_att_rad;
  o.attitude_per_bias = start.attitude_per_bias;
  if (c.initial_accel_bias_mps2) o.initial_accel_bias_b = *c.initial_accel_bias_mps2;
  if (c.initial_gyro_bias_rps) o.initial_gyro_bias_b = *c.initial_gyro_bias_rps;
  o.sigma_initial_accel_bias_b = c.sigma_accel_bias_mps2;
  o.sigma_initial_gyro_bias_b = c.sigma_gyro_bias_rps;
  if (start.standstill && !c.initial_gyro_bias_rps) {
    o.initial_gyro_bias_b = start.standstill->gyro_bias_rps;
    o.sigma_initial_gyro_bias_b = start.standstill->sigma_rps;
  }
  o.gate = c.gate;
  o.recovery = c.recovery;
  o.land = c.land;
  o.fix_min_interval_s = c.fix_min_interval_s;
  o.fix_error_correlation_s = c.fix_error_correlation_s;
  if (c.fix_error_sigma_ned_m && c.fix_error_correlation_s > 0.0 && coupling == fusion::Coupling::kLoose) {
    o.fix_error.enabled = true;  // the correlated part as states, instead of the inflated variance
    o.fix_error.correlation_time_s = c.fix_error_correlation_s;
    o.fix_error.sigma_ned_m = *c.fix_error_sigma_ned_m;
    o.fix_error_correlation_s = 0.0;
  }
  o.ukf = c.ukf;
  o.propagation_interval_s = c.propagation_interval_s;
  return o;
}

}  // namespace ultratrack::pipelines
