// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/gnss_ins_coupler.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include "fusion/clock_model.hpp"
#include "fusion/loose_measurements.hpp"
#include "fusion/tight_measurements.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/strapdown.hpp"
#include "io/input_error.hpp"
#include "io/json_text.hpp"
#include "io/units.hpp"
#include "pipelines/fuse_summary.hpp"
#include "pipelines/imu_model_json.hpp"
#include "pipelines/navigation_initialisation.hpp"
#include "receiver/loop_filters.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;
constexpr double kDllUpdate_s =
    0.020;  // the DLL's update interval after bit sync (the tight filter starts after frame sync)

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A PVT fix as a loose measurement at t_s: NED sigmas from the PVT's a-priori covariance (the off-diagonal
// terms are dropped: GnssFix carries per-axis sigmas).
fusion::GnssFix fix_measurement(const receiver::PvtSolution& f, double t_s) {
  fusion::GnssFix m;
  m.t_s = t_s;
  m.lat_rad = f.lat_rad;
  m.lon_rad = f.lon_rad;
  m.height_m = f.height_m;
  const Eigen::Matrix3d C_en = ins::C_en(f.lat_rad, f.lon_rad);
  const Eigen::Matrix3d P = C_en.transpose() * f.covariance_m2.topLeftCorner<3, 3>() * C_en;
  m.sigma_pos_ned_m = P.diagonal().cwiseMax(0.0).cwiseSqrt();
  m.has_position = (m.sigma_pos_ned_m.array() > 0.0).all() && m.sigma_pos_ned_m.allFinite();
  if (f.velocity_valid) {
    const Eigen::Matrix3d V = C_en.transpose() * f.velocity_covariance_m2ps2.topLeftCorner<3, 3>() * C_en;
    m.v_n_mps = C_en.transpose() * f.v_e_mps;
    m.sigma_vel_n_mps = V.diagonal().cwiseMax(0.0).cwiseSqrt();
    m.has_velocity = (m.sigma_vel_n_mps.array() > 0.0).all() && m.sigma_vel_n_mps.allFinite();
  }
  return m;
}

}  // namespace

struct GnssInsCoupler::Impl {
  ReceiveOptions settings;
  std::vector<ins::ImuIncrement> imu;
  receiver::ReceiverObserver* downstream = nullptr;
  ReceiveSink* sink = nullptr;
  const receiver::ReceiverEngine* engine = nullptr;
  double fs_hz = 0.0;
  fusion::TightOptions tight;
  std::vector<signals::Ephemeris> nav_ephemerides, all_ephemerides;
  std::size_t decoded_seen = 0;

  // Time line.
  std::optional<signals::GpsTime> origin;  // GPS time of IMU t_s = 0
  ReceiverClockJumps clock;
  double last_epoch_t_s = 0.0;
  std::int64_t last_epoch_sample = 0;
  bool have_epoch_time = false;

  // Alignment input and the filter.
  std::vector<fusion::GnssVelocitySample> velocities;
  std::vector<fusion::GnssFix> fixes;  // on the IMU time line
  std::optional<fusion::GnssInsIntegration> integration;
  std::size_t next_imu = 0;
  double first_share = 1.0;  // of imu[next_imu] when the start falls inside its interval
  std::string alignment_note, not_started = "no GNSS epoch yet";
  ins::EulerAngles initial_attitude;
  double start_s = 0.0;

  std::optional<receiver::ObservationEpoch> held;       // waits for its fix (on_fix follows on_observations)
  std::optional<ins::NavState> previous_nav, last_nav;  // the driving filter's last two rows, after the hand-over

  // Odometer aiding (loose, settings.odometer given): the speed windows and the next one to hand over.
  std::vector<fusion::OdometerSpeed> odometer;
  std::size_t next_odometer = 0;
  long long tight_odometer_windows = 0;  // windows the tight integration took before the hand-over
  std::optional<OdometerUse> odometer_use;
  // The ultra-tight driver's odometer counters after the hand-over (take_odometer_windows).
  fusion::OdometerCounters handed_over_odometer;

  // The odometer counters of both filters (the tight one's, then the ultra-tight driver's).
  fusion::OdometerCounters odometer_counters() const {
    fusion::OdometerCounters k = integration->counters().odometer;
    k += handed_over_odometer;
    return k;
  }

  // Counts.
  long long epochs_seen = 0, fixes_seen = 0, before_start = 0, used = 0, nav_rows = 0;
  long long unused = 0;  // after the start: loose epochs without a fix, tight epochs without ephemerides
  struct FixClock {
    signals::GpsTime receive_time;  // continuous receiver clock
    double bias_m = 0.0, drift_mps = 0.0;
  };
  std::optional<FixClock> last_fix_clock;
  long long epochs_below_4 = 0;
  double last_row_t_s = 0.0;  // tight epochs applied with 1-3 satellites with ephemeris
  NavSigma final_sigma;

  Impl(const ReceiveOptions& s, std::vector<ins::ImuIncrement> i, receiver::ReceiverObserver& d, ReceiveSink& k,
       std::vector<signals::Ephemeris> eph)
      : settings(s),
        imu(std::move(i)),
        downstream(&d),
        sink(&k),
        fs_hz(s.receiver.fs_hz),
        nav_ephemerides(std::move(eph)),
        all_ephemerides(nav_ephemerides),
        clock(s.receiver.fs_hz) {
    const receiver::ReceiverOptions& ro = s.receiver;
    tight.elevation_mask_rad = ro.pvt.elevation_mask_rad;
    tight.ionosphere = ro.pvt.ionosphere;
    tight.troposphere = ro.pvt.troposphere;
    // The tight filter takes every epoch's pseudorange as independent, but the DLL's code error is correlated
    // over its time constant 1 / (4 Bn) (0.25 s at 1 Hz against 0.1 s epochs): its 1-sigma per epoch is the
    // PVT's, widened to the white sequence of the same information (receiver::dll_white_equivalent_sigma_factor,
    // 2.21 at the defaults). Without it the tight filter, and the ultra-tight one it hands over to, stated a
    // position 1-sigma ~1.7x too small (benchmarks/ultratight_consistency.sh, docs/validation.md).
    tight.sigma_range_zenith_m =
        ro.pvt.sigma_zenith_m * receiver::dll_white_equivalent_sigma_factor(ro.tracking.dll_bw_coherent_hz,
                                                                            kDllUpdate_s, ro.observation_interval_s);
    tight.sigma_rate_zenith_mps = ro.pvt.sigma_doppler_mps;
  }

  // Ultra-tight pulls in with the tight integration until the hand-over.
  bool is_tight() const { return pipelines::is_tight(settings.coupling); }
  bool handed_over = false;

  const std::vector<signals::Ephemeris>& ephemerides() {
    if (engine && engine->decoded_ephemerides().size() != decoded_seen) {
      const auto& d = engine->decoded_ephemerides();
      all_ephemerides.insert(all_ephemerides.end(), d.begin() + static_cast<std::ptrdiff_t>(decoded_seen), d.end());
      decoded_seen = d.size();
    }
    return all_ephemerides;
  }
  signals::KlobucharParameters iono() const { return engine ? engine->klobuchar() : signals::KlobucharParameters{}; }

  // Ephemerides of the epoch's satellites at its time (one set per PRN).
  std::vector<signals::Ephemeris> epoch_ephemerides(const receiver::ObservationEpoch& e) {
    std::vector<signals::Ephemeris> out;
    const auto& all = ephemerides();
    for (const auto& o : e.observations)
      if (auto eph = signals::select_ephemeris(all, o.prn, e.receive_time)) out.push_back(*eph);
    return out;
  }

  // Receiver clock bias and drift (m, m/s) from an epoch at a known antenna position/velocity: medians of the
  // pseudorange and rate residuals with zero clock. Nothing without a usable satellite.
  std::optional<std::pair<double, double>> fit_clock(const receiver::ObservationEpoch& e, const Eigen::Vector3d& r_e,
                                                     const Eigen::Vector3d& v_e) {
    const auto sats = fusion::prepare_satellites(e, epoch_ephemerides(e), iono(), r_e, tight);
    std::vector<double> b, d;
    for (const auto& s : sats) {
      b.push_back(s.pseudorange_m - fusion::predicted_pseudorange_m(s, r_e, 0.0));
      if (s.has_rate) d.push_back(s.range_rate_mps - fusion::predicted_range_rate_mps(s, r_e, v_e, 0.0));
    }
    if (b.empty()) return std::nullopt;
    return std::make_pair(median(b), d.empty() ? 0.0 : median(d));
  }

  void check_covered(double t, const signals::GpsTime& g) const {
    if (t >= imu.front().t_s && t <= imu.back().t_s + 1e-6) return;
    throw io::InputError(
        settings.imu_name,
        fmt::format("does not cover the signal: the epoch at GPS week {} tow {:.3f} s is IMU time "
                    "{:.3f} s (--imu-time-origin {}), the IMU rows span {:.3f}-{:.3f} s",
                    g.week, g.tow_s, t, to_string(settings.imu_time_origin), imu.front().t_s, imu.back().t_s));
  }

  void emit() {
    const auto& out = integration->output();
    final_sigma = NavSigma{out.sigma_pos_ned_m, out.sigma_vel_n_mps, out.sigma_att_rad};
    if (nav_rows > 0 && !(out.nav.t_s > last_row_t_s)) return;  // an increment too short to step
    last_row_t_s = out.nav.t_s;
    if (odometer_use) odometer_use->estimate = out.odometer;
    sink->on_navigation(out.nav, final_sigma);
    ++nav_rows;
  }

  // Feeds IMU rows until the INS reaches t (or, with `at_most`, the last row not after t).
  void advance_imu(double t, bool at_most = false) {
    while (next_imu < imu.size() && integration->output().nav.t_s < t - 1e-9) {
      if (at_most && imu[next_imu].t_s > t + 1e-9) break;
      ins::ImuIncrement inc = imu[next_imu++];
      if (first_share < 1.0) {
        inc.dtheta_b *= first_share;
        inc.dv_b *= first_share;
        first_share = 1.0;
      }
      for (; next_odometer < odometer.size() && odometer[next_odometer].t_s <= inc.t_s; ++next_odometer) {
        integration->add_odometer(odometer[next_odometer]);
        ++odometer_use->windows;
      }
      integration->add_imu(inc);
      emit();
    }
  }

  // The fix (stored) nearest to t.
  const fusion::GnssFix* fix_near(double t) const {
    const fusion::GnssFix* best = nullptr;
    for (const auto& f : fixes)
      if (f.has_position && (!best || std::abs(f.t_s - t) < std::abs(best->t_s - t))) best = &f;
    return best;
  }

  // Tries to start the INS + filter at this epoch (time t; fix = this epoch's, if any).
  bool try_start(double t, const receiver::ObservationEpoch& e, const std::optional<fusion::GnssFix>& fix) {
    const FuseConfig& c = settings.navigation;
    const ins::ImuErrorSpec preset = imu_error_spec(c);
    AttitudeStart start;
    const fusion::GnssFix* pos_fix = nullptr;
    if (settings.align == AlignMode::Config) {
      if (!c.position_deg_m && !fix) {
        not_started = "--align config: waiting for a fix ([initial] position_deg_m gives the position without one)";
        return false;
      }
      // A configured position is the vehicle's at the IMU's first sample: the INS starts there (and runs alone
      // until the first epoch); without one, at this epoch's fix.
      start = align_from_config(c.position_deg_m ? imu.front().t_s - (imu[1].t_s - imu.front().t_s) : t, c);
      if (fix && fix->has_velocity) start.v_n = fix->v_n_mps;
      if (c.velocity_ned_mps) start.v_n = *c.velocity_ned_mps;
      if (fix) pos_fix = &*fix;
    } else if (settings.align == AlignMode::Static) {
      const std::size_t end = static_span_end(imu, imu.front().t_s, c, settings.imu_name);
      pos_fix = fix_near(imu[end - 1].t_s);  // at rest over the span: any fix is the position there
      if (!pos_fix && !c.position_deg_m) {
        not_started = "--align static: waiting for a fix";
        return false;
      }
      if (t < imu[end - 1].t_s) {
        not_started = "--align static: the static span has not ended";
        return false;
      }
      const double lat = pos_fix ? pos_fix->lat_rad : c.position_deg_m->x() * io::kRadPerDeg;
      start = align_static(std::span(imu).first(end), imu.front().t_s, lat, preset);
    } else {
      auto a = align_moving(imu, velocities, c, c.motion_window_s, false);
      // Once it can align: again with the gyro biases of a standstill at the start, if there was one (looked for
      // only now: the epochs before would each scan the record from its start).
      if (a) {
        if (const auto standstill = motion_standstill(imu, velocities.back().lat_rad, c, preset, t))
          if (auto with = align_moving(imu, velocities, c, c.motion_window_s, false, standstill)) a = std::move(with);
      }
      if (!a) {
        not_started = fmt::format("--align motion: the fixes never showed {} m/s for {} s", c.motion_min_speed_mps,
                                  c.motion_window_s);
        return false;
      }
      start = *a;
      pos_fix = fix_near(a->t_s);
    }
    alignment_note = start.note;
    GnssPosition position;
    if (pos_fix) position = {pos_fix->lat_rad, pos_fix->lon_rad, pos_fix->height_m, pos_fix->sigma_pos_ned_m};
    const NavigationStart n =
        initialise_navigation(start, pos_fix ? &position : nullptr, c, Eigen::Vector3d::Constant(10.0));
    const ins::NavState& init = n.nav;
    fusion::IntegrationOptions o =
        integration_options(n, c, is_tight() ? fusion::Coupling::kTight : fusion::Coupling::kLoose, settings.filter);
    if (is_tight()) {
      // Clock from this epoch at the INS antenna position and velocity there (the INS alone from the start to
      // the epoch), carried back to the start.
      ins::Strapdown alone(init, o.strapdown);
      for (const auto& inc : imu) {
        if (inc.t_s <= init.t_s + 1e-6) continue;
        if (inc.t_s > t) break;
        alone.step(inc);
      }
      const ins::NavState& at = alone.state();
      const Eigen::Vector3d r_e = fusion::antenna_position_e(at, c.lever_arm_b);
      const Eigen::Vector3d v_e = ins::C_en(at.lat_rad, at.lon_rad) * at.v_n;
      const auto clock = fit_clock(e, r_e, v_e);
      if (!clock) {
        not_started = "tight: no satellite with ephemeris above the mask yet";
        return false;
      }
      o.tight = tight;
      o.gps_time_origin = *origin;
      o.initial_clock_drift_mps = clock->second;
      o.initial_clock_bias_m = clock->first - clock->second * (t - init.t_s);
      // The fit's error follows the position and velocity errors (a few metres, m/s), not the receiver's ms.
      o.model.clock.bias_sigma_m = 3.0 * n.sigma_pos_ned_m.norm() + 10.0;
      o.model.clock.drift_sigma_mps = 3.0 * n.sigma_vel_n_mps.norm() + 1.0;
      o.model.clock = fusion::clock_noise_from_allan(c.clock_allan, o.model.clock);
      o.height_aiding = c.height_aiding;
    }
    if (!settings.odometer.empty()) {  // as fuse (pipelines/fuse.hpp): windows of 1 / update_rate_hz
      o.odometer = c.odometer;
      o.odometer.enabled = true;
      if (std::string why; !o.odometer.IsValid(&why)) throw io::InputError("configuration", why);
      odometer = odometer_windows(settings.odometer, 1.0 / c.odometer.update_rate_hz);
      while (next_odometer < odometer.size() && odometer[next_odometer].t_s <= init.t_s) ++next_odometer;
      odometer_use.emplace().gnss_last_used_s = init.t_s;
    }
    integration.emplace(init, o);
    initial_attitude = ins::euler_from_quaternion(init.q_nb);
    start_s = init.t_s;
    next_imu = 0;
    // Rows ending within 1 us of the start are skipped (the integration ignores steps below 1 ns anyway).
    while (next_imu < imu.size() && imu[next_imu].t_s <= init.t_s + 1e-6) ++next_imu;
    if (next_imu > 0 && next_imu < imu.size())
      first_share = (imu[next_imu].t_s - init.t_s) / (imu[next_imu].t_s - imu[next_imu - 1].t_s);
    emit();
    return true;
  }

  // One epoch with its fix (if the PVT made one).
  void process(const receiver::ObservationEpoch& raw, const receiver::PvtSolution* fix) {
    ++epochs_seen;
    if (fix) ++fixes_seen;
    if (handed_over) return;
    const receiver::ObservationEpoch e = clock.continuous(raw);
    std::optional<signals::GpsTime> g;
    if (fix) {
      g = fix->time;
      // The fix's clock on the continuous receiver clock, for the epochs without a fix (loose).
      last_fix_clock = FixClock{e.receive_time, fix->clock_bias_m - kC * clock.jump_s(), fix->clock_drift_mps};
    } else if (integration && is_tight()) {
      g = signals::add_seconds(e.receive_time, -integration->nominal().clock_bias_m / kC);
    } else if (is_tight() && settings.align == AlignMode::Config && settings.navigation.position_deg_m) {
      // No fix (fewer than four satellites): the clock from the configured position (only to map this epoch's
      // time: an error of tens of metres there is tens of nanoseconds).
      const FuseConfig& c = settings.navigation;
      const Eigen::Vector3d r_e = ins::ecef_from_geodetic(
          c.position_deg_m->x() * io::kRadPerDeg, c.position_deg_m->y() * io::kRadPerDeg, c.position_deg_m->z());
      const Eigen::Vector3d v_e =
          ins::C_en(c.position_deg_m->x() * io::kRadPerDeg, c.position_deg_m->y() * io::kRadPerDeg) *
          c.velocity_ned_mps.value_or(Eigen::Vector3d::Zero());
      if (const auto clock = fit_clock(e, r_e, v_e)) g = signals::add_seconds(e.receive_time, -clock->first / kC);
    } else if (integration && last_fix_clock) {
      // Loose, no fix this epoch: the time from the last fix's clock bias and drift; the INS runs on to it.
      const FixClock& k = *last_fix_clock;
      const double bias_m = k.bias_m + k.drift_mps * signals::seconds_between(e.receive_time, k.receive_time);
      g = signals::add_seconds(e.receive_time, -bias_m / kC);
    }
    if (!g) {
      ++(integration ? unused : before_start);
      return;
    }
    if (!origin) origin = imu_time_origin_gps(settings.imu_time_origin, *g, e.sample_index, fs_hz);
    const double t = signals::seconds_between(*g, *origin);
    check_covered(t, *g);
    last_epoch_t_s = t;
    last_epoch_sample = e.sample_index;
    have_epoch_time = true;

    std::optional<fusion::GnssFix> f;
    if (fix) {
      f = fix_measurement(*fix, t);
      fixes.push_back(*f);
      if (f->has_velocity) velocities.push_back({t, f->lat_rad, f->height_m, f->v_n_mps});
    }
    if (!integration && !try_start(t, e, f)) {
      ++before_start;
      return;
    }
    if (t <= start_s + 1e-9) {  // used for the start itself
      ++before_start;
      return;
    }
    if (is_tight()) {
      const auto eph = epoch_ephemerides(e);
      if (eph.empty()) {
        ++unused;
      } else {
        if (eph.size() < 4) ++epochs_below_4;
        integration->add_observations(e, eph, iono());
        if (odometer_use && !e.observations.empty()) odometer_use->gnss_last_used_s = t;
        ++used;
      }
    } else if (f) {
      integration->add_fix(*f);
      if (odometer_use) odometer_use->gnss_last_used_s = t;
      ++used;
    } else {
      ++unused;
    }
    advance_imu(t);
  }

  void flush() {
    if (held) {
      const receiver::ObservationEpoch e = std::move(*held);
      held.reset();
      process(e, nullptr);
    }
  }
};

GnssInsCoupler::GnssInsCoupler(const ReceiveOptions& options, std::vector<ins::ImuIncrement> imu,
                               receiver::ReceiverObserver& downstream, ReceiveSink& sink,
                               std::vector<signals::Ephemeris> nav_ephemerides)
    : impl_(std::make_unique<Impl>(options, std::move(imu), downstream, sink, std::move(nav_ephemerides))) {}

GnssInsCoupler::~GnssInsCoupler() = default;

void GnssInsCoupler::attach(const receiver::ReceiverEngine& engine) { impl_->engine = &engine; }

void GnssInsCoupler::on_tracking(const receiver::TrackingRecord& r) { impl_->downstream->on_tracking(r); }
void GnssInsCoupler::on_acquisition(std::int64_t first, const std::vector<receiver::AcquisitionResult>& r) {
  impl_->downstream->on_acquisition(first, r);
}
void GnssInsCoupler::on_antenna_phases(const receiver::AntennaPhaseEpoch& e) {
  impl_->downstream->on_antenna_phases(e);
}

void GnssInsCoupler::on_observations(const receiver::ObservationEpoch& epoch) {
  impl_->downstream->on_observations(epoch);
  impl_->flush();  // the previous epoch had no fix
  impl_->held = epoch;
}

namespace {
// Once the filter drives the channels (ultra-tight after the hand-over), their Doppler is the filter's
// command plus a PLL residual, so a least-squares velocity from it only adds the residual's noise (4.9 m/s RMS
// against the filter's 0.3 m/s on another generator's 30 km/h circle): the fix reports the filter's antenna
// velocity instead, from its last two navigation rows extrapolated linearly to the fix (the pipelined loop's rows
// lag the fix by 30 ms), when the last row is within 0.1 s of it. Its clock drift stays the least-squares one.
receiver::PvtSolution with_filter_velocity(const receiver::PvtSolution& fix, const ins::NavState& previous,
                                           const ins::NavState& last, const signals::GpsTime& origin,
                                           const Eigen::Vector3d& lever_arm_b) {
  constexpr double kMaxAge_s = 0.1;
  const double t_fix = signals::seconds_between(fix.time, origin);
  const double dt_rows = last.t_s - previous.t_s;
  if (!fix.valid || std::abs(t_fix - last.t_s) > kMaxAge_s || !(dt_rows > 0.0)) return fix;
  const Eigen::Vector3d v1 = fusion::antenna_velocity_n(last, Eigen::Vector3d::Zero(), lever_arm_b);
  const Eigen::Vector3d v0 = fusion::antenna_velocity_n(previous, Eigen::Vector3d::Zero(), lever_arm_b);
  const Eigen::Vector3d v_n = v1 + (v1 - v0) * ((t_fix - last.t_s) / dt_rows);
  receiver::PvtSolution out = fix;
  out.v_e_mps = ins::C_en(last.lat_rad, last.lon_rad) * v_n;
  out.v_enu_mps = Eigen::Vector3d(v_n.y(), v_n.x(), -v_n.z());
  out.velocity_valid = true;
  return out;
}
}  // namespace

void GnssInsCoupler::on_fix(const receiver::PvtSolution& fix, const receiver::ObservationEpoch& epoch) {
  Impl& m = *impl_;
  if (m.handed_over && m.previous_nav && m.origin)
    m.downstream->on_fix(
        with_filter_velocity(fix, *m.previous_nav, *m.last_nav, *m.origin, m.settings.navigation.lever_arm_b), epoch);
  else
    m.downstream->on_fix(fix, epoch);
  if (impl_->held && impl_->held->sample_index == epoch.sample_index) {
    const receiver::ObservationEpoch e = std::move(*impl_->held);
    impl_->held.reset();
    impl_->process(e, &fix);
  } else {
    impl_->flush();
    impl_->process(epoch, &fix);
  }
}

void GnssInsCoupler::finish(std::int64_t end_sample) {
  Impl& m = *impl_;
  m.flush();
  if (m.integration && m.have_epoch_time && !m.handed_over) {
    const double t_end = m.last_epoch_t_s + static_cast<double>(end_sample - m.last_epoch_sample) / m.fs_hz;
    m.advance_imu(std::min(t_end, m.imu.back().t_s), true);
  }
}

bool GnssInsCoupler::started() const { return impl_->integration.has_value(); }
std::string GnssInsCoupler::not_started_reason() const { return impl_->not_started; }
long long GnssInsCoupler::nav_rows() const { return impl_->nav_rows; }
NavSigma GnssInsCoupler::final_sigma() const { return impl_->final_sigma; }

const fusion::GnssInsIntegration* GnssInsCoupler::integration() const {
  return impl_->integration ? &*impl_->integration : nullptr;
}
const std::vector<ins::ImuIncrement>& GnssInsCoupler::imu() const { return impl_->imu; }
const ReceiveOptions& GnssInsCoupler::options() const { return impl_->settings; }
std::optional<signals::GpsTime> GnssInsCoupler::imu_time_origin() const { return impl_->origin; }
std::optional<std::pair<std::int64_t, double>> GnssInsCoupler::last_epoch_time() const {
  if (!impl_->have_epoch_time) return std::nullopt;
  return std::make_pair(impl_->last_epoch_sample, impl_->last_epoch_t_s);
}
void GnssInsCoupler::hand_over() { impl_->handed_over = true; }

std::vector<fusion::OdometerSpeed> GnssInsCoupler::take_odometer_windows() {
  Impl& m = *impl_;
  if (m.odometer_use) m.tight_odometer_windows = m.odometer_use->windows;
  std::vector<fusion::OdometerSpeed> rest(m.odometer.begin() + static_cast<std::ptrdiff_t>(m.next_odometer),
                                          m.odometer.end());
  m.next_odometer = m.odometer.size();
  return rest;
}

void GnssInsCoupler::record_handed_over_odometer(long long windows, const fusion::OdometerCounters& counters,
                                                 const fusion::OdometerEstimate& estimate, double gnss_last_used_s) {
  Impl& m = *impl_;
  if (!m.odometer_use) return;
  m.handed_over_odometer = counters;
  m.odometer_use->estimate = estimate;
  m.odometer_use->windows = m.tight_odometer_windows + windows;
  m.odometer_use->gnss_last_used_s = std::max(m.odometer_use->gnss_last_used_s, gnss_last_used_s);
}
bool GnssInsCoupler::handed_over() const { return impl_->handed_over; }
void GnssInsCoupler::write_nav(const ins::NavState& nav, const Eigen::Vector3d& sigma_pos_ned_m,
                               const Eigen::Vector3d& sigma_vel_n_mps, const Eigen::Vector3d& sigma_att_rad) {
  Impl& m = *impl_;
  m.final_sigma = NavSigma{sigma_pos_ned_m, sigma_vel_n_mps, sigma_att_rad};
  if (m.nav_rows > 0 && !(nav.t_s > m.last_row_t_s)) return;
  m.last_row_t_s = nav.t_s;
  if (m.handed_over) {
    if (m.last_nav) m.previous_nav = m.last_nav;
    m.last_nav = nav;
  }
  m.sink->on_navigation(nav, m.final_sigma);
  ++m.nav_rows;
}

std::string GnssInsCoupler::summary_json() const {
  const Impl& m = *impl_;
  const char* align = to_string(m.settings.align);
  std::string j = "\"fusion\": {";
  j += fmt::format(
      "\"coupling\": \"{}\", \"filter\": \"{}\", \"align\": \"{}\", \"imu_file\": \"{}\", "
      "\"imu_time_origin\": \"{}\", \"imu_preset\": \"{}\", \"started\": {}",
      to_string(m.settings.coupling), m.settings.filter == fusion::FilterKind::Ekf ? "ekf" : "ukf", align,
      io::json_escape(m.settings.imu_name), to_string(m.settings.imu_time_origin),
      io::json_escape(m.settings.navigation.imu_preset), m.integration.has_value());
  j += ", \"imu_model\": " + imu_model_json(m.settings.navigation);
  if (m.origin)
    j += fmt::format(", \"imu_time_origin_gps\": {{\"week\": {}, \"tow_s\": {:.9f}}}", m.origin->week, m.origin->tow_s);
  j += fmt::format(
      ", \"epochs_seen\": {}, \"fixes_seen\": {}, \"epochs_before_start\": {}, \"epochs_used\": {}, "
      "\"epochs_unused\": {}",
      m.epochs_seen, m.fixes_seen, m.before_start, m.used, m.unused);
  if (m.settings.coupling == Coupling::kUltraTight) j += fmt::format(", \"handed_over\": {}", m.handed_over);
  if (m.is_tight()) j += fmt::format(", \"epochs_fewer_than_4_satellites\": {}", m.epochs_below_4);
  j += fmt::format(", \"clock_jumps_removed\": {}, \"nav_rows\": {}", m.clock.jumps(), m.nav_rows);
  if (!m.integration) return j + fmt::format(", \"reason\": \"{}\"}}", io::json_escape(m.not_started));
  const auto& k = m.integration->counters();
  const auto& e = m.initial_attitude;
  j += fmt::format(
      ", \"alignment\": {{\"note\": \"{}\", \"t_s\": {}, \"roll_deg\": {:.6f}, \"pitch_deg\": {:.6f}, "
      "\"yaw_deg\": {:.6f}}}",
      io::json_escape(m.alignment_note), m.start_s, e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg,
      e.yaw_rad / io::kRadPerDeg);
  j += fmt::format(
      ", \"start_s\": {}, \"end_s\": {}, \"imu_steps\": {}, \"updates_accepted\": {}, "
      "\"updates_rejected\": {}, \"late\": {}, \"invalid\": {}, \"satellites_missing_ephemeris\": {}",
      m.start_s, m.integration->output().nav.t_s, k.imu_steps, k.accepted, k.rejected, k.late, k.invalid,
      k.satellites_missing_ephemeris);
  j += fmt::format(", \"lockout_recoveries\": {}, \"recovery_events\": {}", k.recoveries,
                   recovery_events_json(m.integration->recovery_events()));
  if (m.odometer_use)
    j += ", \"odometer\": " + odometer_json(*m.odometer_use, m.odometer_counters(), m.settings.navigation.odometer,
                                            m.settings.odometer_name);
  if (m.is_tight())
    j += fmt::format(
        ", \"clock_oscillator\": {{\"preset\": \"{}\", \"h0\": {:.3g}, \"h_minus2\": {:.3g}}}, "
        "\"height_aiding\": {{\"mode\": \"{}\", \"epochs_few_satellites\": {}, \"accepted\": {}, "
        "\"rejected\": {}}}",
        m.settings.navigation.clock_oscillator, m.settings.navigation.clock_allan.h0,
        m.settings.navigation.clock_allan.h_minus2, m.settings.navigation.height_aiding.enabled ? "auto" : "off",
        k.epochs_few_satellites, k.height_accepted, k.height_rejected);
  const NavSigma& g = m.final_sigma;
  j += fmt::format(
      ", \"final_sigma\": {{\"north_m\": {:.6g}, \"east_m\": {:.6g}, \"down_m\": {:.6g}, "
      "\"vel_mps\": {:.6g}, \"heading_deg\": {:.6g}}}}}",
      g.position_ned_m.x(), g.position_ned_m.y(), g.position_ned_m.z(), g.velocity_ned_mps.norm(),
      g.attitude_ned_rad.z() / io::kRadPerDeg);
  return j;
}

std::string GnssInsCoupler::report() const {
  const Impl& m = *impl_;
  if (!m.integration)
    return fmt::format("receive: {} integration not started: {}", to_string(m.settings.coupling), m.not_started);
  const auto& k = m.integration->counters();
  std::string r = fmt::format(
      "receive: {} {} integration, aligned {} at {:.3f} s; {} epochs used ({} before the start), updates accepted "
      "{}, rejected {}; final 1-sigma horizontal {:.2f} m, vertical {:.2f} m; {} nav rows",
      to_string(m.settings.coupling), m.settings.filter == fusion::FilterKind::Ekf ? "EKF" : "UKF", m.alignment_note,
      m.start_s, m.used, m.before_start, k.accepted, k.rejected, m.final_sigma.position_ned_m.head<2>().norm(),
      m.final_sigma.position_ned_m.z(), m.nav_rows);
  if (m.odometer_use) {
    const fusion::OdometerCounters o = m.odometer_counters();
    r += fmt::format(
        "\nreceive: odometer: {} windows, updates accepted {}, rejected {} (gate); gated out by heading "
        "rate {}, by speed {}",
        m.odometer_use->windows, o.accepted, o.rejected, o.gated_yaw_rate, o.gated_speed);
  }
  return r;
}

}  // namespace ultratrack::pipelines
