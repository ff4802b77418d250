// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/vector_tracking.hpp"

#include <algorithm>
#include <cmath>

#include "receiver/vector_frequency_discriminator.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

using signals::kSpeedOfLight_mps;
constexpr double kChip_m = kSpeedOfLight_mps / signals::kCaChipRate_hz;

double ratio_hz(double cn0_dbhz) { return std::pow(10.0, cn0_dbhz / 10.0); }

// The observable dt seconds of receive time later: the satellite (as seen in the receive-time frame) moves at its
// apparent velocity and its clock at its drift; over tens of milliseconds the neglected acceleration terms are
// below a millimetre.
SatelliteObservable shifted(SatelliteObservable sat, double dt) {
  sat.r_sat_e += dt * sat.v_sat_e;
  sat.sv_clock_m += dt * sat.sv_drift_mps;
  return sat;
}

}  // namespace

double code_discriminator_variance_chips2(double cn0_hz, double t_s, double spacing_chips) {
  const double bn = 1.0 / (2.0 * t_s);
  return bn * spacing_chips / (2.0 * cn0_hz) * (1.0 + 2.0 / ((2.0 - spacing_chips) * t_s * cn0_hz));
}

double costas_phase_variance_cycles2(double cn0_hz, double t_s) {
  const double bn = 1.0 / (2.0 * t_s);
  const double rad2 = bn / cn0_hz * (1.0 + 1.0 / (2.0 * t_s * cn0_hz));
  return rad2 / (4.0 * M_PI * M_PI);
}

double code_discriminator_gain(double cn0_hz, double t_s) {
  const double nu = std::max(cn0_hz * t_s, 0.0) / 8.0;
  // r = I1(nu) / I0(nu); above nu = 100 (C/N0 T = 800) its asymptotic series, good to 1e-8 there (the Bessel
  // functions themselves overflow a double near nu = 700).
  const double r = nu <= 100.0 ? std::cyl_bessel_i(1.0, nu) / std::cyl_bessel_i(0.0, nu)
                               : 1.0 - 1.0 / (2.0 * nu) - 1.0 / (8.0 * nu * nu) - 1.0 / (8.0 * nu * nu * nu);
  return 2.0 * nu * (1.0 + r) / (1.0 + 2.0 * nu + 2.0 * nu * r);
}

const char* to_string(VectorCarrier carrier) {
  switch (carrier) {
    case VectorCarrier::kFll:
      return "fll";
    case VectorCarrier::kPll:
      return "pll";
    default:
      return "aided-pll";
  }
}

std::optional<VectorCarrier> vector_carrier_from_string(std::string_view text) {
  for (const VectorCarrier c : {VectorCarrier::kAidedPll, VectorCarrier::kFll, VectorCarrier::kPll})
    if (text == to_string(c)) return c;
  return std::nullopt;
}

VectorState propagate(const VectorState& x, double dt) {
  VectorState y = x;
  y.segment<3>(vx::kPos) += dt * x.segment<3>(vx::kVel);
  y(vx::kBias) += dt * x(vx::kDrift);
  return y;
}

VectorState VectorProcessModel::f(const VectorState& x, double dt) const { return propagate(x, dt); }

StateMatrix<8> VectorProcessModel::F(const VectorState&) const {
  StateMatrix<8> F = StateMatrix<8>::Zero();
  F.block<3, 3>(vx::kPos, vx::kVel).setIdentity();
  F(vx::kBias, vx::kDrift) = 1.0;
  return F;
}

Eigen::Matrix<double, 8, 5> VectorProcessModel::G(const VectorState&) const {
  Eigen::Matrix<double, 8, 5> G = Eigen::Matrix<double, 8, 5>::Zero();
  G.block<3, 3>(vx::kVel, 0).setIdentity();
  G(vx::kBias, 3) = 1.0;
  G(vx::kDrift, 4) = 1.0;
  return G;
}

Eigen::Matrix<double, 5, 5> VectorProcessModel::Qc() const {
  Eigen::Matrix<double, 5, 5> Q = Eigen::Matrix<double, 5, 5>::Zero();
  const double c2 = kSpeedOfLight_mps * kSpeedOfLight_mps;
  Q(0, 0) = Q(1, 1) = Q(2, 2) = noise.accel_psd_m2ps3;
  Q(3, 3) = c2 * noise.h0 / 2.0;
  Q(4, 4) = c2 * 2.0 * M_PI * M_PI * noise.h_minus2;
  return Q;
}

VectorRangeMeasurement::VectorRangeMeasurement(const SatelliteObservable& sat, double delta_s, bool rate, double z,
                                               double sigma)
    : sat_(sat), delta_s_(delta_s), rate_(rate), z_(z), sigma_(sigma) {}

Eigen::VectorXd VectorRangeMeasurement::h(const VectorState& x) const {
  const VectorState m = propagate(x, -delta_s_);
  const Eigen::Vector3d r = m.segment<3>(vx::kPos);
  const double v = rate_ ? predicted_range_rate_mps(sat_, r, m.segment<3>(vx::kVel), m(vx::kDrift))
                         : predicted_pseudorange_m(sat_, r, m(vx::kBias));
  return Eigen::VectorXd::Constant(1, v);
}

MeasurementJacobian<8> VectorRangeMeasurement::H(const VectorState& x) const {
  const VectorState m = propagate(x, -delta_s_);
  const Eigen::Vector3d r = m.segment<3>(vx::kPos), v = m.segment<3>(vx::kVel);
  const Eigen::Vector3d los = sat_.r_sat_e - r;
  const double rho = los.norm();
  const Eigen::Vector3d u = los / rho;
  MeasurementJacobian<8> H = MeasurementJacobian<8>::Zero(1, 8);
  Eigen::RowVector3d d_r, d_v;  // with respect to the back-propagated position and velocity
  if (!rate_) {
    d_r = -u.transpose();
    d_v.setZero();
    H(0, vx::kBias) = 1.0;
    H(0, vx::kDrift) = -delta_s_;
  } else {
    // h = u.v_sat + (u.v)(u.w)/c - u.v + d - sv drift, w = v_sat + omega x r_sat (predicted_range_rate_mps).
    const Eigen::Vector3d omega(0.0, 0.0, signals::kEarthRotationRate_radps);
    const Eigen::Vector3d w = sat_.v_sat_e + omega.cross(sat_.r_sat_e);
    const double c = kSpeedOfLight_mps;
    const Eigen::Vector3d g = sat_.v_sat_e + (u.dot(w) / c) * v + (u.dot(v) / c) * w - v;  // dh/du
    d_r = -(g.transpose() * (Eigen::Matrix3d::Identity() - u * u.transpose())) / rho;
    d_v = (u * (u.dot(w) / c) - u).transpose();
    H(0, vx::kDrift) = 1.0;
  }
  // Back-propagation: r_m = r - v delta, b_m = b - d delta.
  H.block<1, 3>(0, vx::kPos) = d_r;
  H.block<1, 3>(0, vx::kVel) = d_v - delta_s_ * d_r;
  return H;
}

ReplicaPrediction predict_replica(const SatelliteObservable& sat, const VectorState& x) {
  ReplicaPrediction p;
  const Eigen::Vector3d r = x.segment<3>(vx::kPos);
  p.pseudorange_m = predicted_pseudorange_m(sat, r, x(vx::kBias));
  p.pseudorange_rate_mps = predicted_range_rate_mps(sat, r, x.segment<3>(vx::kVel), x(vx::kDrift));
  p.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 - p.pseudorange_rate_mps / kSpeedOfLight_mps);
  p.doppler_hz = -p.pseudorange_rate_mps / signals::kL1Wavelength_m;
  return p;
}

namespace {

NisReleaseOptions with_gate(NisReleaseOptions o, const GateOptions& gate) {
  o.gate_probability = gate.probability;
  return o;
}

}  // namespace

VectorTrackingFilter::VectorTrackingFilter(const VectorTrackingOptions& options)
    : opt_(options), nis_(with_gate(options.nis, options.gate)) {
  model_.noise = opt_.process;
  phase_.fill(VectorCarrierPhase(opt_.pll));
  prn_.fill(fresh_prn_state());
}

VectorTrackingFilter::PrnState VectorTrackingFilter::fresh_prn_state() const {
  PrnState s;
  s.doppler_bias = FalseLockMonitor(FalseLockMonitor::Averaging::kRunning, opt_.doppler_bias_average_s);
  return s;
}

std::optional<SatelliteObservable> VectorTrackingFilter::observable(const receiver::VectorEpochInput& in, int prn,
                                                                    std::int64_t sample, double pseudorange_m) const {
  receiver::ObservationEpoch epoch;
  epoch.receive_time = signals::add_seconds(in.receive_time, static_cast<double>(sample - in.sample) / in.fs_hz);
  epoch.sample_index = sample;
  receiver::Observation o;
  o.prn = prn;
  o.pseudorange_m = pseudorange_m;
  o.doppler_hz = NAN;
  o.cn0_dbhz = 45.0;
  epoch.observations.push_back(o);
  TightOptions t;
  t.elevation_mask_rad = opt_.elevation_mask_rad;
  t.ionosphere = opt_.ionosphere;
  t.troposphere = opt_.troposphere;
  t.use_range_rate = false;
  static const signals::KlobucharParameters no_iono{};
  const auto sats =
      prepare_satellites(epoch, *in.ephemerides, in.iono ? *in.iono : no_iono, ekf_->x().segment<3>(vx::kPos), t);
  if (sats.empty()) return std::nullopt;
  return sats.front();
}

bool VectorTrackingFilter::initialise(const receiver::VectorEpochInput& in) {
  const receiver::PvtSolution* fix = in.last_fix;
  if (!fix || !fix->valid || !fix->velocity_valid) return false;
  // The fix's bias against the clock as it reads now (the engine may have jumped it since the fix), and the fix's
  // epoch by that clock: its GPS time plus that bias.
  const double bias_m =
      fix->clock_bias_m - kSpeedOfLight_mps * (in.clock_corrections_s - in.last_fix_clock_corrections_s);
  const double dt = signals::seconds_between(in.receive_time, fix->time) - bias_m / kSpeedOfLight_mps;
  if (!(std::abs(dt) < 1.0)) return false;
  VectorState x;
  x.segment<3>(vx::kPos) = fix->r_e_m + dt * fix->v_e_mps;
  x.segment<3>(vx::kVel) = fix->v_e_mps;
  x(vx::kBias) = bias_m + dt * fix->clock_drift_mps;
  x(vx::kDrift) = fix->clock_drift_mps;
  Eigen::Matrix<double, 8, 1> s;
  s << Eigen::Vector3d::Constant(opt_.initial_sigma_pos_m), Eigen::Vector3d::Constant(opt_.initial_sigma_vel_mps),
      opt_.initial_sigma_bias_m, opt_.initial_sigma_drift_mps;
  EkfOptions e;
  e.gate = opt_.gate;
  ekf_.emplace(x, StateMatrix<8>(s.array().square().matrix().asDiagonal()), e);
  sample_ = in.sample;
  clock_corrections_s_ = in.clock_corrections_s;
  starved_s_ = 0.0;
  prn_.fill(fresh_prn_state());
  phase_.fill(VectorCarrierPhase(opt_.pll));
  nis_.reset();
  ++initialisations_;
  return true;
}

bool VectorTrackingFilter::usable(const receiver::VectorChannelInput& ch, const PrnState& st) const {
  if (!std::isfinite(ch.cn0_dbhz) || ch.coasting) return false;
  if (ch.cn0_dbhz >= opt_.min_cn0_dbhz) return true;
  // Weak: only a filter-driven channel the filter already commands (its presence test judges lock).
  return opt_.filter_driven && ch.vector_mode && st.accepted >= opt_.join_after_updates;
}

void VectorTrackingFilter::update(const receiver::VectorEpochInput& in,
                                  std::span<receiver::VectorChannelCommand> commands) {
  for (auto& c : commands) c = {};
  if (!in.ephemerides) return;
  double step_s = 0.0;
  if (!ekf_) {
    if (!initialise(in)) return;
  } else {
    if (in.clock_corrections_s != clock_corrections_s_) {  // the engine's clock jumped: so does the bias
      VectorState x = ekf_->x();
      x(vx::kBias) -= kSpeedOfLight_mps * (in.clock_corrections_s - clock_corrections_s_);
      ekf_->set_x(x);
      clock_corrections_s_ = in.clock_corrections_s;
    }
    const double dt = static_cast<double>(in.sample - sample_) / in.fs_hz;
    if (dt > 0.0) ekf_->predict(model_, dt);
    step_s = std::max(dt, 0.0);
    sample_ = in.sample;
  }
  log_epoch_.channels.assign(in.channels.size(), VectorChannelLog{});

  // Measurement updates, channel by channel (each gated on its own), in slot order.
  int used = 0;
  for (std::size_t i = 0; i < in.channels.size(); ++i) {
    const receiver::VectorChannelInput& ch = in.channels[i];
    VectorChannelLog& log = log_epoch_.channels[i];
    log.prn = ch.prn;
    log.cn0_dbhz = ch.cn0_dbhz;
    log.replica_code_rate_chips_per_s = ch.code_rate_chips_per_s;
    if (ch.has_measurement) {
      log.measurement_sample = ch.measurement_sample;
      log.replica_phase_mid_cycles = ch.replica_carrier_phase_mid_cycles;
    }
    PrnState& st = prn_[static_cast<std::size_t>(ch.prn)];
    const auto k = static_cast<std::size_t>(ch.prn);
    epoch_nis_[k] = 0.0;
    epoch_dof_[k] = 0;
    if (!ch.synchronised && nis_released_[k]) {  // lost: a new track starts afresh
      nis_released_[k] = false;
      nis_.forget(ch.prn);
    }
    if (nis_released_[k]) {  // its rows contradicted the filter: scalar, not used
      st = {};
      continue;
    }
    const bool strong = usable(ch, st);
    // A faded channel the filter commands keeps its standing (it coasts, commanded below); others restart.
    const bool joined = st.accepted >= opt_.join_after_updates && ch.vector_mode;
    if (!ch.synchronised || (!strong && !joined)) st = {};
    if (ch.synchronised && std::isfinite(ch.cn0_dbhz)) {
      const double a = std::min(1.0, (step_s > 0.0 ? step_s : 0.02) / opt_.weak_cn0_average_s);
      st.cn0_mean_hz = std::isfinite(st.cn0_mean_hz) ? st.cn0_mean_hz + a * (ratio_hz(ch.cn0_dbhz) - st.cn0_mean_hz)
                                                     : ratio_hz(ch.cn0_dbhz);
    }
    if (!ch.synchronised || !strong || !ch.has_measurement) continue;
    // A channel the filter commands, or one below min_cn0_dbhz: the lower of the 0.2 s estimate and its running
    // mean. (A commanded channel at 22 dB-Hz reads >= 25 dB-Hz in ~3 % of its 0.2 s estimates, and after a step
    // down the mean lags: taking either alone gave it the weights, and the false-lock immunity, of a strong one.)
    const bool commanded = st.accepted >= opt_.join_after_updates && ch.vector_mode;
    const double cn0 = ch.cn0_dbhz >= opt_.min_cn0_dbhz && !commanded ? ratio_hz(ch.cn0_dbhz)
                                                                      : std::min(ratio_hz(ch.cn0_dbhz), st.cn0_mean_hz);
    const auto now = observable(in, ch.prn, in.sample, ch.replica_pseudorange_m);
    if (!now) {
      st = {};
      continue;
    }
    const double delta = static_cast<double>(in.sample - ch.measurement_sample) / in.fs_hz;
    const SatelliteObservable sat = shifted(*now, -delta);
    const double sigma_pr =
        kChip_m * std::sqrt(code_discriminator_variance_chips2(cn0, ch.integration_time_s, opt_.code_spacing_chips));
    // The discriminator reports gain x the code error (code_discriminator_gain): divided by it, the pseudorange is
    // unbiased to first order, and its variance is the closed form's (var / gain^2: 1.04-1.27 of it at 18-24
    // dB-Hz in the Monte Carlo).
    const double gain = code_discriminator_gain(cn0, ch.integration_time_s);
    const double z_pr =
        ch.replica_pseudorange_mid_m + (ch.measured_pseudorange_m - ch.replica_pseudorange_mid_m) / gain;
    const UpdateResult r = ekf_->update(VectorRangeMeasurement(sat, delta, false, z_pr, sigma_pr));
    log.pr_innovation_m = r.innovation.size() ? r.innovation(0) : NAN;
    log.pr_sigma_m = sigma_pr;
    log.pr_used = r.accepted;
    epoch_nis_[k] += r.nis;
    epoch_dof_[k] += r.dof;
    if (r.accepted) {
      ++st.accepted;
      st.rejections = 0;
      ++used;
    } else {
      ++st.rejections;
    }
    if (opt_.use_doppler && ch.has_doppler) {
      const double delta_d = static_cast<double>(in.sample - ch.doppler_sample) / in.fs_hz;
      const double sigma_hz =
          std::sqrt(receiver::phase_change_frequency_variance_hz2(cn0, ch.integration_time_s, ch.doppler_interval_s));
      const double sigma_rate = signals::kL1Wavelength_m * sigma_hz;
      const double z = -signals::kL1Wavelength_m * ch.measured_doppler_hz;
      const VectorRangeMeasurement m(shifted(*now, -delta_d), delta_d, true, z, sigma_rate);
      // The channel PLL's frequency against the prediction (Hz), averaged: a weak channel whose PLL sits on a
      // false lock (25 Hz off: a half cycle per 20 ms epoch; 10 Hz at 100 ms sums) gives Doppler rows biased by
      // ~2-5 m/s that a 3.9-sigma gate passes at 20-30 dB-Hz; they would drag the velocity, and with it every
      // replica. Its rows are left out while the mean is off by more than doppler_bias_hz (see the commands).
      const double off_hz = (m.z() - m.h(ekf_->x()))(0) / -signals::kL1Wavelength_m;
      st.doppler_bias.add(off_hz, step_s > 0.0 ? step_s : 0.02);
      // (An FLL or vector-PLL channel has no PLL of its own to lock falsely: its offset is the filter's own lag,
      // which its rows correct.)
      const bool weak = opt_.carrier == VectorCarrier::kAidedPll && cn0 < ratio_hz(opt_.false_lock_below_dbhz);
      if (!(weak && std::abs(st.doppler_bias.mean_hz()) > opt_.doppler_bias_hz)) {
        const UpdateResult rr = ekf_->update(m);
        epoch_nis_[k] += rr.nis;
        epoch_dof_[k] += rr.dof;
        log.rate_innovation_mps = rr.innovation.size() ? rr.innovation(0) : NAN;
        log.rate_used = rr.accepted;
      }
      log.rate_sigma_mps = sigma_rate;
      log.measured_doppler_hz = ch.measured_doppler_hz;
    }
  }

  nis_tests(in);

  // Too few satellites for an observable filter: after reset_after_s, restart from the next fix.
  starved_s_ = used >= opt_.min_satellites ? 0.0 : starved_s_ + step_s;
  log_epoch_.sample = in.sample;
  // Channels coasting on the prediction: the filter propagates (their coast limits end it) rather than restart.
  const bool holding = std::any_of(in.channels.begin(), in.channels.end(), [&](const receiver::VectorChannelInput& c) {
    const PrnState& st = prn_[static_cast<std::size_t>(c.prn)];
    return c.synchronised && c.vector_mode && st.accepted >= opt_.join_after_updates && st.coast_s < opt_.max_coast_s;
  });
  if (starved_s_ > opt_.reset_after_s && !holding) {
    ekf_.reset();
    ++resets_;
    return;  // every channel scalar
  }

  // Commands: the replica each channel should run from its next epoch start on.
  int vector = 0;
  for (std::size_t i = 0; i < in.channels.size(); ++i) {
    const receiver::VectorChannelInput& ch = in.channels[i];
    VectorChannelLog& log = log_epoch_.channels[i];
    PrnState& st = prn_[static_cast<std::size_t>(ch.prn)];
    const bool strong = usable(ch, st);
    if (!ch.synchronised || (!strong && st.accepted < opt_.join_after_updates)) continue;
    if (nis_released_[static_cast<std::size_t>(ch.prn)]) continue;
    // Coasting: no measurement to keep it honest, only the prediction (bounded in time and uncertainty).
    const bool coasting = !strong || !log.pr_used;
    st.coast_s = coasting ? st.coast_s + step_s : 0.0;
    log.coasting = !strong;
    log.coast_s = st.coast_s;
    const double delta_e = static_cast<double>(ch.next_epoch_sample - in.sample) / in.fs_hz;
    const auto now = observable(in, ch.prn, in.sample, ch.replica_pseudorange_m);
    if (!now) continue;
    const ReplicaPrediction p = predict_replica(shifted(*now, delta_e), propagate(ekf_->x(), delta_e));
    log.predicted_doppler_hz = p.doppler_hz;
    log.predicted_code_rate_chips_per_s = p.code_rate_chips_per_s;
    if (st.rejections >= opt_.max_rejections) st.accepted = 0;  // back to scalar; it re-joins after new updates
    if (st.accepted < opt_.join_after_updates) continue;
    {  // predicted pseudorange 1-sigma: H = [-u 0 1 0]
      const Eigen::Vector3d u = (now->r_sat_e - ekf_->x().segment<3>(vx::kPos)).normalized();
      Eigen::Matrix<double, 1, 8> H = Eigen::Matrix<double, 1, 8>::Zero();
      H.segment<3>(vx::kPos) = -u.transpose();
      H(vx::kBias) = 1.0;
      log.predicted_sigma_chips = std::sqrt((H * ekf_->P() * H.transpose())(0, 0)) / kChip_m;
    }
    if (!strong && (st.coast_s > opt_.max_coast_s || !(log.predicted_sigma_chips <= opt_.max_coast_sigma_chips))) {
      st = {};  // coasted too long or too uncertain: released to re-acquisition
      continue;
    }
    // The replica at its next epoch start, if left at its current code rate.
    const double replica_m = ch.replica_pseudorange_m +
                             kSpeedOfLight_mps * (1.0 - ch.code_rate_chips_per_s / signals::kCaChipRate_hz) * delta_e;
    const double jump = (replica_m - p.pseudorange_m) / kChip_m;  // replica too far away: advance it
    log.code_jump_chips = jump;
    if (!(std::abs(jump) <= opt_.max_jump_chips)) {
      st.accepted = 0;
      continue;
    }
    commands[i].vector = true;
    commands[i].code_rate_chips_per_s = p.code_rate_chips_per_s;
    commands[i].code_phase_jump_chips = jump;
    if (opt_.carrier == VectorCarrier::kFll || opt_.carrier == VectorCarrier::kPll) {
      // The NCO holds one frequency over the epoch: the predicted Doppler at its middle (the Doppler moves up to
      // ~100 Hz/s in a 2 g turn: 1 Hz over half an epoch). Filter-driven as the aided channels (opt_.filter_driven):
      // the channel's loss test is the presence test (its 0.2 s C/N0 test, whose estimates dip under 25 dB-Hz for
      // ~30 % of the time at 26 dB-Hz, made it coast with the signal there), its time tag is held, and its rows
      // keep updating the filter below min_cn0_dbhz with the weak-signal weights. Its own carrier loop does not
      // run (no long sums, no pure PLL): its bits stay differential (coherent while phase-locked, kPll).
      const double half_epoch_s = 0.5 * (ch.integration_time_s > 0.0 ? ch.integration_time_s : 0.02);
      commands[i].carrier_frequency_hz =
          predict_replica(shifted(*now, delta_e + half_epoch_s), propagate(ekf_->x(), delta_e + half_epoch_s))
              .doppler_hz;
      commands[i].carrier = receiver::CarrierControl::kFrequency;
      commands[i].filter_driven = opt_.filter_driven;
      if (opt_.carrier == VectorCarrier::kPll) {
        const auto doppler_at = [&](std::int64_t sample) {
          const double d = static_cast<double>(sample - in.sample) / in.fs_hz;
          return predict_replica(shifted(*now, d), propagate(ekf_->x(), d)).doppler_hz;
        };
        const double cn0 = ch.cn0_dbhz >= opt_.min_cn0_dbhz || !std::isfinite(st.cn0_mean_hz)
                               ? ratio_hz(ch.cn0_dbhz)
                               : std::min(ratio_hz(ch.cn0_dbhz), st.cn0_mean_hz);
        // The prediction's Doppler variance (Hz^2): the rate row's Jacobian through the covariance.
        const MeasurementJacobian<8> Hr = VectorRangeMeasurement(*now, 0.0, true, 0.0, 1.0).H(ekf_->x());
        const double var_hz2 =
            (Hr * ekf_->P() * Hr.transpose())(0, 0) / (signals::kL1Wavelength_m * signals::kL1Wavelength_m);
        command_pll(ch, doppler_at, var_hz2, strong, cn0, step_s, in.fs_hz, commands[i], log);
      }
    } else {
      commands[i].filter_driven = opt_.filter_driven;
      // A weak channel's PLL held off the prediction for doppler_bias_average_s (a false lock): its aiding steps by
      // the mean offset once, which moves the PLL's frequency onto the prediction (the channel adds each change of
      // the aiding to its PLL); the offset is kept in later commands, so it acts once.
      // (The lower of the estimate and its mean, as for the weights: the linear mean alone stays above 35 dB-Hz
      // for 2.3 s after a step from 45 to 22 dB-Hz.)
      const double low_cn0 =
          std::isfinite(ch.cn0_dbhz) ? std::min(ratio_hz(ch.cn0_dbhz), st.cn0_mean_hz) : st.cn0_mean_hz;
      if (opt_.carrier_aiding && low_cn0 < ratio_hz(opt_.false_lock_below_dbhz) &&
          std::abs(st.doppler_bias.mean_hz()) > opt_.false_lock_hz &&
          st.doppler_bias.epochs() * step_s >= opt_.doppler_bias_average_s) {
        st.aid_offset_hz -= st.doppler_bias.mean_hz();
        st.doppler_bias.reset();
        ++frequency_resets_;
      }
      if (opt_.carrier_aiding) commands[i].carrier_frequency_hz = p.doppler_hz + st.aid_offset_hz;
    }
    log.vector = true;
    ++vector;
  }
  // A channel the filter does not command (scalar, dropped) has no carrier states: a later hand-over starts anew.
  if (opt_.carrier == VectorCarrier::kPll)
    for (std::size_t i = 0; i < in.channels.size(); ++i)
      if (!commands[i].vector) phase_[static_cast<std::size_t>(in.channels[i].prn)] = VectorCarrierPhase(opt_.pll);
  if (log_) {
    log_epoch_.receive_time = in.receive_time;
    log_epoch_.x = ekf_->x();
    log_epoch_.sigma = ekf_->P().diagonal().cwiseSqrt();
    log_epoch_.used = used;
    log_epoch_.vector = vector;
    log_(log_epoch_);
  }
}

void VectorTrackingFilter::nis_tests(const receiver::VectorEpochInput& in) {
  for (const auto& ch : in.channels) {
    const auto k = static_cast<std::size_t>(ch.prn);
    if (epoch_dof_[k] > 0) nis_.add(ch.prn, epoch_nis_[k], epoch_dof_[k]);
  }
  const NisVerdict v = nis_.evaluate();
  const double t_s = static_cast<double>(in.sample) / in.fs_hz;
  if (v.filter) {
    // The channels together contradict the filter: its state is wrong. Its covariance re-opens to at least its
    // initial sigmas (correlations cleared), so that their measurements pull it back; the channels stay commanded.
    Eigen::Matrix<double, 8, 1> s;
    s << Eigen::Vector3d::Constant(opt_.initial_sigma_pos_m), Eigen::Vector3d::Constant(opt_.initial_sigma_vel_mps),
        opt_.initial_sigma_bias_m, opt_.initial_sigma_drift_mps;
    const Eigen::Matrix<double, 8, 1> var = ekf_->P().diagonal().cwiseMax(s.array().square().matrix());
    ekf_->set_P(StateMatrix<8>(var.asDiagonal()));
    release_log_.add(t_s, 0, "filter_nis", v.reasons.front());
  }
  for (std::size_t i = 0; i < v.released.size(); ++i) {
    const auto k = static_cast<std::size_t>(v.released[i]);
    nis_released_[k] = true;
    prn_[k] = fresh_prn_state();
    release_log_.add(t_s, v.released[i], "channel_nis", v.reasons[i]);
  }
}

}  // namespace ultratrack::fusion

namespace ultratrack::fusion {

void VectorTrackingFilter::command_pll(const receiver::VectorChannelInput& ch,
                                       const std::function<double(std::int64_t)>& doppler_at,
                                       double prediction_variance_hz2, bool usable_now, double cn0_hz, double step_s,
                                       double fs_hz, receiver::VectorChannelCommand& command, VectorChannelLog& log) {
  VectorCarrierPhase& ph = phase_[static_cast<std::size_t>(ch.prn)];
  const double t = ch.integration_time_s > 0.0 ? ch.integration_time_s : 0.02;
  const double variance = costas_phase_variance_cycles2(cn0_hz, t);
  // A discriminator this epoch: a fresh, usable (not faded) epoch with normalised taps.
  const bool fresh = usable_now && ch.has_measurement && ch.integration_time_s > 0.0 && ch.iq_scale > 0.0;
  // A faded channel (not usable: below min_cn0_dbhz, or coasting) has no discriminator to hold its phase: the arc
  // ends at once and it is commanded as in the FLL (its phase flagged) until it re-enters after relock_after_s.
  if (ph.active() && !usable_now) {
    ph.stop();
    ++phase_losses_;
  }
  if (ph.active()) {
    if (fresh && ch.measurement_sample > ph.sample()) {
      const std::int64_t mid = (ph.sample() + ch.measurement_sample) / 2;
      const double base = ph.commanded_base_hz(mid);
      ph.propagate(ch.measurement_sample, fs_hz, std::isfinite(base) ? base : doppler_at(mid), prediction_variance_hz2);
      ph.update(ch.iq_i[1], ch.iq_q[1], ch.replica_carrier_phase_mid_cycles, variance, t);
      log.phase_disc_cycles = ph.last_discriminator_cycles();
      log.phase_innovation_cycles = ph.last_innovation_cycles();
      if (!ph.locked()) {  // phase lock failed: the FLL from now on (a new arc after relock_after_s)
        ph.stop();
        ++phase_losses_;
      }
    }
  } else if (fresh) {
    // Hand-over (never tracked since it joined) at once; after a loss, once usable and strong for relock_after_s.
    const bool strong = cn0_hz >= ratio_hz(opt_.min_cn0_dbhz + opt_.pll.relock_margin_dbhz);
    ph.fallback_s = strong ? ph.fallback_s + step_s : 0.0;
    if (!ph.fell_back() || ph.fallback_s >= opt_.pll.relock_after_s) {
      const double nu0 = ch.has_doppler ? ch.measured_doppler_hz - doppler_at(ch.doppler_sample) : 0.0;
      ph.start(ch.measurement_sample, ch.replica_carrier_phase_mid_cycles,
               costas_discriminator_cycles(ch.iq_i[1], ch.iq_q[1]), std::isfinite(nu0) ? nu0 : 0.0, variance);
      ++phase_arcs_;
    }
  }
  if (!ph.active()) return;  // the FLL's command (CarrierControl::kFrequency)
  // The replica's phase at its next epoch start: the carrier states' phase there; the frequency over that epoch:
  // the prediction at its middle plus the residual.
  const std::int64_t next = ch.next_epoch_sample;
  const std::int64_t mid = (ph.sample() + next) / 2;
  const double base = ph.commanded_base_hz(mid);
  const double want = ph.phase_at(next, fs_hz, std::isfinite(base) ? base : doppler_at(mid));
  const double jump = want - ch.replica_carrier_phase_next_cycles;
  // A correction beyond half a cycle means the states no longer describe this replica (a stale or diverged
  // state): the channel falls back rather than drag its replica.
  if (!(std::abs(jump) <= 0.5)) {
    ph.stop();
    ++phase_losses_;
    return;
  }
  ph.record_command(next, command.carrier_frequency_hz);
  command.carrier = receiver::CarrierControl::kFrequencyAndPhase;
  command.carrier_phase_jump_cycles = jump;
  command.carrier_frequency_hz += ph.nu_hz();
  log.phase_tracking = true;
  log.phase_jump_cycles = jump;
  log.phase_sigma_cycles = ph.sigma_phase_cycles();
  log.phase_nu_hz = ph.nu_hz();
  log.phase_lock = ph.lock_indicator();
  log.phase_bn_hz = ph.last_bandwidth_hz();
}

}  // namespace ultratrack::fusion
