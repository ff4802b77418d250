// SPDX-License-Identifier: GPL-3.0-or-later
// The GNSS/INS filter core's template (gnss_ins_core.hpp): included only by the gnss_ins_core_<layout>.cpp files,
// each of which compiles one layout.
#pragma once

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include "fusion/bias_frame_reset.hpp"
#include "fusion/gnss_ins_core.hpp"
#include "fusion/odometer_history.hpp"
#include "ins/attitude.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion::gnss_ins_detail {

inline constexpr double kTimeEpsilon_s = 1e-9;    // measurement this close to the INS time: applied there
inline constexpr std::size_t kMaxRecords = 8192;  // update records kept when nobody takes them (oldest half dropped)

inline bool finite(const Pending& p) {
  if (const auto* f = std::get_if<PendingFix>(&p)) {
    const GnssFix& x = f->fix;
    const bool pos_ok =
        !x.has_position || (std::isfinite(x.lat_rad) && std::isfinite(x.lon_rad) && std::isfinite(x.height_m) &&
                            (x.sigma_pos_ned_m.array() > 0.0).all() && x.sigma_pos_ned_m.allFinite());
    const bool vel_ok = !x.has_velocity || (x.v_n_mps.allFinite() && (x.sigma_vel_n_mps.array() > 0.0).all() &&
                                            x.sigma_vel_n_mps.allFinite());
    return pos_ok && vel_ok;
  }
  if (const auto* a = std::get_if<PendingAttitude>(&p)) {
    const GnssAttitude& x = a->attitude;
    return std::isfinite(x.euler_a.roll_rad) && std::isfinite(x.euler_a.pitch_rad) &&
           std::isfinite(x.euler_a.yaw_rad) && x.sigma_euler_rad.allFinite() && (x.sigma_euler_rad.array() > 0.0).all();
  }
  if (const auto* o = std::get_if<PendingOdometer>(&p))
    return std::isfinite(o->speed.speed_mps) && std::isfinite(o->speed.window_s) && o->speed.window_s > 0.0;
  return true;  // observation epochs: prepare_satellites skips non-finite pseudoranges
}

template <class L>
using BaseModelFor =
    std::conditional_t<L::kHasTerrain, TerrainAugmentedModel,
                       std::conditional_t<L::kHasOdometer, OdometerAugmentedModel<L::kNav>, InsErrorModel<L::kNav>>>;
template <class L>
using ProcessModelFor =
    std::conditional_t<L::kHasFixError, FixErrorAugmentedModel<BaseModelFor<L>, L::kBase>, BaseModelFor<L>>;

// A measurement model written for NIn states (the INS/clock errors unless said), as the filter of L::N takes it.
template <class L, int NIn = L::kNav, class M>
auto for_filter(M m) {
  if constexpr (L::N == NIn)
    return m;
  else
    return PaddedMeasurement<M, NIn, L::N>(std::move(m));
}

template <class L, class Filter>
class Core final : public CoreBase {
  static constexpr int N = L::N;
  static constexpr int kNav = L::kNav;
  static constexpr bool kClock = L::kHasClock;

 public:
  Core(const ins::NavState& initial, const IntegrationOptions& opt, Filter filter)
      : opt_(opt),
        ins_(initial, opt.strapdown),
        model_(make_model(opt)),
        filter_(std::move(filter)),
        monitor_(opt.recovery) {
    nominal_.nav = ins_.state();
    nominal_.accel_bias_b = opt.initial_accel_bias_b;
    nominal_.gyro_bias_b = opt.initial_gyro_bias_b;
    if constexpr (L::kHasTerrain) {
      if (opt.height_aiding.fixed_height_m) {
        terrain_ref_m_ = terrain_m_ = *opt.height_aiding.fixed_height_m;  // P0: sigma_t^2, uncorrelated
      } else {
        hold_terrain();
      }
    }
    if constexpr (kClock) {
      nominal_.clock_bias_m = opt.initial_clock_bias_m;
      nominal_.clock_drift_mps = opt.initial_clock_drift_mps;
    }
    InsLinearisation lin;
    lin.nav = nominal_.nav;
    lin.f_b = nominal_.nav.q_nb.conjugate() * Eigen::Vector3d(0.0, 0.0, -9.80665);
    model_.set_linearisation(lin);
    fill_output();
  }

  void add_pending(double t_s, Pending p) override {
    if (!std::isfinite(t_s) || !finite(p)) {
      ++counters.invalid;
      return;
    }
    const bool attitude = std::holds_alternative<PendingAttitude>(p);
    if (t_s < nominal_.nav.t_s - kTimeEpsilon_s) {
      ++counters.late;
      if (attitude) ++counters.attitude_late;
      return;
    }
    if (t_s <= nominal_.nav.t_s + kTimeEpsilon_s) {
      apply(p);
      fill_output();
      return;
    }
    // At equal times an attitude goes before the fixes already queued there (it counts for their fallback).
    if (attitude)
      pending_.emplace_hint(pending_.lower_bound(t_s), t_s, std::move(p));
    else
      pending_.emplace(t_s, std::move(p));
  }

  void add_imu(const ins::ImuIncrement& inc) override {
    double t = nominal_.nav.t_s;
    if (!(inc.t_s > t) || !std::isfinite(inc.t_s) || !inc.dtheta_b.allFinite() || !inc.dv_b.allFinite()) {
      ++counters.invalid;
      return;
    }
    ++counters.imu_steps;
    Eigen::Vector3d dth = inc.dtheta_b, dv = inc.dv_b;  // raw, still to be applied over (t, inc.t_s]
    while (!pending_.empty() && pending_.begin()->first <= inc.t_s + kTimeEpsilon_s) {
      auto node = pending_.extract(pending_.begin());
      const double t_m = std::min(node.key(), inc.t_s);
      if (t_m > t + kTimeEpsilon_s) {
        const double s = (t_m - t) / (inc.t_s - t);  // increments shared in proportion to time
        ins_step(s * dth, s * dv, t_m - t);
        dth *= 1.0 - s;
        dv *= 1.0 - s;
        t = t_m;
      }
      apply(node.mapped());
    }
    if (inc.t_s - t > kTimeEpsilon_s) ins_step(dth, dv, inc.t_s - t);
    if constexpr (!L::kHasTerrain) {
      if (opt_.land.nhc && nominal_.nav.t_s - last_nhc_t_s_ >= opt_.land.nhc_interval_s - kTimeEpsilon_s) {
        last_nhc_t_s_ = nominal_.nav.t_s;
        propagate();
        ++(update(for_filter<L>(NhcMeasurement<kNav>(nominal_, imu_steps_.w_ib_b, opt_.land)), -3)
               ? counters.nhc_accepted
               : counters.nhc_rejected);
      }
    }
    fill_output();
  }

  NominalState nominal() const override { return nominal_; }
  Eigen::MatrixXd covariance() const override { return filter_.P().template topLeftCorner<kNav, kNav>(); }

 private:
  void ins_step(const Eigen::Vector3d& dth_raw, const Eigen::Vector3d& dv_raw, double dt) {
    const Eigen::Vector3d dth = dth_raw - nominal_.gyro_bias_b * dt;
    const Eigen::Vector3d dv = dv_raw - nominal_.accel_bias_b * dt;
    const Eigen::Quaterniond q0 = ins_.state().q_nb;
    ins_.step(dth, dv, dt);
    nominal_.nav = ins_.state();
    if constexpr (kClock) nominal_.clock_bias_m += nominal_.clock_drift_mps * dt;
    if constexpr (L::kHasTerrain)  // the nominal terrain follows the Gauss-Markov mean back to the reference
      terrain_m_ =
          terrain_ref_m_ + (terrain_m_ - terrain_ref_m_) * std::exp(-dt / opt_.height_aiding.terrain_correlation_s);
    imu_steps_.add(q0, nominal_.nav.q_nb, dth, dv, dt);
    if constexpr (L::kHasFixError)
      fix_error_n_ = propagate_fix_error(fix_error_n_, dt, opt_.fix_error.correlation_time_s);
    if constexpr (L::kHasOdometer) history_.record(nominal_.nav, 1.0 / opt_.odometer.update_rate_hz + 1.0);
    if (imu_steps_.dt_s >= opt_.propagation_interval_s) propagate();
  }

  void propagate() { imu_steps_.predict(filter_, model_, nominal_.nav); }

  template <class M>
  bool update(const M& m, int prn) {
    const UpdateResult r = filter_.update(m);
    if (records.size() >= kMaxRecords) records.erase(records.begin(), records.begin() + kMaxRecords / 2);
    records.push_back(UpdateRecord{nominal_.nav.t_s, prn, r});
    if (!r.accepted) {
      ++counters.rejected;
      return false;
    }
    ++counters.accepted;
    // Closed loop: fold the estimated errors into the nominal (INS, IMU compensation, clock, terrain, odometer,
    // fix error), reset.
    const Eigen::Quaterniond q_before = nominal_.nav.q_nb;
    nominal_ = corrected<kNav>(nominal_, filter_.x().template head<kNav>());
    filter_.set_P(reset_bias_frame<N>(filter_.P(), q_before, nominal_.nav.q_nb));
    if constexpr (L::kHasTerrain) terrain_m_ -= filter_.x()(ix::kTerrain);
    if constexpr (L::kHasOdometer)
      odometer_ = corrected(odometer_, Eigen::Vector4d(filter_.x().template segment<4>(L::kOdo)));
    if constexpr (L::kHasFixError) fix_error_n_ -= filter_.x().template segment<3>(L::kFix);
    ins_.set_state(nominal_.nav);
    filter_.set_x(StateVector<N>::Zero());
    return true;
  }

  void apply(const Pending& p) {
    propagate();  // covariance up to the measurement time
    if (const auto* o = std::get_if<PendingOdometer>(&p)) {
      if constexpr (L::kHasOdometer) apply_odometer(o->speed);
      return;
    }
    if (const auto* a = std::get_if<PendingAttitude>(&p)) {
      ++counters.attitude_epochs;
      if (!attitude_usable(a->attitude, opt_.attitude)) {
        ++counters.attitude_unusable;
        return;
      }
      if (update(for_filter<L>(AttitudeMeasurement<kNav>(nominal_, a->attitude, opt_.attitude)), -1)) {
        ++counters.attitude_accepted;
        attitude_since_fix_ = true;
      } else {
        ++counters.attitude_rejected;
      }
      return;
    }
    double fix_variance_factor = 1.0;
    if (const auto* f = std::get_if<PendingFix>(&p)) {
      const double since_last = f->fix.t_s - last_fix_t_s_;
      if (opt_.fix_min_interval_s > 0.0 && since_last < opt_.fix_min_interval_s - kTimeEpsilon_s) {
        ++counters.fixes_skipped;
        return;
      }
      if (opt_.fix_error_correlation_s > 0.0)
        fix_variance_factor = 1.0 + 2.0 * opt_.fix_error_correlation_s / std::max(since_last, 1e-3);
      last_fix_t_s_ = f->fix.t_s;
    }
    ++counters.epochs;
    if (!attitude_since_fix_) ++counters.fixes_without_attitude;
    attitude_since_fix_ = false;
    if (const auto* f = std::get_if<PendingFix>(&p)) {
      if constexpr (!L::kHasClock) {
        if (f->fix.has_position || f->fix.has_velocity) {
          GnssFix fix = f->fix;
          fix.sigma_pos_ned_m *= std::sqrt(fix_variance_factor);
          if constexpr (L::kHasFixError) fix.sigma_pos_ned_m = fix_white_sigma(fix.sigma_pos_ned_m, opt_.fix_error);
          const bool accepted = update_fix(fix);
          ++(accepted ? counters.fix_accepted : counters.fix_rejected);
          const UpdateResult r = records.back().result;
          if (auto event = monitor_.observe(nominal_.nav.t_s, accepted, r.nis, r.dof)) {
            const int pos_rows = fix.has_position ? 3 : 0;
            const Eigen::Vector3d dp = pos_rows ? Eigen::Vector3d(r.innovation.head<3>()) : Eigen::Vector3d::Zero();
            std::optional<Eigen::Vector3d> dv;
            if (fix.has_velocity) dv = r.innovation.segment<3>(pos_rows);
            recover(*event, dp, dv, std::nullopt);
            // The fix that tripped the monitor, again through the opened filter (counted as accepted if it passes).
            if (!accepted && update_fix(fix)) ++counters.fix_accepted;
          }
        }
      }
      return;
    }
    if constexpr (kClock) {
      const auto& e = std::get<PendingEpoch>(p);
      PrepareStats stats;
      const auto sats = prepare_satellites(e.epoch, e.ephemerides, e.iono,
                                           antenna_position_e(nominal_.nav, opt_.lever_arm_b), opt_.tight, &stats);
      counters.satellites_missing_ephemeris += stats.missing_ephemeris;
      const HeightAidingOptions& ha = opt_.height_aiding;
      const bool few = static_cast<int>(sats.size()) < ha.min_satellites;
      if (few) ++counters.epochs_few_satellites;
      // Height first: the satellites' rows are then linearised about the aided height.
      // (0.99: epochs come on the receiver clock, slightly off 1 s in true time.)
      if constexpr (L::kHasTerrain) {
        if (few && nominal_.nav.t_s - last_aid_t_s_ >= 0.99 * ha.min_interval_s) {
          last_aid_t_s_ = nominal_.nav.t_s;
          if (update(TerrainHeightMeasurement(nominal_, terrain_m_, ha.sigma0_m), -2))
            ++counters.height_accepted;
          else
            ++counters.height_rejected;
        }
      }
      const EpochUpdates u = update_satellites(sats);
      if (!sats.empty()) {
        if (auto event = monitor_.observe(nominal_.nav.t_s, u.any_accepted, u.nis, u.dof)) {
          const double rms = std::sqrt(u.range_innovation2 / static_cast<double>(sats.size()));
          recover(*event, Eigen::Vector3d::Constant(rms), std::nullopt, rms);
          // This epoch again, through the opened filter (linearised about the current nominal).
          update_satellites(prepare_satellites(e.epoch, e.ephemerides, e.iono,
                                               antenna_position_e(nominal_.nav, opt_.lever_arm_b), opt_.tight));
        }
      }
      if constexpr (L::kHasTerrain) {  // full geometry: this epoch's height is the terrain reference from now on
        if (!few && !ha.fixed_height_m) hold_terrain();
      }
    }
  }

  // One loose fix update (position rows with the fix-error states when the filter carries them).
  bool update_fix(const GnssFix& fix) {
    auto m = for_filter<L>(LooseMeasurement<kNav>(nominal_, fix, opt_.lever_arm_b, imu_steps_.w_ib_b));
    if constexpr (L::kHasFixError)
      return update(FixErrorMeasurement<decltype(m), N, L::kFix>(std::move(m), fix.has_position, fix_error_n_), 0);
    else
      return update(m, 0);
  }

  void fill_output() {
    IntegrationOutput& o = output;
    const StateVector<N> sd = filter_.P().diagonal().cwiseMax(0.0).cwiseSqrt();
    set_ins_output<N>(o, nominal_, sd);
    if constexpr (L::kHasTerrain) {
      o.terrain_height_m = terrain_m_;
      o.sigma_terrain_height_m = sd(ix::kTerrain);
    }
    if constexpr (L::kHasOdometer) {
      o.odometer.value = odometer_;
      o.odometer.sigma = {sd(L::kOdo), sd(L::kOdo + 1), sd(L::kOdo + 2), sd(L::kOdo + 3)};
    }
    if constexpr (L::kHasFixError) {
      o.fix_error_ned_m = fix_error_n_;
      o.sigma_fix_error_ned_m = sd.template segment<3>(L::kFix);
    }
    if constexpr (kClock) {
      o.clock_bias_m = nominal_.clock_bias_m;
      o.clock_drift_mps = nominal_.clock_drift_mps;
      o.sigma_clock_bias_m = sd(ix::kClockBias);
      o.sigma_clock_drift_mps = sd(ix::kClockDrift);
    }
  }

  static BaseModelFor<L> make_base_model(const IntegrationOptions& o) {
    if constexpr (L::kHasTerrain)
      return TerrainAugmentedModel(o.model, o.height_aiding);
    else if constexpr (L::kHasOdometer)
      return OdometerAugmentedModel<kNav>(o.model, o.odometer);
    else
      return InsErrorModel<kNav>(o.model);
  }
  static ProcessModelFor<L> make_model(const IntegrationOptions& o) {
    if constexpr (L::kHasFixError)
      return ProcessModelFor<L>(make_base_model(o), o.fix_error, o.model.discretisation);
    else
      return make_base_model(o);
  }

  // One epoch's satellite updates, and what the lock-out monitor needs of them.
  struct EpochUpdates {
    bool any_accepted = false;
    double nis = 0.0, range_innovation2 = 0.0;
    int dof = 0;
  };
  EpochUpdates update_satellites(const std::vector<SatelliteObservable>& sats) {
    EpochUpdates u;
    for (const auto& s : sats) {
      u.any_accepted |= update(for_filter<L>(SatelliteMeasurement17(nominal_, s, opt_.lever_arm_b, imu_steps_.w_ib_b,
                                                                    opt_.tight.use_range_rate)),
                               s.prn);
      const UpdateResult& r = records.back().result;
      u.nis += std::isfinite(r.nis) ? r.nis : 1e6;
      u.dof += r.dof;
      if (r.innovation.size() > 0) u.range_innovation2 += r.innovation(0) * r.innovation(0);
    }
    return u;
  }

  // Lock-out recovery: open the covariance of what the measurements observe, log the event.
  void recover(const RecoveryEvent& event, const Eigen::Vector3d& dp, const std::optional<Eigen::Vector3d>& dv,
               std::optional<double> clock_innovation_m) {
    ++counters.recoveries;
    recovery_events.push_back(event);
    const double span = opt_.recovery.min_span_s;
    const Eigen::MatrixXd P = inflate_for_recovery(filter_.P(), dp, dv, span, opt_.recovery, clock_innovation_m);
    filter_.set_P(P);
  }

  // The INS height becomes the terrain reference; the terrain error is the negative INS down error.
  void hold_terrain() {
    if constexpr (L::kHasTerrain) {
      StateMatrix<18> P = filter_.P();
      hold_terrain_at_ins_height(P, opt_.height_aiding.sigma0_m);
      filter_.set_P(P);
      StateVector<18> x = filter_.x();
      x(ix::kTerrain) = -x(ix::kPos + 2);
      filter_.set_x(x);
      terrain_ref_m_ = terrain_m_ = nominal_.nav.height_m;
    }
  }

  // One odometer window ([KimVMS] eqs. 11-17): the gate of eqs. 16-17, then the VMS/NHC update.
  void apply_odometer(const OdometerSpeed& speed) {
    if constexpr (L::kHasOdometer) {
      const auto w = history_.gated_window(nominal_.nav, speed, opt_.odometer, counters.odometer);
      if (!w) return;
      VmsMeasurement m(nominal_, odometer_, imu_steps_.w_ib_b, w->a_b, speed, opt_.odometer);
      bool accepted;
      if constexpr (L::kOdo == ix::kOdoDelay)
        accepted = update(for_filter<L, 19>(std::move(m)), -4);
      else
        accepted = update(OdometerStatesAt<VmsMeasurement, L::kOdo, N>(std::move(m)), -4);
      ++(accepted ? counters.odometer.accepted : counters.odometer.rejected);
    }
  }

  IntegrationOptions opt_;
  ins::Strapdown ins_;
  ProcessModelFor<L> model_;
  Filter filter_;
  NominalState nominal_;
  std::multimap<double, Pending> pending_;
  ImuStepAccumulator imu_steps_;
  LockoutMonitor monitor_;
  bool attitude_since_fix_ = false;
  // Height aiding (18 states): the terrain nominal and its Gauss-Markov mean (the held or configured height).
  double terrain_m_ = 0.0, terrain_ref_m_ = 0.0;
  double last_aid_t_s_ = -1e300;
  double last_nhc_t_s_ = -1e300;
  double last_fix_t_s_ = -1e300;
  OdometerNominal odometer_;
  Eigen::Vector3d fix_error_n_ = Eigen::Vector3d::Zero();  // Gauss-Markov fix error estimate, NED [m]
  OdometerHistory history_;  // odometer aiding: the INS heading and velocity over the last windows
};

template <class L>
std::unique_ptr<CoreBase> make_core(const ins::NavState& initial, const IntegrationOptions& o) {
  constexpr int N = L::N;
  InsErrorModelOptions mo = o.model;
  mo.discretisation = o.discretisation;
  IntegrationOptions oo = o;
  oo.model = mo;
  StateMatrix<L::kBase> P_base;
  if constexpr (L::kHasTerrain)
    P_base = TerrainAugmentedModel(mo, o.height_aiding)
                 .initial_covariance(o.sigma_pos_ned_m, o.sigma_vel_n_mps, o.sigma_att_rad);
  else if constexpr (L::kHasOdometer)
    P_base = OdometerAugmentedModel<L::kNav>(mo, o.odometer)
                 .initial_covariance(o.sigma_pos_ned_m, o.sigma_vel_n_mps, o.sigma_att_rad);
  else
    P_base = InsErrorModel<L::kNav>(mo).initial_covariance(o.sigma_pos_ned_m, o.sigma_vel_n_mps, o.sigma_att_rad);
  StateMatrix<N> P0;
  if constexpr (L::kHasFixError)
    P0 = with_fix_error_states<L::kBase>(P_base, o.fix_error);
  else
    P0 = P_base;
  // Biases from an alignment: their own 1-sigma (cross terms with the other states stay zero).
  if (o.sigma_initial_accel_bias_b)
    P0.template block<3, 3>(ix::kAccelBias, ix::kAccelBias) = o.sigma_initial_accel_bias_b->cwiseAbs2().asDiagonal();
  if (o.sigma_initial_gyro_bias_b)
    P0.template block<3, 3>(ix::kGyroBias, ix::kGyroBias) = o.sigma_initial_gyro_bias_b->cwiseAbs2().asDiagonal();
  if (!o.attitude_per_bias.isZero()) correlate_attitude_with_biases<N>(P0, o.attitude_per_bias);
  const StateVector<N> x0 = StateVector<N>::Zero();
  if (o.filter == FilterKind::Ekf)
    return std::make_unique<Core<L, Ekf<N>>>(initial, oo, Ekf<N>(x0, P0, EkfOptions{o.discretisation, o.gate}));
  return std::make_unique<Core<L, Ukf<N>>>(initial, oo, Ukf<N>(x0, P0, UkfOptions{o.ukf, o.discretisation, o.gate}));
}

}  // namespace ultratrack::fusion::gnss_ins_detail
