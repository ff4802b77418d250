// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/scenario_models.hpp"

#include <fmt/core.h>

#include <GeographicLib/Geocentric.hpp>
#include <numbers>
#include <stdexcept>

#include "io/input_error.hpp"
#include "io/units.hpp"
#include "io/why_invalid.hpp"
#include "signals/gps_constants.hpp"
#include "sim/ins_truth_motion.hpp"
#include "sim/local_frame.hpp"

namespace ultratrack::sim {
namespace {

using io::InputError;

}  // namespace

ins::TrajectorySpec trajectory_spec(const Scenario& s) {
  if (!s.trajectory_enabled()) throw InputError(s.source.string(), "the scenario has no [trajectory]");
  const double lat = s.llh_deg_m[0] * io::kRadPerDeg, lon = s.llh_deg_m[1] * io::kRadPerDeg, h = s.llh_deg_m[2];
  ins::TrajectorySpec spec;
  if (!s.trajectory_profile.empty()) {
    try {
      spec = ins::profile_spec(s.trajectory_profile, s.trajectory_duration_s, lat, lon, h);
    } catch (const InputError& e) {
      throw InputError(s.source.string(), std::string("[trajectory]: ") + e.what());
    }
    if (s.trajectory_profile == "static") {
      spec.roll0_rad = s.attitude_deg[0] * io::kRadPerDeg;
      spec.pitch0_rad = s.attitude_deg[1] * io::kRadPerDeg;
      spec.heading0_rad = s.attitude_deg[2] * io::kRadPerDeg;
    }
  } else {
    ins::TrajectorySpec start;
    start.lat0_rad = lat;
    start.lon0_rad = lon;
    start.height0_m = h;
    start.speed0_mps = s.start_speed_mps;
    start.heading0_rad = s.start_heading_deg * io::kRadPerDeg;
    start.coordinated_turns = s.coordinated_turns;
    start.ramp_s = s.ramp_s;
    const auto file = resolve_path(s, s.trajectory_file);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      throw InputError(s.source.string(), "key trajectory.file: no such segment file " + file.string());
    spec = ins::read_segments_csv(file, start);  // errors in the file name it and the line
  }
  spec.vibrations = s.vibrations;
  return spec;
}

ins::ImuErrorSpec imu_error_spec(const Scenario& s) {
  ins::ImuErrorSpec e;
  try {
    e = ins::imu_preset(s.imu_preset);
  } catch (const InputError& err) {
    throw InputError(s.source.string(), std::string("[imu]: ") + err.what());
  }
  return ins::apply_datasheet(e, s.imu_datasheet);
}

std::shared_ptr<const signals::ReceiverMotion> make_motion(const Scenario& s,
                                                           std::shared_ptr<const ins::TruthInterpolator> truth) {
  if (s.trajectory_enabled()) {
    if (!truth) throw std::invalid_argument("make_motion: an inertial scenario needs its truth");
    std::vector<Eigen::Vector3d> levers;
    for (const auto& l : s.lever_arms_body_m) levers.emplace_back(l[0], l[1], l[2]);
    return std::make_shared<InsTruthMotion>(std::move(truth), std::move(levers));
  }
  if (!s.trajectory.empty()) {
    const auto path = resolve_path(s, s.trajectory);
    auto samples = signals::read_trajectory_csv(path);
    if (samples.front().t_s > 1e-9 || samples.back().t_s < s.duration_s - 1e-9) {
      throw InputError(path.string(),
                       fmt::format("the trajectory covers t = {} .. {} s but the scenario needs 0 .. {} s",
                                   samples.front().t_s, samples.back().t_s, s.duration_s));
    }
    return std::make_shared<signals::TrajectoryMotion>(std::move(samples));
  }
  Eigen::Vector3d r0;
  GeographicLib::Geocentric::WGS84().Forward(s.llh_deg_m[0], s.llh_deg_m[1], s.llh_deg_m[2], r0.x(), r0.y(), r0.z());
  const Eigen::Matrix3d C_ned_e = ned_from_ecef(s.llh_deg_m[0] * io::kRadPerDeg, s.llh_deg_m[1] * io::kRadPerDeg);
  std::vector<Eigen::Vector3d> antennas;
  for (const auto& o : s.antenna_offsets_enu_m) {
    const Eigen::Vector3d d_ned(o[1], o[0], -o[2]);
    antennas.push_back(r0 + C_ned_e.transpose() * d_ned);
  }
  return std::make_shared<signals::StaticMotion>(std::move(antennas));
}

signals::SynthesiserOptions synthesiser_options(const Scenario& s, const NavigationSource& nav) {
  signals::SynthesiserOptions o;
  o.sample_rate_hz = s.sample_rate_hz;
  o.if_hz = s.if_hz;
  o.real_output = !signals::is_complex(s.format);
  // Automatic gain: noise plus signals at RMS = full scale / 4 per component (clipping beyond 4 sigma); the
  // 2-bit formats rescale to the noise alone in simulate() (quantiser threshold at 1 noise sigma).
  o.output_rms = signals::nominal_rms(s.format);
  o.start = {s.gps_week, s.tow_s};
  o.default_cn0_dbhz = s.cn0_dbhz;
  o.cn0_dbhz_by_prn = s.cn0_dbhz_by_prn;
  o.elevation_mask_rad = s.elevation_mask_deg * io::kRadPerDeg;
  o.include_unhealthy = s.include_unhealthy;
  o.ionosphere = s.ionosphere;
  o.troposphere = s.troposphere;
  o.klobuchar = nav.klobuchar;
  o.utc = nav.utc;
  o.nav_data = s.nav_data;
  o.noise = s.noise;
  o.clock.bias_s = s.clock_bias_m / signals::kSpeedOfLight_mps;
  o.clock.drift_sps = s.clock_drift_mps / signals::kSpeedOfLight_mps;
  o.clock.bias_noise_s_per_sqrt_s = s.clock_bias_noise_m_per_sqrt_s / signals::kSpeedOfLight_mps;
  o.clock.drift_noise_sps_per_sqrt_s = s.clock_drift_noise_mps_per_sqrt_s / signals::kSpeedOfLight_mps;
  o.seed = s.seed;
  o.parameter_update_s = s.parameter_update_s;
  o.lnav.field_rounding = s.nav_field_rounding;
  o.lnav.random_pages = s.nav_random_pages;
  o.lnav.page_seed = s.seed;
  o.antenna_impairments = s.antenna_impairments;
  o.cycle_slips = s.cycle_slips;
  o.blockages = s.blockages;
  o.cn0_steps = s.cn0_steps;
  if (const auto err = io::why_invalid(o); !err.empty()) throw InputError(s.source.string(), err);
  return o;
}

}  // namespace ultratrack::sim
