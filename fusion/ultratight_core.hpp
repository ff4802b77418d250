// SPDX-License-Identifier: GPL-3.0-or-later
// The filter behind fusion::UltraTightIntegration (internal to fusion): UltraTightCore<Filter> on 17 states (INS and
// clock errors) or 21 (+ the odometer's four at [17, 21): UltraTightOptions::odometer). Included only by
// ultratight_core_17.cpp and ultratight_core_21.cpp, each of which compiles one state size (EKF and UKF), so that
// the four filters build in parallel instead of one source taking minutes.
#pragma once

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "fusion/bias_frame_reset.hpp"
#include "fusion/carrier_rate_measurement.hpp"
#include "fusion/odometer_history.hpp"
#include "fusion/ultratight_integration.hpp"
#include "fusion/ultratight_measurement_models.hpp"
#include "ins/earth_model.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion::ultratight_detail {

inline constexpr double kC = signals::kSpeedOfLight_mps;
inline constexpr double kLambda_m = signals::kL1Wavelength_m;

// The entry of a satellite in a list by PRN (the last one, should it appear twice); nullptr when absent.
template <class T>
const T* find_prn(const std::vector<T>& list, int prn) {
  const T* found = nullptr;
  for (const T& x : list)
    if (x.prn == prn) found = &x;
  return found;
}

struct UltraTightCoreBase {
  virtual ~UltraTightCoreBase() = default;
  virtual void add_imu(const ins::ImuIncrement& inc) = 0;
  virtual void add_ephemerides(const std::vector<signals::Ephemeris>& eph) = 0;
  virtual void start_period(double T) = 0;
  virtual void finish_period(const std::vector<ChannelCorrelation>& c) = 0;
  virtual NominalState nominal() const = 0;
  virtual Eigen::MatrixXd covariance() const = 0;
  virtual void set_covariance(const Eigen::MatrixXd& P) = 0;
  virtual void add_odometer(const OdometerSpeed& speed) = 0;
  std::vector<ReplicaCommand> replicas;
  std::vector<UltraTightSatelliteUpdate> last_updates;
  IntegrationOutput output;
  UltraTightCounters counters;
};

struct ChannelState {
  double carrier_phase_cycles = 0.0;
  bool coasting = false;
  // The carrier phase error (signal minus replica, rad) at the end of this channel's last measured epoch, for a
  // continuous-carrier channel (ChannelCorrelation::continuous_carrier): its measured mean phase plus the
  // end-minus-mean phase of the filter's rate-error profile; its variance; the epoch's end time (s).
  bool has_end_phase = false;
  double end_phase_rad = 0.0, end_phase_var_rad2 = 0.0, end_phase_t_s = 0.0;
};

// N = 17 (INS and clock errors) or 21 (+ the odometer's four at [17, 21): UltraTightOptions::odometer). The I&Q,
// discriminator and carrier-rate models are written for the first 17 and padded.
template <class Filter>
class UltraTightCore final : public UltraTightCoreBase {
  static constexpr int N = Filter::kStateSize;
  static constexpr bool kOdometer = N == 21;
  static_assert(N == 17 || N == 21);
  using Model = std::conditional_t<kOdometer, OdometerAugmentedModel<17>, InsErrorModel<17>>;

 public:
  UltraTightCore(const ins::NavState& initial, std::vector<signals::Ephemeris> eph, const UltraTightOptions& o,
                 Filter filter)
      : opt_(o), eph_(std::move(eph)), ins_(initial, o.strapdown), model_(make_model(o)), filter_(std::move(filter)) {
    nominal_.nav = ins_.state();
    nominal_.clock_bias_m = o.initial_clock_bias_m;
    nominal_.clock_drift_mps = o.initial_clock_drift_mps;
    nominal_.accel_bias_b = o.initial_accel_bias_b;
    nominal_.gyro_bias_b = o.initial_gyro_bias_b;
    odometer_ = o.initial_odometer;
    InsLinearisation lin;
    lin.nav = nominal_.nav;
    lin.f_b = nominal_.nav.q_nb.conjugate() * Eigen::Vector3d(0.0, 0.0, -9.80665);
    model_.set_linearisation(lin);
    fill_output();
  }

  void add_imu(const ins::ImuIncrement& inc) override {
    const double dt = inc.t_s - nominal_.nav.t_s;
    if (!(dt > 0.0) || !std::isfinite(inc.t_s) || !inc.dtheta_b.allFinite() || !inc.dv_b.allFinite()) return;
    const Eigen::Vector3d dth = inc.dtheta_b - nominal_.gyro_bias_b * dt;
    const Eigen::Vector3d dv = inc.dv_b - nominal_.accel_bias_b * dt;
    const Eigen::Quaterniond q0 = ins_.state().q_nb;
    ins_.step(dth, dv, dt);
    nominal_.nav = ins_.state();
    nominal_.clock_bias_m += nominal_.clock_drift_mps * dt;
    imu_steps_.add(q0, nominal_.nav.q_nb, dth, dv, dt);
    if constexpr (kOdometer) history_.record(nominal_.nav, 1.0 / opt_.odometer.update_rate_hz + 1.0);
    fill_output();
  }

  // One odometer window ending now ([KimVMS] eqs. 11-17): the gate of eqs. 16-17, then the VMS/NHC update.
  void add_odometer(const OdometerSpeed& speed) override {
    if constexpr (kOdometer) {
      if (!std::isfinite(speed.speed_mps) || !(speed.window_s > 0.0) || !std::isfinite(speed.window_s)) {
        ++counters.odometer.unusable;
        return;
      }
      const auto w = history_.gated_window(nominal_.nav, speed, opt_.odometer, counters.odometer);
      if (!w) return;
      propagate();
      const VmsMeasurement m(nominal_, odometer_, imu_steps_.w_ib_b, w->a_b, speed, opt_.odometer);
      ++(apply(OdometerStatesAt<VmsMeasurement, 17, N>(m)).accepted ? counters.odometer.accepted
                                                                    : counters.odometer.rejected);
      fill_output();
    } else {
      (void)speed;
      throw std::logic_error("ultra-tight: odometer aiding is not enabled");
    }
  }

  void add_ephemerides(const std::vector<signals::Ephemeris>& eph) override {
    for (const signals::Ephemeris& e : eph) {
      const bool held = std::any_of(eph_.begin(), eph_.end(), [&](const signals::Ephemeris& h) {
        return h.prn == e.prn && h.iode == e.iode && h.iodc == e.iodc && h.week == e.week && h.toe_s == e.toe_s &&
               h.toc_s == e.toc_s;
      });
      if (held) continue;
      eph_.push_back(e);
      now_valid_ = false;  // finish_period's satellites lack this set: the next start_period predicts afresh
    }
  }

  void start_period(double T) override {
    if (!(T >= 1e-3 - 1e-12 && T <= 0.020 + 1e-12))
      throw std::invalid_argument("ultra-tight: integration time must lie in [1, 20] ms");
    T_ = T;
    // Right after finish_period (same instant): its satellites, re-ranged from the updated nominal. The updates
    // move the nominal by mm to m, the transmit time by 1e-11 to 1e-8 s: satellite states differ from a new
    // prediction by 4 km/s x that (< 0.1 mm), and the two-pass iteration is half the driver's cost per period.
    if (now_valid_ && now_t_s_ == nominal_.nav.t_s) {
      sats_start_ = now_;
      predict_ranges(sats_start_);
    } else {
      predict_satellites(sats_start_);
    }
    replicas.clear();
    for (const SatelliteObservable& s : sats_start_) {
      ChannelState& ch = channels_[s.prn];
      ReplicaCommand r;
      r.prn = s.prn;
      r.t_start_s = nominal_.nav.t_s;
      r.pseudorange_m = s.pseudorange_m;
      r.range_rate_mps = s.range_rate_mps;
      r.nco.carrier_frequency_hz = -s.range_rate_mps / kLambda_m;
      r.nco.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 - s.range_rate_mps / kC);
      r.carrier_phase_cycles = ch.carrier_phase_cycles;
      r.elevation_rad = s.elevation_rad;
      r.coasting = ch.coasting;
      r.aided_only = s.elevation_rad < opt_.measurement_mask_rad;
      replicas.push_back(r);
    }
  }

  void finish_period(const std::vector<ChannelCorrelation>& corr) override {
    ++counters.periods;
    last_updates.clear();
    propagate();
    predict_satellites(now_);
    now_valid_ = true;
    now_t_s_ = nominal_.nav.t_s;
    const std::vector<SatelliteObservable>& now = now_;
    auto lookup = [&](int prn, const ChannelCorrelation*& c, const SatelliteObservable*& s) {
      c = find_prn(corr, prn);
      s = find_prn(now, prn);
      return c && s && c->data_wiped && c->cn0_dbhz >= opt_.coast_cn0_dbhz &&
             std::abs(c->integration_time_s - T_) < 1e-9;
    };
    int usable_count = 0;
    for (const ReplicaCommand& r : replicas) {
      const ChannelCorrelation* c;
      const SatelliteObservable* s;
      usable_count += lookup(r.prn, c, s) && !r.aided_only ? 1 : 0;
    }
    // The receiver clock's frequency within the period differs from the drift state by e, common to every
    // satellite of the period (variance v, clock_rate_noise_var): the measurements see drift + e. Exact
    // treatment without an 18th state: the period's updates run on x' = x + u e (u the drift axis; prior
    // covariance P + v u u'), then e is conditioned on the posterior x' and taken out (end_common_clock).
    // e is correlated with this period's clock process noise, already in P: for the random-walk FM (S_d)
    // e = (T/3-weighted drift) - (end drift) has covariance -2 S_d T / 3 with the drift's increment (correlation
    // -0.91: the frequency the taps see is nearly the drift at the period's start); for the white FM (S_b) the
    // mean phase's rate equivalent (2 / T^2) int (T - s) db(s) has covariance S_b with the bias increment.
    const double common_var = usable_count > 0 ? clock_rate_noise_var(T_) : 0.0;
    StateMatrix<N> P_prime;
    StateVector<N> cov_xe = StateVector<N>::Zero();
    if (common_var > 0.0) {
      cov_xe(ix::kClockBias) = opt_.model.clock.bias_psd_m2_per_s;
      cov_xe(ix::kClockDrift) = -2.0 * opt_.model.clock.drift_psd_m2_per_s3 * T_ / 3.0;
      P_prime = filter_.P();
      StateVector<N> u = StateVector<N>::Zero();
      u(ix::kClockDrift) = 1.0;
      P_prime += common_var * u * u.transpose() + u * cov_xe.transpose() + cov_xe * u.transpose();
      filter_.set_P(P_prime);
    }
    period_dx_.setZero();
    period_odometer_dx_.setZero();
    struct EndPhase {
      ChannelState* ch;
      ReplicaErrors17 rep;  // at the nominal of the satellite's update
      Eigen::Vector2d offset;
      double theta, var, slope_mps, t_end;
      StateVector<17> dx_before;  // the period's corrections before the satellite's update
    };
    std::vector<EndPhase> end_phases;
    for (ReplicaCommand& command : replicas) {
      ChannelState& ch = channels_[command.prn];
      ReplicaCommand r = command;
      ch.carrier_phase_cycles = r.carrier_phase_cycles + r.nco.carrier_frequency_hz * T_;  // keeps running
      const ChannelCorrelation* c;
      const SatelliteObservable* s;
      const bool usable = lookup(r.prn, c, s);
      if (usable && c->has_replica) {  // the replica that ran instead of the command
        r.t_start_s = c->replica_t_start_s;
        r.pseudorange_m = c->replica_pseudorange_m;
        r.range_rate_mps = c->replica_range_rate_mps;
      }
      const bool had_end_phase = ch.has_end_phase;
      ch.has_end_phase = false;
      if (usable && command.aided_only) {
        ch.coasting = false;
        ++counters.aided_only;
        continue;
      }
      if (!usable) {
        ch.coasting = true;
        ++counters.coasting;
        continue;
      }
      // Offset of the replica that ran (constant rate from its start range) from this nominal's signal over
      // the period, as the correlations see it (period_replica_errors: mean range, rate error at a third of
      // the period): the signal's rate varies linearly over the period with the slope of the nominal's own
      // predictions (start and end, both before this period's updates; line-of-sight acceleration up to
      // 4 m/s^2 on the circle, 0.46 Hz over 20 ms), anchored at the end on the nominal as it stands now
      // (earlier satellites of this period have updated it; those corrections hold over the whole period).
      const Eigen::Vector3d r_ant = antenna_position_e(nominal_.nav, opt_.lever_arm_b);
      const Eigen::Vector3d v_ant = ins::C_en(nominal_.nav.lat_rad, nominal_.nav.lon_rad) *
                                    antenna_velocity_n(nominal_.nav, imu_steps_.w_ib_b, opt_.lever_arm_b);
      const double pr_now = predicted_pseudorange_m(*s, r_ant, nominal_.clock_bias_m);
      const double rr_now = predicted_range_rate_mps(*s, r_ant, v_ant, nominal_.clock_drift_mps);
      // The replica's period [t0, t0 + T] may end before this update (a receiver channel's epoch): the signal's
      // rate is carried back along the slope of the command's two predictions.
      const double command_span = nominal_.nav.t_s - command.t_start_s;
      const double rate_slope = command_span > 0.0 ? (s->range_rate_mps - command.range_rate_mps) / command_span : 0.0;
      const Eigen::Vector2d offset = period_signal_offset(r.pseudorange_m, r.range_rate_mps, r.t_start_s, T_,
                                                          nominal_.nav.t_s, pr_now, rr_now, rate_slope);
      const double span = period_span_s(nominal_.nav.t_s, r.t_start_s, T_);
      const double clock_rate_var = 0.0;  // the common clock term is in P for this period (above)
      IqSettings is;
      is.cn0_dbhz = c->cn0_dbhz;
      is.integration_time_s = T_;
      is.tap_offset_chips = opt_.tap_offset_chips;
      if (opt_.ca_code_correlation) is.code_lag1_correlation = ca_code_lag1_correlation(r.prn);
      // Start phase: the previous epoch's end phase when the carrier ran on from it (ChannelCorrelation).
      double start_phase = 0.0, start_phase_var = c->start_phase_var_rad2;
      if (c->continuous_carrier && had_end_phase && std::abs(ch.end_phase_t_s - r.t_start_s) < 1e-5) {
        start_phase = ch.end_phase_rad;
        start_phase_var = ch.end_phase_var_rad2;
      }
      const ReplicaErrors17 rep(nominal_, {*s}, opt_.lever_arm_b, imu_steps_.w_ib_b);
      const StateVector<17> dx_before = period_dx_;
      bool ok = false;
      if (opt_.form == UltraTightForm::Iq) {
        IqPeriodOptions period;
        period.offset = offset;
        period.span_s = span;
        period.prior_code_sigma_chips = prior_code_sigma_chips(rep, P17(), span);
        period.clock_rate_var_m2ps2 = clock_rate_var;
        period.start_phase_rad = start_phase;
        period.start_phase_var_rad2 = start_phase_var;
        ok =
            update(padded(PeriodIqMeasurement(nominal_, *s, opt_.lever_arm_b, imu_steps_.w_ib_b, is, c->taps, period)));
      } else {
        // The frequency discriminator reads the mean phase, start phase + pi T f(T / 3): the start phase comes off.
        ok = update(padded(PeriodDiscriminatorMeasurement(nominal_, *s, opt_.lever_arm_b, imu_steps_.w_ib_b, offset,
                                                          span, period_discriminator_errors(c->taps, is, start_phase),
                                                          discriminator_noise(is), clock_rate_var,
                                                          start_phase_rate_variance(start_phase_var, T_))));
      }
      if (c->continuous_carrier) {
        // This epoch's end phase (after the period's last update, below): its measured mean phase (data wiped:
        // the prompt near the I axis) plus the end-minus-mean phase pi T f(2 T / 3) of the rate-error profile.
        const double theta = std::atan2(c->taps.q[1], c->taps.i[1]);
        const double a2 = std::pow(iq_amplitude(is), 2);
        if (std::abs(theta) < 0.5 * M_PI && a2 > 0.0)
          end_phases.push_back(
              {&ch, rep, offset, theta, (1.0 + 1.0 / a2) / a2, rate_slope * T_, r.t_start_s + T_, dx_before});
      }
      ch.coasting = !ok;
      if (!ok) ++counters.coasting;
      last_updates.push_back({r.prn, ok, last_result_.nis, last_result_.innovation});
    }
    // End phases from the period's final profile (x', whose drift includes the common e the taps saw): the rate
    // error at 2 T / 3 (replica minus signal; the replica holds its rate, the signal's changes by slope over the
    // period) under the corrections from the satellite's own update on.
    for (const EndPhase& p : end_phases) {
      const double e13 = p.rep.errors(period_dx_ - p.dx_before)(1) + p.offset(1);
      p.ch->has_end_phase = true;
      p.ch->end_phase_rad = p.theta + M_PI * T_ * (e13 - p.slope_mps / 3.0) / kLambda_m;
      p.ch->end_phase_var_rad2 = p.var;
      p.ch->end_phase_t_s = p.t_end;
    }
    if (common_var > 0.0) end_common_clock(P_prime, common_var, cov_xe);
    carrier_rate_update(corr);
    fill_output();
  }

  // The period's carrier-phase rates (fusion/carrier_rate_measurement.hpp), after its I&Q updates: every usable
  // satellite with a window ending now, in one update (their clock term is common). Each window's rate is carried
  // from its middle to now along the nominal's predicted slope; a row whose innovation alone is beyond
  // carrier_rate_screen_sigma is left out (a slipped or lost PLL), the rest face the filter's gate together.
  void carrier_rate_update(const std::vector<ChannelCorrelation>& corr) {
    std::vector<CarrierRateRow> rows;
    double common_var = 0.0;
    const Eigen::Vector3d r_ant = antenna_position_e(nominal_.nav, opt_.lever_arm_b);
    const Eigen::Vector3d v_ant = ins::C_en(nominal_.nav.lat_rad, nominal_.nav.lon_rad) *
                                  antenna_velocity_n(nominal_.nav, imu_steps_.w_ib_b, opt_.lever_arm_b);
    const StateMatrix<17> P = P17();
    for (const ReplicaCommand& command : replicas) {
      if (command.aided_only) continue;
      const ChannelCorrelation* c = find_prn(corr, command.prn);
      const SatelliteObservable* s = find_prn(now_, command.prn);
      if (!c || !s || !c->has_carrier_rate || !(c->cn0_dbhz >= opt_.coast_cn0_dbhz) ||
          !(c->carrier_rate_window_s > 0.0))
        continue;
      const double t_u = nominal_.nav.t_s;
      const double command_span = t_u - command.t_start_s;
      const double slope = command_span > 0.0 ? (s->range_rate_mps - command.range_rate_mps) / command_span : 0.0;
      CarrierRateRow row;
      row.sat = *s;
      row.rate_at_update_mps = c->carrier_rate_mps + slope * (t_u - c->carrier_rate_t_mid_s);
      row.predicted_rate_mps = predicted_range_rate_mps(*s, r_ant, v_ant, nominal_.clock_drift_mps);
      row.phase_noise_var_m2ps2 = c->carrier_rate_var_m2ps2 + opt_.carrier_rate_floor_mps * opt_.carrier_rate_floor_mps;
      // The clock's random-walk FM between the window and now: its mean over the window against the drift now.
      const double half = 0.5 * c->carrier_rate_window_s;
      const double v = opt_.model.clock.drift_psd_m2_per_s3 *
                       (std::max(0.0, t_u - c->carrier_rate_t_mid_s - half) + c->carrier_rate_window_s / 3.0);
      const ReplicaErrors17 rep(nominal_, {*s}, opt_.lever_arm_b, imu_steps_.w_ib_b);
      const Eigen::Matrix<double, 1, 17> J = rep.jacobian().row(1);
      const double S = J * P * J.transpose() + row.phase_noise_var_m2ps2 + v;
      const double y = row.predicted_rate_mps - row.rate_at_update_mps;
      if (!(y * y <= opt_.carrier_rate_screen_sigma * opt_.carrier_rate_screen_sigma * S)) {
        ++counters.rate_screened;
        continue;
      }
      common_var = std::max(common_var, v);
      rows.push_back(row);
    }
    if (rows.empty()) return;
    ++counters.rate_updates;
    counters.rate_rows += static_cast<long long>(rows.size());
    if (apply(padded(CarrierRateMeasurement(nominal_, rows, opt_.lever_arm_b, imu_steps_.w_ib_b, common_var))).accepted)
      ++counters.rate_accepted;
  }

  NominalState nominal() const override { return nominal_; }
  Eigen::MatrixXd covariance() const override { return P17(); }
  // The INS-and-clock block; with the odometer states theirs is kept and the cross terms dropped (a block-diagonal
  // of two covariances is one).
  void set_covariance(const Eigen::MatrixXd& P) override {
    StateMatrix<N> full = StateMatrix<N>::Zero();
    full.template topLeftCorner<17, 17>() = P;
    if constexpr (kOdometer) full.template bottomRightCorner<4, 4>() = filter_.P().template bottomRightCorner<4, 4>();
    filter_.set_P(full);
    fill_output();
  }

 private:
  static Model make_model(const UltraTightOptions& o) {
    if constexpr (kOdometer)
      return Model(o.model, o.odometer);
    else
      return Model(o.model);
  }
  StateMatrix<17> P17() const { return filter_.P().template topLeftCorner<17, 17>(); }
  // A model written for the 17 INS-and-clock states, as the filter of N states takes it.
  template <class M>
  static auto padded(M m) {
    if constexpr (N == 17)
      return m;
    else
      return PaddedMeasurement<M, 17, N>(std::move(m));
  }

  // Satellites above the mask predicted from the current nominal (antenna position, clock): two passes of
  // the transmit-time iteration through prepare_satellites, the pseudorange and rate then being predictions.
  void predict_satellites(std::vector<SatelliteObservable>& out) const {
    const Eigen::Vector3d r_ant = antenna_position_e(nominal_.nav, opt_.lever_arm_b);
    receiver::ObservationEpoch epoch;
    epoch.receive_time = signals::add_seconds(opt_.gps_time_origin, nominal_.nav.t_s + nominal_.clock_bias_m / kC);
    // One observation per PRN: ephemerides may hold several sets of a satellite (a day's RINEX: ~12), and
    // prepare_satellites picks the set valid at the transmit time.
    std::set<int> prns;
    for (const auto& e : eph_) prns.insert(e.prn);
    for (const int prn : prns) {
      receiver::Observation ob;
      ob.prn = prn;
      ob.pseudorange_m = 0.075 * kC + nominal_.clock_bias_m;
      ob.doppler_hz = 0.0;
      epoch.observations.push_back(ob);
    }
    TightOptions t = opt_.tight;
    t.use_range_rate = true;
    for (int pass = 0; pass < 2; ++pass) {
      out = prepare_satellites(epoch, eph_, opt_.iono, r_ant, t);
      epoch.observations.clear();
      for (const auto& s : out) {
        receiver::Observation ob;
        ob.prn = s.prn;
        ob.pseudorange_m = predicted_pseudorange_m(s, r_ant, nominal_.clock_bias_m);
        ob.doppler_hz = 0.0;
        epoch.observations.push_back(ob);
      }
    }
    predict_ranges(out);
  }

  // Pseudorange and rate of each satellite from the current nominal (antenna position/velocity, clock).
  void predict_ranges(std::vector<SatelliteObservable>& sats) const {
    const Eigen::Vector3d r_ant = antenna_position_e(nominal_.nav, opt_.lever_arm_b);
    const Eigen::Vector3d v_ant = ins::C_en(nominal_.nav.lat_rad, nominal_.nav.lon_rad) *
                                  antenna_velocity_n(nominal_.nav, imu_steps_.w_ib_b, opt_.lever_arm_b);
    for (auto& s : sats) {
      s.pseudorange_m = predicted_pseudorange_m(s, r_ant, nominal_.clock_bias_m);
      s.range_rate_mps = predicted_range_rate_mps(s, r_ant, v_ant, nominal_.clock_drift_mps);
      s.has_rate = true;
    }
  }

  // The receiver clock's frequency inside the period is not the drift state at its end: the white FM (phase
  // random walk, PSD S_b) adds a mean phase whose rate equivalent has variance 4 S_b / (3 T), the random-walk
  // FM (S_d) a difference between the T/3-weighted drift and the end drift of variance 8 S_d T / 15. That
  // error is common to the satellites of the period (finish_period).
  double clock_rate_noise_var(double T) const {
    if (!(T > 0.0)) return 0.0;
    const ClockNoiseModel& c = opt_.model.clock;
    return 4.0 * c.bias_psd_m2_per_s / (3.0 * T) + 8.0 * c.drift_psd_m2_per_s3 * T / 15.0;
  }

  // After the period's updates on x' = x + u e (e ~ N(0, v), Cov(x, e) = c0; prior covariance
  // P' = P + v u u' + u c0' + c0 u'): the measurements depend on x' alone, so e given the data is e given x'.
  // With g = Cov(x', e) = c0 + v u and w = P'^-1 g: E[e | x'] = w' x', Var(e | x') = v - g' w. With the
  // posterior x' (mean delta = the period's corrections, covariance P'_post): mean m = w' delta, variance
  // v - g' w + w' P'_post w, Cov(x', e) = P'_post w. The state is x = x' - u e: the nominal's drift loses m,
  // P = P'_post - c u' - u c' + var u u' (c = P'_post w). With no update this returns P exactly.
  void end_common_clock(const StateMatrix<N>& P_prime, double v, const StateVector<N>& c0) {
    StateVector<N> u = StateVector<N>::Zero();
    u(ix::kClockDrift) = 1.0;
    const StateVector<N> g = c0 + v * u;
    const StateVector<N> w = P_prime.ldlt().solve(g);
    const StateMatrix<N> P_post = filter_.P();
    double m = w.template head<17>().dot(period_dx_);
    if constexpr (kOdometer) m += w.template tail<4>().dot(period_odometer_dx_);
    const double var = std::max(0.0, v - g.dot(w) + w.dot(P_post * w));
    const StateVector<N> c = P_post * w;
    StateMatrix<N> P = P_post - c * u.transpose() - u * c.transpose() + var * u * u.transpose();
    filter_.set_P(0.5 * (P + P.transpose()));
    if (m != 0.0) {
      nominal_ = corrected<17>(nominal_, StateVector<17>(-m * u.template head<17>()));
      ins_.set_state(nominal_.nav);
    }
  }

  void propagate() { imu_steps_.predict(filter_, model_, nominal_.nav); }

  // One filter update; when accepted, its correction goes into the nominal and the INS (closed loop).
  template <class M>
  UpdateResult apply(const M& m) {
    const UpdateResult r = filter_.update(m);
    if (!r.accepted) return r;
    last_dx_ = filter_.x().template head<17>();
    period_dx_ += last_dx_;
    const Eigen::Quaterniond q_before = nominal_.nav.q_nb;
    nominal_ = corrected<17>(nominal_, last_dx_);
    filter_.set_P(reset_bias_frame<N>(filter_.P(), q_before, nominal_.nav.q_nb));
    if constexpr (kOdometer) {
      const Eigen::Vector4d dx_odometer = filter_.x().template tail<4>();
      period_odometer_dx_ += dx_odometer;
      odometer_ = corrected(odometer_, dx_odometer);
    }
    ins_.set_state(nominal_.nav);
    filter_.set_x(StateVector<N>::Zero());
    return r;
  }

  // A satellite's I&Q or discriminator update, counted (counters.updates, accepted, rejected).
  template <class M>
  bool update(const M& m) {
    ++counters.updates;
    last_result_ = apply(m);
    ++(last_result_.accepted ? counters.accepted : counters.rejected);
    return last_result_.accepted;
  }

  void fill_output() {
    IntegrationOutput& o = output;
    const StateVector<N> sd = filter_.P().diagonal().cwiseMax(0.0).cwiseSqrt();
    set_ins_output<N>(o, nominal_, sd);
    o.clock_bias_m = nominal_.clock_bias_m;
    o.clock_drift_mps = nominal_.clock_drift_mps;
    o.sigma_clock_bias_m = sd(ix::kClockBias);
    o.sigma_clock_drift_mps = sd(ix::kClockDrift);
    if constexpr (kOdometer) {
      o.odometer.value = odometer_;
      o.odometer.sigma = {sd(17), sd(18), sd(19), sd(20)};
    }
  }

  UltraTightOptions opt_;
  std::vector<signals::Ephemeris> eph_;
  ins::Strapdown ins_;
  Model model_;
  Filter filter_;
  NominalState nominal_;
  std::vector<SatelliteObservable> sats_start_;
  std::vector<SatelliteObservable> now_;  // finish_period's satellites at now_t_s_ (before its updates)
  bool now_valid_ = false;
  double now_t_s_ = 0.0;
  std::map<int, ChannelState> channels_;
  double T_ = 0.020;
  ImuStepAccumulator imu_steps_;
  UpdateResult last_result_;
  StateVector<17> last_dx_ = StateVector<17>::Zero();             // the correction of the latest accepted update
  StateVector<17> period_dx_ = StateVector<17>::Zero();           // the corrections of this period's updates, summed
  Eigen::Vector4d period_odometer_dx_ = Eigen::Vector4d::Zero();  // ... of the odometer states
  OdometerNominal odometer_;                                      // odometer aiding (21 states)
  OdometerHistory history_;
};

// The core of N = 17 or 21 states with the options' filter (EKF or UKF), started at `initial` with covariance P0.
template <int N>
std::unique_ptr<UltraTightCoreBase> make_core(const ins::NavState& initial, std::vector<signals::Ephemeris> eph,
                                              const UltraTightOptions& options, const StateMatrix<N>& P0) {
  const StateVector<N> x0 = StateVector<N>::Zero();
  const Discretisation d = options.model.discretisation;
  if (options.filter == FilterKind::Ekf)
    return std::make_unique<UltraTightCore<Ekf<N>>>(initial, std::move(eph), options,
                                                    Ekf<N>(x0, P0, EkfOptions{d, options.gate}));
  return std::make_unique<UltraTightCore<Ukf<N>>>(initial, std::move(eph), options,
                                                  Ukf<N>(x0, P0, UkfOptions{options.ukf, d, options.gate}));
}
extern template std::unique_ptr<UltraTightCoreBase> make_core<17>(const ins::NavState&, std::vector<signals::Ephemeris>,
                                                                  const UltraTightOptions&, const StateMatrix<17>&);
extern template std::unique_ptr<UltraTightCoreBase> make_core<21>(const ins::NavState&, std::vector<signals::Ephemeris>,
                                                                  const UltraTightOptions&, const StateMatrix<21>&);

}  // namespace ultratrack::fusion::ultratight_detail
