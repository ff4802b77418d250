#include "fusion/ultratight_integration.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "ins/earth_model.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;
constexpr double kLambda_m = signals::kL1Wavelength_m;
constexpr double kChip_m = kC / signals::kCaChipRate_hz;

// The replica errors of a hypothesis dx over the period that ended at the update time: the nominal's errors
// at that time (range e0, rate e1) seen over the period (mean range: a rate error e1 held over the period
// moves the mean range by -e1 span / 2) plus the known offset of the replica that ran from the nominal
// (period_replica_errors), so h(dx) describes the replica that really ran.
Eigen::Matrix2d period_mixing(double span_s) {
  Eigen::Matrix2d M = Eigen::Matrix2d::Identity();
  M(0, 1) = -0.5 * span_s;
  return M;
}

// One satellite's I&Q (6 rows) over the period with the replica actually held.
class PeriodIqMeasurement {
 public:
  static constexpr int kMeasurementSize = kIqRowsPerChannel;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  PeriodIqMeasurement(const NominalState& nominal, const SatelliteObservable& sat, const Eigen::Vector3d& lever_b,
                      const Eigen::Vector3d& w_ib_b, const IqSettings& s, const Eigen::Vector2d& offset,
                      double span_s, const IqTaps& measured, double prior_code_sigma_chips, double rate_noise_var,
                      double start_phase_rad, double start_phase_var)
      : replica_(nominal, {sat}, lever_b, w_ib_b), s_(s), offset_(offset), M_(period_mixing(span_s)),
        R_(iq_noise_covariance(s)),
        code_sigma_(prior_code_sigma_chips), start_phase_(start_phase_rad) {
    // Frequency noise of the receiver clock within the period (common to every satellite; see finish_period)
    // enters the taps through their frequency derivative.
    if (rate_noise_var > 0.0) {
      const Eigen::Matrix<double, 6, 1> g = iq_jacobian(errors(StateVector<17>::Zero()), s_).col(1) / kLambda_m;
      R_ += rate_noise_var * g * g.transpose();
    }
    // The replica's unknown phase error at the period's start (a closed PLL's residual) turns all six taps.
    if (start_phase_var > 0.0) {
      const Eigen::Matrix<double, 6, 1> g = iq_phase_derivative(errors(StateVector<17>::Zero()), s_);
      R_ += start_phase_var * g * g.transpose();
    }
    for (int k = 0; k < 3; ++k) {
      z_(k) = measured.i[k];
      z_(3 + k) = measured.q[k];
    }
  }
  const Vector6& z() const { return z_; }
  Vector6 h(const StateVector<17>& dx) const {
    const IqTaps t = expected_iq(errors(dx), s_);
    Vector6 out;
    for (int k = 0; k < 3; ++k) {
      out(k) = t.i[k];
      out(3 + k) = t.q[k];
    }
    return out;
  }
  MeasurementJacobian<17> H(const StateVector<17>& dx) const {
    const TrackingErrors te = errors(dx);
    Eigen::Matrix<double, 6, 2> J = iq_jacobian(te, s_);
    // The prompt sits on the triangle's peak, where R = 1 - |tau| has a kink: its local slope (+-1) would
    // claim to measure tau with the sign of the current guess. Statistical linearisation over the prior
    // (tau ~ N(guess, sigma^2)): the expected slope is the local one times erf(|guess| / (sqrt 2 sigma)).
    if (code_sigma_ > 0.0) {
      const double w = std::erf(std::abs(te.code_chips) / (std::sqrt(2.0) * code_sigma_));
      J(1, 0) *= w;
      J(4, 0) *= w;
    }
    const Eigen::Matrix<double, 2, 2> D = Eigen::Vector2d(1.0 / kChip_m, 1.0 / kLambda_m).asDiagonal();
    return J * D * M_ * replica_.jacobian();
  }
  const Eigen::Matrix<double, 6, 6>& R() const { return R_; }

 private:
  TrackingErrors errors(const StateVector<17>& dx) const {
    const Eigen::Vector2d e = M_ * replica_.errors(0, dx) + offset_;
    TrackingErrors te = tracking_errors(e(0), e(1));
    te.phase_rad = start_phase_;
    return te;
  }
  ReplicaErrors17 replica_;
  IqSettings s_;
  Eigen::Vector2d offset_;
  Eigen::Matrix2d M_;
  Vector6 z_;
  Eigen::Matrix<double, 6, 6> R_;
  double code_sigma_ = 0.0;
  double start_phase_ = 0.0;
};

// Discriminator form: range and rate errors of the replica that ran, h(dx) = replica errors + offset.
class PeriodDiscriminatorMeasurement {
 public:
  PeriodDiscriminatorMeasurement(const NominalState& nominal, const SatelliteObservable& sat,
                                 const Eigen::Vector3d& lever_b, const Eigen::Vector3d& w_ib_b,
                                 const Eigen::Vector2d& offset, double span_s, const Eigen::Vector2d& measured,
                                 const DiscriminatorNoise& noise, double rate_noise_var, double start_phase_rate_var)
      : replica_(nominal, {sat}, lever_b, w_ib_b), offset_(offset), M_(period_mixing(span_s)), z_(measured),
        R_(Eigen::MatrixXd::Zero(2, 2)) {
    R_(0, 0) = noise.range_sigma_m * noise.range_sigma_m;
    R_(1, 1) = noise.rate_sigma_mps * noise.rate_sigma_mps + rate_noise_var + start_phase_rate_var;
  }
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const { return M_ * replica_.errors(dx) + offset_; }
  MeasurementJacobian<17> H(const StateVector<17>&) const { return M_ * replica_.jacobian(); }
  Eigen::MatrixXd R() const { return R_; }

 private:
  ReplicaErrors17 replica_;
  Eigen::Vector2d offset_;
  Eigen::Matrix2d M_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

void check_options(const UltraTightOptions& o) {
  auto positive = [](const Eigen::Vector3d& v) { return (v.array() > 0.0).all() && v.allFinite(); };
  if (!positive(o.sigma_pos_ned_m) || !positive(o.sigma_vel_n_mps) || !positive(o.sigma_att_rad))
    throw std::invalid_argument("ultra-tight: initial sigmas must be positive");
  if (!(o.tap_offset_chips > 0.0 && o.tap_offset_chips <= 0.5))
    throw std::invalid_argument("ultra-tight: tap offset must lie in (0, 0.5] chip");
  if (!(o.gate.probability > 0.0 && o.gate.probability < 1.0))
    throw std::invalid_argument("ultra-tight: gate probability must lie in (0, 1)");
  if (!std::isfinite(o.coast_cn0_dbhz)) throw std::invalid_argument("ultra-tight: coasting threshold not finite");
  if (std::isnan(o.measurement_mask_rad)) throw std::invalid_argument("ultra-tight: measurement mask is NaN");
}

}  // namespace

struct UltraTightCoreBase {
  virtual ~UltraTightCoreBase() = default;
  virtual void add_imu(const ins::ImuIncrement& inc) = 0;
  virtual void add_ephemerides(const std::vector<signals::Ephemeris>& eph) = 0;
  virtual void start_period(double T) = 0;
  virtual void finish_period(const std::vector<ChannelCorrelation>& c) = 0;
  virtual NominalState nominal() const = 0;
  virtual Eigen::MatrixXd covariance() const = 0;
  std::vector<ReplicaCommand> replicas;
  std::vector<UltraTightSatelliteUpdate> last_updates;
  IntegrationOutput output;
  UltraTightCounters counters;
};

namespace {

struct ChannelState {
  double carrier_phase_cycles = 0.0;
  bool coasting = false;
  // The carrier phase error (signal minus replica, rad) at the end of this channel's last measured epoch, for a
  // continuous-carrier channel (ChannelCorrelation::continuous_carrier): its measured mean phase plus the
  // end-minus-mean phase of the filter's rate-error profile; its variance; the epoch's end time (s).
  bool has_end_phase = false;
  double end_phase_rad = 0.0, end_phase_var_rad2 = 0.0, end_phase_t_s = 0.0;
};

template <class Filter>
class UltraTightCore final : public UltraTightCoreBase {
 public:
  UltraTightCore(const ins::NavState& initial, std::vector<signals::Ephemeris> eph, const UltraTightOptions& o,
                 Filter filter)
      : opt_(o), eph_(std::move(eph)), ins_(initial, o.strapdown), model_(o.model), filter_(std::move(filter)) {
    nominal_.nav = ins_.state();
    nominal_.clock_bias_m = o.initial_clock_bias_m;
    nominal_.clock_drift_mps = o.initial_clock_drift_mps;
    nominal_.accel_bias_b = o.initial_accel_bias_b;
    nominal_.gyro_bias_b = o.initial_gyro_bias_b;
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
    fill_output();
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
      c = nullptr;
      s = nullptr;
      for (const auto& x : corr)
        if (x.prn == prn) c = &x;
      for (const auto& x : now)
        if (x.prn == prn) s = &x;
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
    StateMatrix<17> P_prime;
    StateVector<17> cov_xe = StateVector<17>::Zero();
    if (common_var > 0.0) {
      cov_xe(ix::kClockBias) = opt_.model.clock.bias_psd_m2_per_s;
      cov_xe(ix::kClockDrift) = -2.0 * opt_.model.clock.drift_psd_m2_per_s3 * T_ / 3.0;
      P_prime = filter_.P();
      StateVector<17> u = StateVector<17>::Zero();
      u(ix::kClockDrift) = 1.0;
      P_prime += common_var * u * u.transpose() + u * cov_xe.transpose() + cov_xe * u.transpose();
      filter_.set_P(P_prime);
    }
    period_dx_.setZero();
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
      const double back_end = nominal_.nav.t_s - (r.t_start_s + T_);
      const double command_span = nominal_.nav.t_s - command.t_start_s;
      const double rate_slope = command_span > 0.0 ? (s->range_rate_mps - command.range_rate_mps) / command_span : 0.0;
      const double rate_end = rr_now - rate_slope * back_end;
      const double range_end = pr_now - 0.5 * (rate_end + rr_now) * back_end;
      const Eigen::Vector2d offset = period_replica_errors(r.pseudorange_m, r.range_rate_mps, range_end,
                                                           rate_end - rate_slope * T_, rate_end, T_);
      const double span = 2.0 * (nominal_.nav.t_s - r.t_start_s) - T_;  // the mean range sits span / 2 back
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
        const MeasurementJacobian<17> J = rep.jacobian();
        const Eigen::Matrix<double, 1, 17> h_range = J.row(0) - 0.5 * span * J.row(1);
        const double sigma_code = std::sqrt(std::max(0.0, (h_range * filter_.P() * h_range.transpose())(0, 0))) / kChip_m;
        ok = update(PeriodIqMeasurement(nominal_, *s, opt_.lever_arm_b, imu_steps_.w_ib_b, is, offset, span, c->taps, sigma_code,
                                         clock_rate_var, start_phase, start_phase_var));
      } else {
        // The frequency discriminator reads the mean phase, start phase + pi T f(T / 3): the start phase comes off.
        const double f_hz = frequency_discriminator_hz(c->taps, is) - start_phase / (M_PI * T_);
        const Eigen::Vector2d z(code_discriminator_chips(c->taps, is) * kChip_m, f_hz * kLambda_m);
        ok = update(PeriodDiscriminatorMeasurement(nominal_, *s, opt_.lever_arm_b, imu_steps_.w_ib_b, offset, span, z,
                                                   discriminator_noise(is), clock_rate_var,
                                                   start_phase_var * std::pow(kLambda_m / (M_PI * T_), 2)));
      }
      if (c->continuous_carrier) {
        // This epoch's end phase (after the period's last update, below): its measured mean phase (data wiped:
        // the prompt near the I axis) plus the end-minus-mean phase pi T f(2 T / 3) of the rate-error profile.
        const double theta = std::atan2(c->taps.q[1], c->taps.i[1]);
        const double a2 = std::pow(iq_amplitude(is), 2);
        if (std::abs(theta) < 0.5 * M_PI && a2 > 0.0)
          end_phases.push_back({&ch, rep, offset, theta, (1.0 + 1.0 / a2) / a2, rate_slope * T_, r.t_start_s + T_,
                                dx_before});
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
    fill_output();
  }

  NominalState nominal() const override { return nominal_; }
  Eigen::MatrixXd covariance() const override { return filter_.P(); }

 private:
  // Satellites above the mask predicted from the current nominal (antenna position, clock): two passes of
  // the transmit-time iteration through prepare_satellites, the pseudorange and rate then being predictions.
  void predict_satellites(std::vector<SatelliteObservable>& out) const {
    const Eigen::Vector3d r_ant = antenna_position_e(nominal_.nav, opt_.lever_arm_b);
    receiver::ObservationEpoch epoch;
    epoch.receive_time =
        signals::add_seconds(opt_.gps_time_origin, nominal_.nav.t_s + nominal_.clock_bias_m / kC);
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
    const Eigen::Vector3d v_ant =
        ins::C_en(nominal_.nav.lat_rad, nominal_.nav.lon_rad) * antenna_velocity_n(nominal_.nav, imu_steps_.w_ib_b, opt_.lever_arm_b);
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
  void end_common_clock(const StateMatrix<17>& P_prime, double v, const StateVector<17>& c0) {
    StateVector<17> u = StateVector<17>::Zero();
    u(ix::kClockDrift) = 1.0;
    const StateVector<17> g = c0 + v * u;
    const StateVector<17> w = P_prime.ldlt().solve(g);
    const StateMatrix<17> P_post = filter_.P();
    const double m = w.dot(period_dx_);
    const double var = std::max(0.0, v - g.dot(w) + w.dot(P_post * w));
    const StateVector<17> c = P_post * w;
    StateMatrix<17> P = P_post - c * u.transpose() - u * c.transpose() + var * u * u.transpose();
    filter_.set_P(0.5 * (P + P.transpose()));
    if (m != 0.0) {
      nominal_ = corrected<17>(nominal_, StateVector<17>(-m * u));
      ins_.set_state(nominal_.nav);
    }
  }

  void propagate() {
    if (imu_steps_.dt_s <= 0.0) return;
    model_.set_linearisation(imu_steps_.linearisation(nominal_.nav));
    filter_.predict(model_, imu_steps_.dt_s);
    imu_steps_.clear();
  }

  template <class M>
  bool update(const M& m) {
    ++counters.updates;
    const UpdateResult r = filter_.update(m);
    last_result_ = r;
    if (!r.accepted) {
      ++counters.rejected;
      return false;
    }
    ++counters.accepted;
    last_dx_ = filter_.x();
    period_dx_ += last_dx_;
    nominal_ = corrected<17>(nominal_, filter_.x());
    ins_.set_state(nominal_.nav);
    filter_.set_x(StateVector<17>::Zero());
    return true;
  }

  void fill_output() {
    IntegrationOutput& o = output;
    o.nav = nominal_.nav;
    const StateVector<17> sd = filter_.P().diagonal().cwiseMax(0.0).cwiseSqrt();
    o.sigma_pos_ned_m = sd.segment<3>(ix::kPos);
    o.sigma_vel_n_mps = sd.segment<3>(ix::kVel);
    o.sigma_att_rad = sd.segment<3>(ix::kAtt);
    o.accel_bias_b = nominal_.accel_bias_b;
    o.gyro_bias_b = nominal_.gyro_bias_b;
    o.sigma_accel_bias_b = sd.segment<3>(ix::kAccelBias);
    o.sigma_gyro_bias_b = sd.segment<3>(ix::kGyroBias);
    o.clock_bias_m = nominal_.clock_bias_m;
    o.clock_drift_mps = nominal_.clock_drift_mps;
    o.sigma_clock_bias_m = sd(ix::kClockBias);
    o.sigma_clock_drift_mps = sd(ix::kClockDrift);
  }

  UltraTightOptions opt_;
  std::vector<signals::Ephemeris> eph_;
  ins::Strapdown ins_;
  InsErrorModel<17> model_;
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
  StateVector<17> last_dx_ = StateVector<17>::Zero();  // the correction of the latest accepted update
  StateVector<17> period_dx_ = StateVector<17>::Zero();  // the corrections of this period's updates, summed
};

}  // namespace

struct UltraTightIntegration::Impl {
  UltraTightOptions options;
  std::unique_ptr<UltraTightCoreBase> core;
};

UltraTightIntegration::UltraTightIntegration(const ins::NavState& initial, std::vector<signals::Ephemeris> eph,
                                             const UltraTightOptions& options)
    : impl_(std::make_unique<Impl>()) {
  check_options(options);
  impl_->options = options;
  InsErrorModelOptions mo = options.model;
  mo.discretisation = options.discretisation;
  impl_->options.model = mo;
  const InsErrorModel<17> model(mo);
  const StateMatrix<17> P0 =
      model.initial_covariance(options.sigma_pos_ned_m, options.sigma_vel_n_mps, options.sigma_att_rad);
  const StateVector<17> x0 = StateVector<17>::Zero();
  if (options.filter == FilterKind::Ekf)
    impl_->core = std::make_unique<UltraTightCore<Ekf<17>>>(initial, std::move(eph), impl_->options,
                                                          Ekf<17>(x0, P0, EkfOptions{mo.discretisation, options.gate}));
  else
    impl_->core = std::make_unique<UltraTightCore<Ukf<17>>>(
        initial, std::move(eph), impl_->options, Ukf<17>(x0, P0, UkfOptions{options.ukf, mo.discretisation, options.gate}));
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
const UltraTightCounters& UltraTightIntegration::counters() const { return impl_->core->counters; }
const std::vector<UltraTightSatelliteUpdate>& UltraTightIntegration::last_updates() const {
  return impl_->core->last_updates;
}
const UltraTightOptions& UltraTightIntegration::options() const { return impl_->options; }

}  // namespace ultratrack::fusion
