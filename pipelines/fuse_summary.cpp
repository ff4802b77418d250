// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/fuse_summary.hpp"

#include <fmt/core.h>

#include <numbers>

#include "io/json_text.hpp"
#include "io/units.hpp"
#include "pipelines/imu_model_json.hpp"

namespace ultratrack::pipelines {

std::string odometer_json(const OdometerUse& u, const fusion::OdometerCounters& n,
                          const fusion::OdometerAidingOptions& o, const std::string& file) {
  const fusion::OdometerNominal &v = u.estimate.value, &sd = u.estimate.sigma;
  auto opt = [](const std::optional<double>& x) { return x ? fmt::format("{:.6g}", *x) : std::string("null"); };
  auto pct = [&](const std::optional<double>& e) -> std::optional<double> {
    if (!e || !u.distance_travelled_m) return std::nullopt;
    return 100.0 * *e / *u.distance_travelled_m;
  };
  std::string j = fmt::format(
      "{{\"file\": \"{}\", \"mode\": \"{}\", \"yaw_rate_threshold_dps\": {:.6g}, \"min_speed_mps\": {:.6g}, "
      "\"update_rate_hz\": {:.6g}, \"windows\": {}, \"updates_accepted\": {}, \"updates_rejected\": {}, "
      "\"gated_yaw_rate\": {}, \"gated_speed\": {}, \"unusable\": {}, ",
      io::json_escape(file), o.mode == fusion::OdometerMode::kGated ? "gated" : "always",
      o.yaw_rate_threshold_rad_s / io::kRadPerDeg, o.min_speed_mps, o.update_rate_hz, u.windows, n.accepted, n.rejected,
      n.gated_yaw_rate, n.gated_speed, n.unusable);
  j += fmt::format(
      "\"scale_factor\": {:.6g}, \"sigma_scale_factor\": {:.6g}, \"misalignment_pitch_deg\": {:.6g}, "
      "\"sigma_misalignment_pitch_deg\": {:.6g}, \"misalignment_yaw_deg\": {:.6g}, \"sigma_misalignment_yaw_deg\": "
      "{:.6g}, "
      "\"delay_s\": {:.6g}, \"sigma_delay_s\": {:.6g}, ",
      v.scale_factor, sd.scale_factor, v.pitch_rad / io::kRadPerDeg, sd.pitch_rad / io::kRadPerDeg,
      v.yaw_rad / io::kRadPerDeg, sd.yaw_rad / io::kRadPerDeg, v.delay_s, sd.delay_s);
  j += fmt::format(
      "\"gnss_last_used_s\": {:.3f}, \"distance_travelled_m\": {}, \"horizontal_error_max_m\": {}, "
      "\"horizontal_error_end_m\": {}, \"altitude_error_max_m\": {}, \"horizontal_error_max_pct_dt\": {}, "
      "\"horizontal_error_end_pct_dt\": {}, \"altitude_error_max_pct_dt\": {}}}",
      u.gnss_last_used_s, opt(u.distance_travelled_m), opt(u.horizontal_error_max_m), opt(u.horizontal_error_end_m),
      opt(u.altitude_error_max_m), opt(pct(u.horizontal_error_max_m)), opt(pct(u.horizontal_error_end_m)),
      opt(pct(u.altitude_error_max_m)));
  return j;
}

std::string recovery_events_json(const std::vector<fusion::RecoveryEvent>& events) {
  std::string j = "[";
  for (std::size_t i = 0; i < events.size(); ++i)
    j += fmt::format("{}{{\"t_s\": {:.3f}, \"reason\": \"{}\"}}", i ? ", " : "", events[i].t_s,
                     io::json_escape(events[i].reason));
  return j + "]";
}

std::string fuse_summary_json(const FuseResult& r, const FuseSettings& s, const std::string& imu_file,
                              const std::string& gnss_file, const std::string& truth_file) {
  auto rms_json = [](const ErrorRms& e) {
    return fmt::format(
        "{{\"rows\": {}, \"horizontal_m\": {:.6g}, \"vertical_m\": {:.6g}, \"position_3d_m\": {:.6g}, "
        "\"velocity_mps\": {:.6g}, \"attitude_deg\": {:.6g}, \"heading_deg\": {:.6g}, \"within_3sigma\": {:.4f}}}",
        e.rows, e.horizontal_m, e.vertical_m, e.position_3d_m, e.velocity_mps, e.attitude_deg, e.heading_deg,
        e.within_3sigma);
  };
  const char* align = to_string(s.align);
  std::string j = "{\n";
  j += fmt::format("  \"imu_file\": \"{}\",\n  \"gnss_file\": \"{}\",\n", io::json_escape(imu_file),
                   io::json_escape(gnss_file));
  if (!truth_file.empty()) j += fmt::format("  \"truth_file\": \"{}\",\n", io::json_escape(truth_file));
  if (r.interrupted) j += "  \"interrupted\": true,\n";  // the rows up to the stop; absent from a complete run
  j += fmt::format(
      "  \"coupling\": \"loose\",\n  \"filter\": \"{}\",\n  \"align\": \"{}\",\n  \"imu_preset\": \"{}\",\n",
      s.filter == fusion::FilterKind::Ekf ? "ekf" : "ukf", align, s.config.imu_preset);
  j += "  \"imu_model\": " + imu_model_json(s.config) + ",\n";
  j += fmt::format(
      "  \"alignment\": {{\"note\": \"{}\", \"t_s\": {}, \"roll_deg\": {:.6f}, \"pitch_deg\": {:.6f}, "
      "\"yaw_deg\": {:.6f}}},\n",
      io::json_escape(r.alignment_note), r.start_s, r.initial_attitude.roll_rad / io::kRadPerDeg,
      r.initial_attitude.pitch_rad / io::kRadPerDeg, r.initial_attitude.yaw_rad / io::kRadPerDeg);
  if (r.motion_span_s > 0.0) j += fmt::format("  \"alignment_track_span_s\": {},\n", r.motion_span_s);
  if (r.standstill) {
    constexpr double kDph = io::kRadPerSecPerDegPerHour;
    const ins::StandstillGyroBias& b = *r.standstill;
    j += fmt::format(
        "  \"standstill_gyro_bias\": {{\"t_start_s\": {}, \"t_end_s\": {}, \"gyro_dph\": [{:.6g}, {:.6g}, {:.6g}], "
        "\"sigma_gyro_dph\": [{:.6g}, {:.6g}, {:.6g}]}},\n",
        b.t_start_s, b.t_end_s, b.gyro_bias_rps.x() / kDph, b.gyro_bias_rps.y() / kDph, b.gyro_bias_rps.z() / kDph,
        b.sigma_rps.x() / kDph, b.sigma_rps.y() / kDph, b.sigma_rps.z() / kDph);
  }
  j += fmt::format("  \"start_s\": {},\n  \"end_s\": {},\n", r.start_s, r.end_s);
  j += fmt::format(
      "  \"imu_steps\": {},\n  \"fixes_used\": {},\n  \"fixes_before_start\": {},\n  \"fixes_in_outage\": {},\n",
      r.counters.imu_steps, r.fixes_used, r.fixes_before_start, r.fixes_in_outage);
  j += fmt::format("  \"updates_accepted\": {},\n  \"updates_rejected\": {},\n  \"fixes_late\": {},\n",
                   r.counters.accepted, r.counters.rejected, r.counters.late);
  j += fmt::format("  \"fix_updates_accepted\": {},\n  \"fix_updates_rejected\": {},\n", r.counters.fix_accepted,
                   r.counters.fix_rejected);
  j += fmt::format("  \"fixes_skipped_by_interval\": {},\n", r.counters.fixes_skipped);
  const bool measured = r.fix_whiteness && r.fix_whiteness->correlated;
  const char* source = measured ? "measured" : "configuration";
  if (r.fix_error.enabled) {
    const auto& sg = r.fix_error.sigma_ned_m;
    j += fmt::format(
        "  \"fix_error_model\": {{\"kind\": \"gauss_markov_states\", \"source\": \"{}\", \"correlation_time_s\": {}, "
        "\"sigma_ned_m\": [{}, {}, {}]}},\n",
        source, r.fix_error.correlation_time_s, sg.x(), sg.y(), sg.z());
  } else if (r.fix_error_inflation_s > 0.0) {
    j += fmt::format(
        "  \"fix_error_model\": {{\"kind\": \"inflated_variance\", \"source\": \"configuration\", "
        "\"correlation_time_s\": {}}},\n",
        r.fix_error_inflation_s);
  } else {
    // Measured white; taken as white for want of fixes to measure; or told so.
    const char* white_source = r.fix_whiteness ? (r.fix_whiteness->measured ? "measured" : "default") : "configuration";
    j += fmt::format("  \"fix_error_model\": {{\"kind\": \"white\", \"source\": \"{}\"}},\n", white_source);
  }
  if (r.fix_whiteness) {
    const fusion::FixErrorWhiteness& w = *r.fix_whiteness;
    j += fmt::format(
        "  \"fix_whiteness\": {{\"measured\": {}, \"correlated\": {}, \"interval_s\": {}, \"long_lag\": {}, "
        "\"differences\": {}, \"white_share_ned\": [{:.4f}, {:.4f}, {:.4f}], \"growth_ned\": [{:.3f}, {:.3f}, {:.3f}], "
        "\"correlation_time_is_bound\": {}, \"sigma_scale_ned\": [{:.4f}, {:.4f}, {:.4f}], \"note\": \"{}\"}},\n",
        w.measured, w.correlated, w.interval_s, w.long_lag, w.differences, w.white_share.x(), w.white_share.y(),
        w.white_share.z(), w.growth.x(), w.growth.y(), w.growth.z(), w.correlation_time_is_bound, w.sigma_scale.x(),
        w.sigma_scale.y(), w.sigma_scale.z(), io::json_escape(w.note));
  }
  if (r.velocity_whiteness) {
    const fusion::VelocityWhiteness& v = *r.velocity_whiteness;
    j += fmt::format(
        "  \"velocity_whiteness\": {{\"measured\": {}, \"correlated\": {}, \"interval_s\": {}, \"differences\": {}, "
        "\"white_share_ne\": [{:.4f}, {:.4f}], \"correlation_time_s\": {}, \"sigma_used_mps\": {}, \"note\": "
        "\"{}\"}},\n",
        v.measured, v.correlated, v.interval_s, v.differences, v.white_share.x(), v.white_share.y(),
        v.correlation_time_s, r.velocity_sigma_mps, io::json_escape(v.note));
  }
  if (s.gnss_until_s)
    j += fmt::format("  \"gnss_until_s\": {},\n  \"fixes_after_gnss_until\": {},\n", *s.gnss_until_s,
                     r.fixes_after_gnss_until);
  if (r.odometer)
    j += "  \"odometer\": " + odometer_json(*r.odometer, r.counters.odometer, s.config.odometer, s.odometer_file) +
         ",\n";
  if (s.config.land.nhc)
    j += fmt::format("  \"nhc_updates_accepted\": {},\n  \"nhc_updates_rejected\": {},\n", r.counters.nhc_accepted,
                     r.counters.nhc_rejected);
  j += fmt::format("  \"lockout_recoveries\": {},\n  \"recovery_events\": {},\n", r.counters.recoveries,
                   recovery_events_json(r.recovery_events));
  if (!s.attitude.empty()) {
    const AttitudeUse& a = r.attitude;
    const auto& n = r.counters;
    const Eigen::Vector3d& m = s.config.attitude_misalignment_deg;
    j += fmt::format(
        "  \"attitude\": {{\"file\": \"{}\", \"rows\": {}, \"fixed_rows\": {}, \"unfixed_skipped\": {}, "
        "\"before_start\": {}, \"after_end\": {}, \"in_outage\": {}, \"used\": {}, \"updates\": {}, "
        "\"updates_accepted\": {}, \"updates_rejected\": {}, \"rejected_near_vertical\": {}, \"late\": {}, "
        "\"fallback_fixes\": {}, \"misalignment_deg\": [{}, {}, {}], \"max_pitch_deg\": {}}},\n",
        io::json_escape(s.attitude_file), a.rows, a.fixed_rows, a.unfixed_skipped, a.before_start, a.after_end,
        a.in_outage, a.used, n.attitude_epochs, n.attitude_accepted, n.attitude_rejected, n.attitude_unusable,
        n.attitude_late, n.fixes_without_attitude, m.x(), m.y(), m.z(), s.config.attitude_max_pitch_deg);
  }
  j += fmt::format("  \"converged\": {},\n  \"converged_at_s\": {},\n", r.converged_at_s.has_value(),
                   r.converged_at_s ? fmt::format("{}", *r.converged_at_s) : std::string("null"));
  j += fmt::format("  \"convergence_heading_sigma_deg\": {},\n", s.config.convergence_heading_sigma_deg);
  const NavSigma& g = r.final_sigma;
  j += fmt::format(
      "  \"final_sigma\": {{\"north_m\": {:.6g}, \"east_m\": {:.6g}, \"down_m\": {:.6g}, \"vel_mps\": {:.6g}, "
      "\"tilt_n_deg\": {:.6g}, \"tilt_e_deg\": {:.6g}, \"heading_deg\": {:.6g}}},\n",
      g.position_ned_m.x(), g.position_ned_m.y(), g.position_ned_m.z(), g.velocity_ned_mps.norm(),
      g.attitude_ned_rad.x() / io::kRadPerDeg, g.attitude_ned_rad.y() / io::kRadPerDeg,
      g.attitude_ned_rad.z() / io::kRadPerDeg);
  constexpr double kMg = 9.80665e-3, kDph = io::kRadPerSecPerDegPerHour;
  auto triple = [](const Eigen::Vector3d& v, double unit) {
    return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v.x() / unit, v.y() / unit, v.z() / unit);
  };
  j += fmt::format(
      "  \"bias_estimates\": {{\"accel_mg\": {}, \"sigma_accel_mg\": {}, \"gyro_dph\": {}, "
      "\"sigma_gyro_dph\": {}}},\n",
      triple(r.accel_bias_b, kMg), triple(r.sigma_accel_bias_b, kMg), triple(r.gyro_bias_b, kDph),
      triple(r.sigma_gyro_bias_b, kDph));
  if (r.rms_all) j += "  \"rms_all\": " + rms_json(*r.rms_all) + ",\n";
  if (r.rms_converged) j += "  \"rms_converged\": " + rms_json(*r.rms_converged) + ",\n";
  if (r.gnss_rms) j += "  \"gnss_only_rms\": " + rms_json(*r.gnss_rms) + ",\n";
  j += "  \"outages\": [";
  for (std::size_t i = 0; i < r.outages.size(); ++i)
    j += fmt::format(
        "{}{{\"start_s\": {}, \"end_s\": {}, \"horizontal_error_m\": {:.6g}, \"sigma_horizontal_m\": {:.6g}}}",
        i ? ", " : "", r.outages[i].start_s, r.outages[i].end_s, r.outages[i].horizontal_error_m,
        r.outages[i].sigma_horizontal_m);
  j += "]\n}\n";
  return j;
}

}  // namespace ultratrack::pipelines
