// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/fuse.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include "fusion/fuse_motion_alignment.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"

namespace ultratrack::pipelines {
namespace {

// GNSS position/velocity linearly interpolated at t (clamped to the fixes' span).
struct GnssState {
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  bool has_velocity = false;
  Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_ned_m = Eigen::Vector3d::Ones();
};

GnssState gnss_at(const std::vector<GnssFixRow>& g, double t) {
  auto from = [](const GnssFixRow& r) {
    return GnssState{r.lat_rad, r.lon_rad, r.height_m, r.has_velocity, r.v_n, r.sigma_ned_m};
  };
  if (t <= g.front().t_s) return from(g.front());
  if (t >= g.back().t_s) return from(g.back());
  const auto it = std::upper_bound(g.begin(), g.end(), t, [](double x, const GnssFixRow& r) { return x < r.t_s; });
  const GnssFixRow &b = *it, &a = *(it - 1);
  const double w = (t - a.t_s) / (b.t_s - a.t_s);
  GnssState s;
  s.lat_rad = a.lat_rad + w * (b.lat_rad - a.lat_rad);
  s.lon_rad = a.lon_rad + w * (b.lon_rad - a.lon_rad);
  s.height_m = a.height_m + w * (b.height_m - a.height_m);
  s.has_velocity = a.has_velocity && b.has_velocity;
  s.v_n = a.v_n + w * (b.v_n - a.v_n);
  s.sigma_ned_m = a.sigma_ned_m.cwiseMax(b.sigma_ned_m);
  return s;
}

// NED offset (m) of geodetic point b from a, small distances.
Eigen::Vector3d ned_difference(double lat_a, double lon_a, double h_a, double lat_b, double lon_b, double h_b) {
  const Eigen::Vector3d d_e = ins::ecef_from_geodetic(lat_b, lon_b, h_b) - ins::ecef_from_geodetic(lat_a, lon_a, h_a);
  return ins::C_en(lat_a, lon_a).transpose() * d_e;
}

// GNSS velocities for the motion alignment: the fixes' own (1-sigma velocity_sigma_mps), else central differences
// of positions over at least span_s (at 1.5 m noise and 5 s: ~0.4 m/s per axis; neighbours alone would give metres
// per second at 5 Hz and fake motion while parked), 1-sigma from the two fixes' horizontal sigmas. A central
// difference over a steady turn points along the track at its middle, so long spans suit slow platforms.
constexpr double kPositionDifferenceSpan_s = 5.0;
constexpr double kPositionDifferenceSpans_s[] = {5.0, 10.0, 20.0, 40.0};  // tried in turn (heading sigma goal)

std::vector<fusion::GnssVelocitySample> gnss_velocities(const std::vector<GnssFixRow>& g, double span_s,
                                                        double velocity_sigma_mps) {
  std::vector<fusion::GnssVelocitySample> out;
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    fusion::GnssVelocitySample s{g[i].t_s, g[i].lat_rad, g[i].height_m, g[i].v_n, velocity_sigma_mps};
    if (!g[i].has_velocity) {
      const double half = 0.5 * span_s;
      while (lo < i && g[lo + 1].t_s <= g[i].t_s - half) ++lo;
      if (g[lo].t_s > g[i].t_s - half + 1e-9) continue;  // not enough history yet
      hi = std::max(hi, i);
      while (hi < g.size() && g[hi].t_s < g[i].t_s + half - 1e-9) ++hi;
      if (hi == g.size()) continue;
      const auto& a = g[lo];
      const auto& b = g[hi];
      s.v_n = ned_difference(a.lat_rad, a.lon_rad, a.height_m, b.lat_rad, b.lon_rad, b.height_m) / (b.t_s - a.t_s);
      const double sa = a.sigma_ned_m.head<2>().maxCoeff(), sb = b.sigma_ned_m.head<2>().maxCoeff();
      s.sigma_horizontal_mps = std::hypot(sa, sb) / (b.t_s - a.t_s);
    }
    out.push_back(s);
  }
  return out;
}

// A fix row as the loose filter takes it: its velocity only when the configuration uses velocities, at
// velocity_sigma_mps (the fix file carries position sigmas only).
// position_sigma_scale: the file's position sigmas times this (fixes noisier than they state).
fusion::GnssFix loose_fix(const GnssFixRow& r, const FuseConfig& c, double velocity_sigma_mps,
                          const Eigen::Vector3d& position_sigma_scale) {
  fusion::GnssFix f;
  f.t_s = r.t_s;
  f.lat_rad = r.lat_rad;
  f.lon_rad = r.lon_rad;
  f.height_m = r.height_m;
  f.sigma_pos_ned_m = r.sigma_ned_m.cwiseProduct(position_sigma_scale);
  f.has_velocity = r.has_velocity && c.use_velocity;
  f.v_n_mps = r.v_n;
  f.sigma_vel_n_mps = Eigen::Vector3d::Constant(velocity_sigma_mps);
  return f;
}

bool in_outage(const FuseSettings& s, double t) {
  for (const auto& [start, duration] : s.outages)
    if (t >= start && t < start + duration) return true;
  return false;
}

struct RowError {
  double t_s;
  Eigen::Vector3d pos_ned_m, sigma_pos_m;
  double vel_mps;
  Eigen::Vector3d att_rad;
  double distance_m = 0.0;  // truth path length from the first row
};

// The odometer's part of the result against truth: from the last GNSS use to the end.
void odometer_errors(const std::vector<RowError>& errors, OdometerUse& u) {
  const RowError* first = nullptr;
  double h_max = 0.0, v_max = 0.0;
  for (const auto& e : errors) {
    if (e.t_s < u.gnss_last_used_s - 1e-9) continue;
    if (!first) first = &e;
    h_max = std::max(h_max, e.pos_ned_m.head<2>().norm());
    v_max = std::max(v_max, std::abs(e.pos_ned_m.z()));
  }
  if (!first || errors.back().distance_m - first->distance_m <= 0.0) return;
  u.distance_travelled_m = errors.back().distance_m - first->distance_m;
  u.horizontal_error_max_m = h_max;
  u.horizontal_error_end_m = errors.back().pos_ned_m.head<2>().norm();
  u.altitude_error_max_m = v_max;
}

ErrorRms rms_of(const std::vector<RowError>& e, double from_t) {
  ErrorRms r;
  double h2 = 0, v2 = 0, vel2 = 0, att2 = 0, hd2 = 0;
  int inside = 0;
  for (const auto& x : e) {
    if (x.t_s < from_t) continue;
    ++r.rows;
    h2 += x.pos_ned_m.head<2>().squaredNorm();
    v2 += x.pos_ned_m.z() * x.pos_ned_m.z();
    vel2 += x.vel_mps * x.vel_mps;
    att2 += x.att_rad.squaredNorm();
    hd2 += x.att_rad.z() * x.att_rad.z();
    if ((x.pos_ned_m.cwiseAbs().array() <= 3.0 * x.sigma_pos_m.array()).all()) ++inside;
  }
  if (r.rows == 0) return r;
  const double n = r.rows;
  r.horizontal_m = std::sqrt(h2 / n);
  r.vertical_m = std::sqrt(v2 / n);
  r.position_3d_m = std::sqrt((h2 + v2) / n);
  r.velocity_mps = std::sqrt(vel2 / n);
  r.attitude_deg = std::sqrt(att2 / n) / io::kRadPerDeg;
  r.heading_deg = std::sqrt(hd2 / n) / io::kRadPerDeg;
  r.within_3sigma = inside / n;
  return r;
}

fusion::AttitudeAidingOptions attitude_aiding_options(const FuseConfig& c) {
  fusion::AttitudeAidingOptions o;
  const Eigen::Vector3d m = c.attitude_misalignment_deg * io::kRadPerDeg;
  o.q_ba = ins::quaternion_from_euler({m.x(), m.y(), m.z()});
  o.max_abs_pitch_rad = c.attitude_max_pitch_deg * io::kRadPerDeg;
  return o;
}

// A fixed attitude row on the IMU time line.
struct TimedAttitude {
  double t_s = 0.0;
  int line = 0;
  fusion::GnssAttitude attitude;
};

// The fixed rows of the attitude file on the IMU time line (unfixed rows are the fallback: left out here).
std::vector<TimedAttitude> timed_attitudes(const FuseSettings& s, double imu_start, double imu_end) {
  std::vector<TimedAttitude> out;
  if (s.attitude.empty()) return out;
  const auto& origin = s.config.attitude_gps_time_at_imu_zero;
  if (!origin)
    throw io::InputError("configuration",
                         "GPS attitude needs the GPS time of IMU t = 0: [attitude] "
                         "gps_time_at_imu_zero = [week, tow_s] or --attitude-origin WEEK TOW");
  for (const auto& r : s.attitude) {
    if (!r.fixed) continue;
    TimedAttitude t;
    t.t_s = signals::seconds_between(r.time, *origin);
    t.line = r.line;
    t.attitude.t_s = t.t_s;
    t.attitude.euler_a = r.euler;
    t.attitude.sigma_euler_rad = Eigen::Vector3d(r.sigma_roll_rad, r.sigma_pitch_rad, r.sigma_yaw_rad);
    out.push_back(t);
  }
  if (!out.empty() && (out.back().t_s <= imu_start || out.front().t_s >= imu_end))
    throw io::InputError(s.attitude_file, fmt::format("fixed attitudes ({:.3f}-{:.3f} s on the IMU time line) do not "
                                                      "overlap the IMU data ({:.3f}-{:.3f} s): check "
                                                      "gps_time_at_imu_zero",
                                                      out.front().t_s, out.back().t_s, imu_start, imu_end));
  return out;
}

}  // namespace

FuseResult fuse(const std::vector<ins::ImuIncrement>& imu, const std::vector<GnssFixRow>& gnss,
                const std::vector<ins::TruthSample>& truth, const FuseSettings& s,
                const std::function<void(const ins::NavState&, const NavSigma&)>& on_row,
                const std::function<void(double)>& on_progress, std::stop_token stop) {
  const FuseConfig& c = s.config;
  if (imu.size() < 2) throw io::InputError("IMU file", "fewer than 2 IMU rows");
  const bool odometer_only = gnss.empty() && !s.odometer.empty();
  if (gnss.empty() && !odometer_only) throw io::InputError("GNSS file", "no fixes");
  if (odometer_only && (s.align != AlignMode::Config || !c.position_deg_m))
    throw io::InputError("command line",
                         "without --gnss the start is the configuration's: --align config with "
                         "[initial] attitude_deg, position_deg_m (and velocity_ned_mps)");
  const double imu_start = imu[0].t_s - (imu[1].t_s - imu[0].t_s);  // the first row's interval start
  if (!odometer_only && (gnss.back().t_s <= imu_start || gnss.front().t_s >= imu.back().t_s))
    throw io::InputError("GNSS file",
                         fmt::format("fixes ({:.3f}-{:.3f} s) do not overlap the IMU data ({:.3f}-{:.3f} s)",
                                     gnss.front().t_s, gnss.back().t_s, imu_start, imu.back().t_s));
  const ins::ImuErrorSpec preset = imu_error_spec(c);
  const fusion::AttitudeAidingOptions attitude_options = attitude_aiding_options(c);
  const std::vector<TimedAttitude> attitude = timed_attitudes(s, imu_start, imu.back().t_s);

  // --- initial state (pipelines/navigation_initialisation.hpp) ---
  FuseResult result;
  AttitudeStart start;
  const double lat_hint = c.position_deg_m ? c.position_deg_m->x() * io::kRadPerDeg : gnss.front().lat_rad;
  std::optional<NavigationStart> config_start;  // odometer only: everything from the configuration
  if (s.align == AlignMode::Static) {
    const std::size_t end = static_span_end(imu, imu_start, c, "IMU file");
    start = align_static(std::span(imu).first(end), imu_start, lat_hint, preset);
    if (start.heading_sigma_rad > 10.0 * io::kRadPerDeg)
      start.note +=
          fmt::format(" (heading 1-sigma {:.0f} deg: too short or too noisy to gyrocompass: --align motion is better)",
                      start.heading_sigma_rad / io::kRadPerDeg);
  } else if (s.align == AlignMode::Motion) {
    // Gyro biases from a standstill before the motion, when better than the datasheet's turn-on sigma.
    const auto standstill = motion_standstill(imu, lat_hint, c, preset, imu.back().t_s);
    // Position-only fixes: smoothed velocities over a span that grows until the heading's sigma meets the goal, a
    // window at least that long and a looser tilt.
    const bool position_only =
        std::none_of(gnss.begin(), gnss.end(), [](const GnssFixRow& r) { return r.has_velocity; });
    std::optional<AttitudeStart> a;
    for (const double span : kPositionDifferenceSpans_s) {
      std::vector<fusion::GnssVelocitySample> velocities = gnss_velocities(gnss, span, c.velocity_sigma_mps);
      if (s.gnss_until_s)  // the alignment too uses GNSS only until then
        std::erase_if(velocities, [&](const fusion::GnssVelocitySample& v) { return v.t_s > *s.gnss_until_s; });
      const double window = position_only ? std::max(c.motion_window_s, span) : c.motion_window_s;
      if (auto candidate = align_moving(imu, velocities, c, window, position_only, standstill)) {
        a = std::move(candidate);
        result.motion_span_s = position_only ? span : 0.0;
        if (a->sigma_att_rad.z() <= c.motion_heading_sigma_deg * io::kRadPerDeg) break;
      }
      if (!position_only) break;
    }
    if (!a) {
      double fastest = 0.0;
      for (const auto& v : gnss_velocities(gnss, kPositionDifferenceSpan_s, c.velocity_sigma_mps))
        fastest = std::max(fastest, v.v_n.head<2>().norm());
      throw AlignmentUnavailable(fmt::format(
          "no in-motion alignment: the fixes never show {} m/s for {} s within the IMU data (fastest {:.2f} m/s); "
          "for a slower platform lower [alignment] motion_min_speed_mps (the heading then comes from a shorter, "
          "noisier track), or align with --align static, config or attitude",
          c.motion_min_speed_mps,
          position_only ? std::max(c.motion_window_s, kPositionDifferenceSpan_s) : c.motion_window_s, fastest));
    }
    start = *a;
    result.standstill = start.standstill;
    if (result.motion_span_s > 0.0)
      start.note += fmt::format(", heading from a {:.0f} s track ({:.1f} deg 1-sigma)", result.motion_span_s,
                                start.sigma_att_rad.z() / io::kRadPerDeg);
  } else if (s.align == AlignMode::Attitude) {
    if (attitude.empty()) throw io::InputError("command line", "--align attitude needs --attitude FILE");
    const double from = std::max(imu_start, gnss.front().t_s);
    const auto it = std::find_if(attitude.begin(), attitude.end(), [&](const TimedAttitude& a) {
      return a.t_s >= from && a.t_s < imu.back().t_s && fusion::attitude_usable(a.attitude, attitude_options);
    });
    if (it == attitude.end())
      throw AlignmentUnavailable(s.attitude_file + ": " +
                                 fmt::format("--align attitude: no fixed attitude within the IMU and GNSS "
                                             "data ({:.3f}-{:.3f} s)",
                                             from, imu.back().t_s));
    start.t_s = it->t_s;
    start.q_nb = fusion::measured_q_nb(it->attitude, attitude_options.q_ba);
    // One GPS attitude's accuracy: its Euler sigmas as NED rotation sigmas (fusion/attitude_measurement.hpp).
    const Eigen::Matrix3d M = fusion::euler_rate_to_rotation_n(it->attitude.euler_a);
    const Eigen::Matrix3d R = M * it->attitude.sigma_euler_rad.cwiseAbs2().asDiagonal() * M.transpose();
    start.sigma_att_rad = R.diagonal().cwiseSqrt().cwiseMax(0.01 * io::kRadPerDeg);
    start.sigma_vel_n_mps = Eigen::Vector3d::Constant(1.0);
    start.note = fmt::format("GPS attitude at {:.3f} s (line {})", it->t_s, it->line);
  } else {
    if (!c.attitude_deg) throw io::InputError("configuration", "--align config needs [initial] attitude_deg");
    if (odometer_only) {
      start = align_from_config(imu_start, c);
      if (c.velocity_ned_mps) start.v_n = *c.velocity_ned_mps;
      config_start = initialise_navigation(start, nullptr, c, Eigen::Vector3d::Ones());
    } else {
      auto it = std::find_if(gnss.begin(), gnss.end(), [&](const GnssFixRow& r) { return r.t_s >= imu_start; });
      start = align_from_config(it->t_s, c);
    }
  }
  result.alignment_note = start.note;
  const NavigationStart n = config_start ? *config_start : [&] {
    const GnssState g0 = gnss_at(gnss, start.t_s);
    if ((s.align == AlignMode::Config || s.align == AlignMode::Attitude) && g0.has_velocity) start.v_n = g0.v_n;
    if (s.align == AlignMode::Config && c.velocity_ned_mps) start.v_n = *c.velocity_ned_mps;
    const GnssPosition position{g0.lat_rad, g0.lon_rad, g0.height_m, g0.sigma_ned_m};
    return initialise_navigation(start, &position, c, g0.sigma_ned_m);
  }();
  const ins::NavState& init = n.nav;
  result.initial_attitude = ins::euler_from_quaternion(init.q_nb);
  result.start_s = init.t_s;

  fusion::IntegrationOptions o = integration_options(n, c, fusion::Coupling::kLoose, s.filter);
  o.attitude = attitude_options;
  // How each fix is weighted: as stated and told, unless the fixes' own errors say otherwise.
  result.velocity_sigma_mps = c.velocity_sigma_mps;
  Eigen::Vector3d position_sigma_scale = Eigen::Vector3d::Ones();
  if (c.fix_error_auto && !gnss.empty()) {  // the fixes' own errors: white at their rate, or correlated
    std::vector<fusion::GnssFix> usable;
    for (const GnssFixRow& r : gnss) {
      if (in_outage(s, r.t_s) || (s.gnss_until_s && r.t_s > *s.gnss_until_s)) continue;
      usable.push_back(loose_fix(r, c, c.velocity_sigma_mps, position_sigma_scale));
    }
    const fusion::FixErrorWhiteness& w = result.fix_whiteness.emplace(fusion::measure_fix_error_whiteness(usable));
    position_sigma_scale = w.sigma_scale;
    if (w.correlated) {
      o.fix_error.enabled = true;
      o.fix_error.correlation_time_s = w.correlation_time_s;
      o.fix_error.sigma_ned_m = c.fix_error_sigma_ned_m ? *c.fix_error_sigma_ned_m : w.sigma_ned_m;
      o.fix_error_correlation_s = 0.0;
    }
    if (c.use_velocity) {  // and the velocities against the told sigma: a receiver may smooth them
      const fusion::VelocityWhiteness& v =
          result.velocity_whiteness.emplace(fusion::measure_velocity_whiteness(usable, c.velocity_sigma_mps));
      result.velocity_sigma_mps = c.velocity_sigma_mps * std::sqrt(v.variance_factor);
    }
  }
  result.fix_error = o.fix_error;
  result.fix_error_inflation_s = o.fix_error_correlation_s;
  std::vector<fusion::OdometerSpeed> odometer;
  if (!s.odometer.empty()) {
    o.odometer = c.odometer;
    o.odometer.enabled = true;
    if (std::string why; !o.odometer.IsValid(&why)) throw io::InputError("configuration", why);
    odometer = odometer_windows(s.odometer, 1.0 / c.odometer.update_rate_hz);
    result.odometer.emplace().gnss_last_used_s = init.t_s;
  }
  fusion::GnssInsIntegration integration(init, o);
  std::size_t od = 0;
  while (od < odometer.size() && odometer[od].t_s <= init.t_s) ++od;

  // --- run ---
  std::optional<ins::TruthInterpolator> truth_at;
  if (truth.size() >= 2) truth_at.emplace(truth);
  std::vector<RowError> errors;
  std::optional<double> converged_since;
  std::size_t g = 0;
  while (g < gnss.size() && gnss[g].t_s <= init.t_s) {
    ++result.fixes_before_start;
    ++g;
  }
  AttitudeUse& au = result.attitude;
  au.rows = static_cast<long long>(s.attitude.size());
  for (const auto& r : s.attitude) {
    if (r.fixed)
      ++au.fixed_rows;
    else
      ++au.unfixed_skipped;
  }
  std::size_t a = 0;
  while (a < attitude.size() && attitude[a].t_s <= init.t_s) {
    ++au.before_start;
    ++a;
  }
  std::size_t k = 0;
  while (k < imu.size() && imu[k].t_s <= init.t_s) ++k;
  const std::size_t k_first = k;
  const double progress_step = std::max<std::size_t>(1, (imu.size() - k_first) / 10);
  std::optional<Eigen::Vector3d> last_truth_r_e;
  double truth_distance_m = 0.0;
  auto emit = [&](const fusion::IntegrationOutput& out) {
    NavSigma sig{out.sigma_pos_ned_m, out.sigma_vel_n_mps, out.sigma_att_rad};
    if (on_row) on_row(out.nav, sig);
    if (sig.attitude_ned_rad.z() > c.convergence_heading_sigma_deg * io::kRadPerDeg)
      converged_since.reset();
    else if (!converged_since)
      converged_since = out.nav.t_s;
    if (truth_at && out.nav.t_s >= truth_at->start_s() - 1e-9 && out.nav.t_s <= truth_at->end_s() + 1e-9) {
      const double t = out.nav.t_s;
      const ins::EcefMotion m = truth_at->antenna(t, Eigen::Vector3d::Zero());
      const Eigen::Vector3d r_nav = ins::ecef_from_geodetic(out.nav.lat_rad, out.nav.lon_rad, out.nav.height_m);
      const Eigen::Matrix3d C_ne = ins::C_en(out.nav.lat_rad, out.nav.lon_rad).transpose();
      if (last_truth_r_e) truth_distance_m += (m.r_e - *last_truth_r_e).norm();
      last_truth_r_e = m.r_e;
      errors.push_back({t, C_ne * (r_nav - m.r_e), sig.position_ned_m, (out.nav.v_n - C_ne * m.v_e).norm(),
                        ins::attitude_error_n(out.nav.q_nb, truth_at->attitude(t)), truth_distance_m});
    }
    result.final_sigma = sig;
    result.final_nav = out.nav;
    result.accel_bias_b = out.accel_bias_b;
    result.gyro_bias_b = out.gyro_bias_b;
    result.sigma_accel_bias_b = out.sigma_accel_bias_b;
    result.sigma_gyro_bias_b = out.sigma_gyro_bias_b;
    if (result.odometer) result.odometer->estimate = out.odometer;
  };
  emit(integration.output());
  for (; k < imu.size(); ++k) {
    if (stop.stop_requested()) {
      result.interrupted = true;
      break;
    }
    while (g < gnss.size() && gnss[g].t_s <= imu[k].t_s) {
      const GnssFixRow& r = gnss[g++];
      if (in_outage(s, r.t_s)) {
        ++result.fixes_in_outage;
        continue;
      }
      if (s.gnss_until_s && r.t_s > *s.gnss_until_s) {
        ++result.fixes_after_gnss_until;
        continue;
      }
      if (result.odometer) result.odometer->gnss_last_used_s = r.t_s;
      integration.add_fix(loose_fix(r, c, result.velocity_sigma_mps, position_sigma_scale));
      ++result.fixes_used;
    }
    for (; a < attitude.size() && attitude[a].t_s <= imu[k].t_s; ++a) {
      if (in_outage(s, attitude[a].t_s)) {
        ++au.in_outage;
        continue;
      }
      integration.add_attitude(attitude[a].attitude);
      ++au.used;
    }
    for (; od < odometer.size() && odometer[od].t_s <= imu[k].t_s; ++od) {
      integration.add_odometer(odometer[od]);
      ++result.odometer->windows;
    }
    ins::ImuIncrement inc = imu[k];
    const double t_prev = k > 0 ? imu[k - 1].t_s : imu_start;
    if (k == k_first && t_prev < init.t_s) {  // the first interval straddles the start: keep its share
      const double share = (inc.t_s - init.t_s) / (inc.t_s - t_prev);
      inc.dtheta_b *= share;
      inc.dv_b *= share;
    }
    integration.add_imu(inc);
    emit(integration.output());
    if (on_progress && (k - k_first + 1) % static_cast<std::size_t>(progress_step) == 0)
      on_progress(double(k - k_first + 1) / double(imu.size() - k_first));
  }
  au.after_end = static_cast<long long>(attitude.size() - a);
  result.end_s = integration.output().nav.t_s;
  result.counters = integration.counters();
  result.recovery_events = integration.recovery_events();
  result.converged_at_s = converged_since;

  if (truth_at) {
    result.rms_all = rms_of(errors, -1e300);
    if (result.odometer && !errors.empty()) odometer_errors(errors, *result.odometer);
    if (result.converged_at_s) result.rms_converged = rms_of(errors, *result.converged_at_s);
    for (const auto& [start, duration] : s.outages) {
      OutageResult oo{start, start + duration};
      const RowError* last = nullptr;
      for (const auto& e : errors)
        if (e.t_s <= start + duration + 1e-9) last = &e;
      if (last) {
        oo.horizontal_error_m = last->pos_ned_m.head<2>().norm();
        oo.sigma_horizontal_m = last->sigma_pos_m.head<2>().norm();
      }
      result.outages.push_back(oo);
    }
    // The fixes themselves (antenna positions) against the truth antenna.
    std::vector<RowError> ge;
    for (const auto& r : gnss) {
      if (r.t_s < truth_at->start_s() || r.t_s > truth_at->end_s()) continue;
      const ins::EcefMotion m = truth_at->antenna(r.t_s, c.lever_arm_b);
      const Eigen::Vector3d r_fix = ins::ecef_from_geodetic(r.lat_rad, r.lon_rad, r.height_m);
      ge.push_back({r.t_s, ins::C_en(r.lat_rad, r.lon_rad).transpose() * (r_fix - m.r_e), r.sigma_ned_m, 0.0,
                    Eigen::Vector3d::Zero()});
    }
    if (!ge.empty()) result.gnss_rms = rms_of(ge, -1e300);
  }
  return result;
}

std::vector<fusion::OdometerSpeed> odometer_windows(const std::vector<ins::OdometerSample>& rows, double window_s) {
  std::vector<fusion::OdometerSpeed> out;
  if (rows.size() < 2) return out;
  double start = rows[0].t_s - (rows[1].t_s - rows[0].t_s), distance = 0.0;
  const double period = rows[1].t_s - rows[0].t_s;
  for (const auto& r : rows) {
    distance += r.distance_m;
    const double span = r.t_s - start;
    if (span >= window_s - 0.5 * period) {
      out.push_back({r.t_s, distance / span, span});
      start = r.t_s;
      distance = 0.0;
    }
  }
  return out;
}

}  // namespace ultratrack::pipelines
