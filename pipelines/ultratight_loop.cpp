// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/ultratight_loop.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "fusion/carrier_rate_measurement.hpp"
#include "fusion/clock_model.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/lockout_recovery.hpp"
#include "fusion/loose_measurements.hpp"
#include "fusion/tight_measurements.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "io/input_error.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kC = signals::kSpeedOfLight_mps;
constexpr double kLambda_m = signals::kL1Wavelength_m;
constexpr double kChip_m = kC / signals::kCaChipRate_hz;
constexpr double kEpochChips = 20.0 * 1023.0;  // a 20 ms channel epoch of C/A code

// A channel's latest correlation epoch is new, of one loop period (20 ms), and has a transmit-time tag.
bool fresh_epoch(const receiver::VectorChannelInput& in, double period_s) {
  return in.synchronised && in.has_measurement && std::abs(in.integration_time_s - period_s) <= 1e-4;
}

// The same for its prompt alone: also an epoch the fade gate kept from being a measurement (has_prompt).
bool fresh_prompt(const receiver::VectorChannelInput& in, double period_s) {
  return in.synchronised && in.has_prompt && std::abs(in.prompt_integration_time_s - period_s) <= 1e-4;
}

// One prompt (its taps on the raw scale, taps / iq_scale) into the channel's I&Q amplitude average; returns A^2 from
// the epochs before it (PromptPowerAverage::update). in.iq_scale must be > 0.
double update_prompt_power(PromptPowerAverage& average, const receiver::VectorChannelInput& in) {
  const double scale2 = in.iq_scale * in.iq_scale;
  return average.update((in.iq_i[1] * in.iq_i[1] + in.iq_q[1] * in.iq_q[1]) / scale2, scale2);
}

// The start and the middle of a channel's latest correlation epoch on the driver's time line (t_k at epoch.sample).
struct EpochTimes {
  double start_s, half_s;
  double mid_s() const { return start_s + half_s; }
};
EpochTimes epoch_times(const receiver::VectorEpochInput& epoch, const receiver::VectorChannelInput& in, double t_k) {
  return {t_k - static_cast<double>(epoch.sample - in.measurement_first_sample) / epoch.fs_hz,
          static_cast<double>(in.measurement_sample - in.measurement_first_sample) / epoch.fs_hz};
}

}  // namespace

UltraTightLoop::UltraTightLoop(GnssInsCoupler& fusion, ReceiveSink& sink, UltraTightLoopOptions ut)
    : fusion_(fusion), sink_(sink), options_(fusion.options().receiver), ut_(ut), nis_(ut.nis) {
  if (ut_.common_clock_bw_hz > 0.0)
    clock_loop_.emplace(receiver::CommonClockLoopOptions{ut_.common_clock_bw_hz, ut_.period_s});
}

UltraTightLoop::ChannelState& UltraTightLoop::channel(int prn) {
  auto [it, made] = channels_.try_emplace(prn);
  if (made)
    it->second.runaway = fusion::FalseLockMonitor(fusion::FalseLockMonitor::Averaging::kBlock, ut_.runaway_average_s);
  return it->second;
}

void UltraTightLoop::attach(receiver::ReceiverEngine& engine) {
  engine.set_vector_loop(this, ut_.period_s, fusion_.options().ut_pipelined);
}

// IMU time of a receiver sample: the receive time on the clock continuous since the hand-over, less the
// driver's clock bias (carried to that time by its drift).
double UltraTightLoop::imu_time(const receiver::VectorEpochInput& epoch, std::int64_t sample) const {
  const signals::GpsTime rx =
      signals::add_seconds(epoch.receive_time, (epoch.clock_corrections_s - corrections_at_start_s_) +
                                                   static_cast<double>(sample - epoch.sample) / epoch.fs_hz);
  const double t_rx = signals::seconds_between(rx, origin_);
  const auto& o = driver_->output();
  const double bias_m = o.clock_bias_m + o.clock_drift_mps * (t_rx - t_ins_);
  return t_rx - bias_m / kC;
}

void UltraTightLoop::emit_nav() {
  const auto& o = driver_->output();
  fusion_.write_nav(o.nav, o.sigma_pos_ned_m, o.sigma_vel_n_mps, o.sigma_att_rad);
}

// IMU rows are split where a vector epoch falls inside one (constant rates over a row); a nav row at each row end.
void UltraTightLoop::feed_imu_to(double t) {
  const auto& imu = fusion_.imu();
  while (t_ins_ < t - 1e-9) {
    while (next_imu_ < imu.size() && imu[next_imu_].t_s <= t_ins_ + 1e-9) ++next_imu_;
    if (next_imu_ == 0 || next_imu_ >= imu.size())
      throw io::InputError(fusion_.options().imu_name,
                           fmt::format("does not cover the signal: the ultra-tight loop needs IMU time {:.3f} s, the "
                                       "rows span {:.3f}-{:.3f} s",
                                       t, imu.front().t_s, imu.back().t_s));
    const ins::ImuIncrement& a = imu[next_imu_ - 1];
    const ins::ImuIncrement& b = imu[next_imu_];
    double end = std::min(b.t_s, t);
    // An odometer window ending inside: the row is split there, the window taken at its time.
    while (next_odometer_ < odometer_.size() && odometer_[next_odometer_].t_s <= t_ins_ + 1e-9) ++next_odometer_;
    const bool window_ends = next_odometer_ < odometer_.size() && odometer_[next_odometer_].t_s <= end + 1e-9;
    if (window_ends) end = odometer_[next_odometer_].t_s;
    const double share = (end - t_ins_) / (b.t_s - a.t_s);
    driver_->add_imu({end, b.dtheta_b * share, b.dv_b * share});
    t_ins_ = end;
    if (window_ends) {
      driver_->add_odometer(odometer_[next_odometer_++]);
      ++odometer_windows_;
      record_odometer();
    }
    if (end >= b.t_s - 1e-9) emit_nav();
  }
}

void UltraTightLoop::record_odometer() {
  if (driver_ && driver_->options().odometer.enabled)
    fusion_.record_handed_over_odometer(odometer_windows_, driver_->counters().odometer, driver_->output().odometer,
                                        gnss_last_used_s_);
}

void UltraTightLoop::start(const receiver::VectorEpochInput& epoch, double t_k) {
  const fusion::IntegrationOutput& out = fusion_.integration()->output();
  const ReceiveOptions& s = fusion_.options();
  const FuseConfig& c = s.navigation;
  fusion::UltraTightOptions o;
  o.filter = s.filter;
  o.form = s.ut_form;
  o.model = fusion::error_model_from_preset(imu_error_spec(c));
  // The tight filter's clock sigmas (its bias is re-expressed below, exactly, from the time line) with margin.
  o.model.clock.bias_sigma_m = 3.0 * out.sigma_clock_bias_m + 1.0;
  o.model.clock.drift_sigma_mps = 3.0 * out.sigma_clock_drift_mps + 0.1;
  o.model.clock = fusion::clock_noise_from_allan(c.clock_allan, o.model.clock);
  o.lever_arm_b = c.lever_arm_b;
  const auto floor = [](const Eigen::Vector3d& v, double m) { return Eigen::Vector3d(v.cwiseMax(m)); };
  o.sigma_pos_ned_m = floor(out.sigma_pos_ned_m, 0.1);
  o.sigma_vel_n_mps = floor(out.sigma_vel_n_mps, 0.01);
  o.sigma_att_rad = floor(out.sigma_att_rad, 1e-4);
  o.gate = c.gate;
  o.ukf = c.ukf;
  fusion::NisReleaseOptions nis = ut_.nis;
  nis.gate_probability = c.gate.probability;  // an update counts at most the threshold of the filter's own gate
  nis_ = fusion::NisReleaseMonitor(nis);
  // Commanded above command_mask_deg, measured above the PVT's mask. (Used for updates, the two low satellites of
  // the 10 g turn, at 6.5 and 8.4 deg, made the position diverge to 10 m RMS in the turn: docs/validation.md; left
  // scalar, they were lost wherever the scalar loops are.)
  o.tight.elevation_mask_rad = std::min(options_.pvt.elevation_mask_rad, ut_.command_mask_deg * M_PI / 180.0);
  o.measurement_mask_rad = options_.pvt.elevation_mask_rad;
  o.tight.ionosphere = options_.pvt.ionosphere;
  o.tight.troposphere = options_.pvt.troposphere;
  if (epoch.iono) o.iono = *epoch.iono;
  o.tap_offset_chips = options_.tracking.early_late_offset_chips;
  o.ca_code_correlation = true;  // the channels correlate C/A codes, not the ideal triangle
  o.gps_time_origin = origin_;
  o.initial_accel_bias_b = out.accel_bias_b;
  o.initial_gyro_bias_b = out.gyro_bias_b;
  if (!s.odometer.empty()) {  // the odometer states go on from the tight filter's estimates
    o.odometer = c.odometer;
    o.odometer.enabled = true;
    o.initial_odometer = out.odometer.value;
    o.sigma_initial_odometer = out.odometer.sigma;
    odometer_ = fusion_.take_odometer_windows();
    next_odometer_ = 0;
  }
  // The bias that makes this epoch's receive time (on the clock as it reads now) the tight filter's GPS time of it:
  // pseudoranges c (t_rx - t_tx) then equal range + bias, as the driver predicts them.
  corrections_at_start_s_ = epoch.clock_corrections_s;
  o.initial_clock_drift_mps = out.clock_drift_mps;
  o.initial_clock_bias_m =
      kC * (signals::seconds_between(epoch.receive_time, origin_) - t_k) - out.clock_drift_mps * (t_k - out.nav.t_s);
  // One ephemeris per PRN, chosen for this time (the driver would pick it among a day's ~12 sets every period);
  // 2-4 h fit intervals cover any run `receive` makes of a recording.
  std::vector<signals::Ephemeris> eph;
  for (int prn = 1; prn <= 32; ++prn)
    if (auto e = signals::select_ephemeris(*epoch.ephemerides, prn, epoch.receive_time)) eph.push_back(*e);
  ephemerides_ = eph;
  ephemerides_seen_ = epoch.ephemerides->size();
  driver_.emplace(out.nav, std::move(eph), o);
  gnss_last_used_s_ = out.nav.t_s;
  accepted_before_ = 0;
  t_ins_ = out.nav.t_s;
  next_imu_ = 0;
  handover_t_s_ = t_k;
  handover_sample_ = epoch.sample;
  fusion_.hand_over();
}

std::vector<fusion::ChannelCorrelation> UltraTightLoop::correlations(const receiver::VectorEpochInput& epoch,
                                                                     double t_k) {
  std::vector<fusion::ChannelCorrelation> out;
  const double shift_m = kC * (epoch.clock_corrections_s - corrections_at_start_s_);
  const double common_offset_hz = common_carrier_offset_hz(epoch, t_k);
  for (const auto& in : epoch.channels) {
    // An epoch the fade gate dropped still moves the I&Q model's amplitude (PromptPowerAverage, below): after a step
    // from 45 to 20 dB-Hz the gate drops ~1 s of epochs, and an average that skipped them met the first kept epoch
    // with the amplitude of 45 dB-Hz. The I&Q model then reads the missing amplitude as code and frequency error
    // (I_P innovations of -30 sigma; the few accepted ones pushed the common clock drift 1.7 Hz off and every
    // channel followed it away: weak_signal_told_tuning, seed 203).
    if (!fresh_epoch(in, ut_.period_s) && fresh_prompt(in, ut_.period_s) && in.iq_scale > 0.0)
      update_prompt_power(channel(in.prn).prompt_power, in);
    if (!fresh_epoch(in, ut_.period_s) || !std::isfinite(in.cn0_dbhz)) continue;
    if (!(in.iq_scale > 0.0)) continue;          // no noise estimate
    if (channel(in.prn).nis_released) continue;  // its correlations contradict the filter: not used
    const EpochTimes times = epoch_times(epoch, in, t_k);
    const double half_s = times.half_s, t_start_s = times.start_s;
    // A channel whose PLL ran away from the prediction correlates mostly noise against a replica carrier tens of
    // Hz off the signal; the I&Q (and discriminator) model takes that replica carrier as given and reads the
    // difference as the filter's Doppler error (16-34 Hz innovations were accepted: docs/validation.md), so its
    // correlations are left out until it is back.
    if (runaway_check(in, times.mid_s(), common_offset_hz)) {
      ++runaway_left_out_;
      channel(in.prn).rate_anchored = false;
      continue;
    }
    ++measurements_;
    fusion::ChannelCorrelation c;
    c.prn = in.prn;
    // The I&Q model's amplitude A = sqrt(2 C/N0 T) must be the one of these normalised taps: C/N0 by the moments
    // of the same taps (E[I_P^2 + Q_P^2] = A^2 + 2), averaged over the epochs (PromptPowerAverage)
    // on the raw scale and carried to this epoch's normalisation: the channel's noise estimate moves the
    // normalised amplitude by +-8 % (+-2.8 noise sigmas at 45 dB-Hz) from epoch to epoch, which an average of the
    // normalised power does not follow (I_P innovation variance 3.3 instead of 1: docs/validation.md). The
    // average of the epochs before this one: with this epoch's prompt in it (weight 0.1) the I_P innovation
    // would lose a tenth of its noise (variance 0.81).
    ChannelState& st = channel(in.prn);
    // PromptPowerAverage: the ~1 s mean while the C/N0 holds (the 0.2 s mean's spread made the gate below,
    // coast_cn0_dbhz, pass only its upper tail at 16 dB-Hz: A^2 ~1.9 x the taps'), the 0.2 s one after a step.
    const double a2 = update_prompt_power(st.prompt_power, in);
    c.cn0_dbhz = a2 > 0.0 ? 10.0 * std::log10(a2 / (2.0 * ut_.period_s)) : -100.0;
    // The channel's PLL stays closed: the period starts with its residual phase error (thermal jitter of the
    // loop at its design bandwidth for the coherent time it runs now, N x 20 ms), not the realigned phase of the
    // seed model.
    const int n = in.pll_coherent_epochs;
    const double jitter_rad = receiver::pll_thermal_jitter_rad(receiver::long_coherent_pll_bw_hz(options_.tracking, n),
                                                               n * ut_.period_s, c.cn0_dbhz);
    c.start_phase_var_rad2 = a2 > 0.0 ? jitter_rad * jitter_rad : 0.0;
    // The NCO phase is never jumped (only its frequency changes): each epoch starts where the previous one ended,
    // and the driver carries the previous epoch's measured phase over (ChannelCorrelation::continuous_carrier).
    c.continuous_carrier = true;
    c.integration_time_s = ut_.period_s;
    // Data wipe-off by the known bit (receiver/nav_bit_source.hpp: decoded from the signal by default), else by
    // the prompt's sign, the Costas form (each 20 ms update holds one bit: nothing sums across an unknown bit): the
    // Costas loop holds the signal in I (bit errors at 30 dB-Hz, 20 ms: Q(sqrt(2 C/N0 T)) = Q(6.3), none in
    // practice; at 20 dB-Hz Q(2) = 2 %, hence the known bits).
    const bool known = in.bit_sign != 0;
    const double sign = known ? in.bit_sign : (in.iq_i[1] >= 0.0 ? 1.0 : -1.0);
    for (int k = 0; k < 3; ++k) {
      c.taps.i[k] = sign * in.iq_i[k];
      c.taps.q[k] = sign * in.iq_q[k];
    }
    c.data_wiped = known || std::abs(in.iq_i[1]) > std::abs(in.iq_q[1]);  // else the sign is a guess: no update
    if (known) ++known_bits_;
    if (!c.data_wiped) ++not_wiped_;
    // The replica that ran over this epoch: code pseudorange (continuous clock) and the PLL's carrier rate.
    c.has_replica = true;
    c.replica_range_rate_mps = -kLambda_m * in.replica_carrier_frequency_hz;
    c.replica_t_start_s = t_start_s;
    c.replica_pseudorange_m = in.replica_pseudorange_mid_m + shift_m - c.replica_range_rate_mps * half_s;
    carrier_rate(in, times.mid_s(), c.start_phase_var_rad2, st, c);
    out.push_back(c);
  }
  return out;
}

// The channel's carrier-phase rate window (UltraTightLoopOptions::carrier_rate_window_s): continued by an epoch
// 20 ms after the previous one (the NCO's phase runs on: no jump in ultra-tight), else started afresh here. On the
// vector epochs that close a window (every window / period), a window of at least half its length is handed to the
// filter (ChannelCorrelation::has_carrier_rate) and the next starts where it ended.
void UltraTightLoop::carrier_rate(const receiver::VectorChannelInput& in, double t_mid_s, double phase_var_rad2,
                                  ChannelState& st, fusion::ChannelCorrelation& c) const {
  if (!(ut_.carrier_rate_window_s > 0.0)) return;
  const double phase = in.replica_carrier_phase_mid_cycles;
  const bool contiguous =
      st.rate_anchored && !in.coasting && std::abs(t_mid_s - st.rate_last_t_s - ut_.period_s) < 1e-4;
  st.rate_last_t_s = t_mid_s;
  if (!contiguous) {
    st.rate_anchored = !in.coasting;
    st.rate_t0_s = t_mid_s;
    st.rate_phase0_cycles = phase;
    st.rate_var0_rad2 = phase_var_rad2;
    return;
  }
  const long long every = std::max(1LL, std::llround(ut_.carrier_rate_window_s / ut_.period_s));
  const double window_s = t_mid_s - st.rate_t0_s;
  if (vector_epochs_ % every != 0 || window_s < 0.5 * ut_.carrier_rate_window_s) return;
  c.has_carrier_rate = true;
  c.carrier_rate_mps = -kLambda_m * (phase - st.rate_phase0_cycles) / window_s;
  c.carrier_rate_t_mid_s = 0.5 * (t_mid_s + st.rate_t0_s);
  c.carrier_rate_window_s = window_s;
  c.carrier_rate_var_m2ps2 = fusion::carrier_rate_phase_variance(st.rate_var0_rad2, phase_var_rad2, window_s);
  st.rate_t0_s = t_mid_s;
  st.rate_phase0_cycles = phase;
  st.rate_var0_rad2 = phase_var_rad2;
}

// The filter's predicted Doppler of a satellite at IMU time t_s: linear through the starts of the open period's
// replica and the one before (the measured epoch of a pipelined loop may start in the period before). NaN: none.
double UltraTightLoop::predicted_doppler_at(int prn, double t_s) const {
  const auto cur = period_replicas_.find(prn);
  if (cur == period_replicas_.end()) return NAN;
  const double f1 = cur->second.nco.carrier_frequency_hz, t1 = cur->second.t_start_s;
  const auto prev = previous_replicas_.find(prn);
  if (prev == previous_replicas_.end() || !(t1 - prev->second.t_start_s > 1e-6)) return f1;
  const double f0 = prev->second.nco.carrier_frequency_hz, t0 = prev->second.t_start_s;
  return f1 + (f1 - f0) / (t1 - t0) * (t_s - t1);
}

double UltraTightLoop::common_carrier_offset_hz(const receiver::VectorEpochInput& epoch, double t_k) const {
  std::vector<double> offsets;
  for (const auto& in : epoch.channels) {
    const auto it = channels_.find(in.prn);
    if (it == channels_.end() || !it->second.commanded || in.coasting || !fresh_epoch(in, ut_.period_s)) continue;
    const double offset =
        in.replica_carrier_frequency_hz - predicted_doppler_at(in.prn, epoch_times(epoch, in, t_k).mid_s());
    if (std::isfinite(offset)) offsets.push_back(offset);
  }
  if (offsets.size() < 4) return NAN;
  const auto middle = offsets.begin() + static_cast<std::ptrdiff_t>(offsets.size() / 2);
  std::nth_element(offsets.begin(), middle, offsets.end());
  if (offsets.size() % 2 == 1) return *middle;
  return 0.5 * (*middle + *std::max_element(offsets.begin(), middle));
}

// Carrier runaway of one channel with a 20 ms measurement (t_mid_s: its middle, IMU time); returns whether the
// channel is judged off its signal (its correlations are then not used). Only a commanded, not coasting channel
// below runaway_below_dbhz is checked; anything else starts the monitor afresh. A 1 s mean of its offset from the
// common one (common_offset_hz) beyond runaway_relative_hz, or without a common one of its offset beyond runaway_hz,
// sets the aiding step (sent with the next command) and keeps the channel off until a later 1 s mean is within it.
bool UltraTightLoop::runaway_check(const receiver::VectorChannelInput& in, double t_mid_s, double common_offset_hz) {
  ChannelState& st = channel(in.prn);
  st.last_offset_hz = in.replica_carrier_frequency_hz - predicted_doppler_at(in.prn, t_mid_s);
  if (!st.commanded || in.coasting || !(in.cn0_dbhz < ut_.runaway_below_dbhz)) {
    st.runaway.reset();
    st.runaway_off = false;
    st.runaway_repeats = 0;
    st.pending_step_hz = 0.0;
    return false;
  }
  // Against the common offset when there is one (the channel's own error), else the offset itself.
  const bool relative = std::isfinite(common_offset_hz);
  const double own_offset_hz = relative ? st.last_offset_hz - common_offset_hz : st.last_offset_hz;
  if (st.runaway.add(own_offset_hz, ut_.period_s)) {
    const double mean = st.runaway.mean_hz();
    const bool off = std::abs(mean) > (relative ? ut_.runaway_relative_hz : ut_.runaway_hz);
    st.runaway_repeats = off && st.runaway_off ? st.runaway_repeats + 1 : 0;
    st.runaway_off = off;
    if (st.runaway_repeats >= ut_.runaway_max_recentres) {
      st.runaway_given_up = true;
      ++runaway_releases_;
    } else if (st.runaway_off) {
      st.pending_step_hz = -st.runaway.recent_hz();
      // The step reaches the PLL with the next command (a pipelined one a period later) and shows in the
      // measurement after that: 3 epochs are left out of the next mean.
      st.runaway.reset(3);
    }
  }
  return st.runaway_off;
}

// The change of each satellite's predicted Doppler over the period just ended caused by the INS propagation alone
// (the nominal at its end, before this epoch's update, against the period's replicas). The channels' PLLs get
// only this as aiding: the filter's corrections would reach them as frequency steps, and the PLL's residual
// phase, which the I&Q / discriminator measurement reads as a frequency error, would then be fed back into it
// (a loop inside the loop: it diverged within a second in the 500 km/h circle).
std::map<int, double> UltraTightLoop::propagated_doppler_change() {
  std::map<int, double> out;
  const fusion::NominalState n = driver_->nominal();
  const auto& o = driver_->options();
  const Eigen::Vector3d r_ant = fusion::antenna_position_e(n.nav, o.lever_arm_b);
  const Eigen::Vector3d v_ant = ins::C_en(n.nav.lat_rad, n.nav.lon_rad) *
                                fusion::antenna_velocity_n(n.nav, Eigen::Vector3d::Zero(), o.lever_arm_b);
  receiver::ObservationEpoch e;
  e.receive_time = signals::add_seconds(origin_, n.nav.t_s + n.clock_bias_m / kC);
  for (const auto& [prn, r] : period_replicas_) {
    receiver::Observation ob;
    ob.prn = prn;
    ob.pseudorange_m = r.pseudorange_m + r.range_rate_mps * (n.nav.t_s - r.t_start_s);
    ob.doppler_hz = 0.0;
    e.observations.push_back(ob);
  }
  fusion::TightOptions t = o.tight;
  t.use_range_rate = true;
  for (const auto& sat : fusion::prepare_satellites(e, ephemerides_, o.iono, r_ant, t)) {
    const double doppler = -fusion::predicted_range_rate_mps(sat, r_ant, v_ant, n.clock_drift_mps) / kLambda_m;
    out[sat.prn] = doppler - period_replicas_[sat.prn].nco.carrier_frequency_hz;
  }
  return out;
}

void UltraTightLoop::command(const receiver::VectorEpochInput& epoch, double t_k,
                             std::span<receiver::VectorChannelCommand> commands,
                             const std::map<int, double>& aid_change, double clock_change_hz) {
  const double shift_m = kC * (epoch.clock_corrections_s - corrections_at_start_s_);
  std::map<int, const fusion::UltraTightSatelliteUpdate*> updates;
  for (const auto& u : driver_->last_updates()) updates[u.prn] = &u;
  std::map<int, fusion::ReplicaCommand> previous;
  previous.swap(period_replicas_);
  previous_replicas_ = previous;
  for (const auto& r : driver_->replicas()) period_replicas_[r.prn] = r;
  int commanded = 0;
  log_.sample = epoch.sample;
  log_.time_s = static_cast<double>(epoch.sample) / epoch.fs_hz;
  log_.channels.clear();
  for (std::size_t i = 0; i < epoch.channels.size(); ++i) {
    const receiver::VectorChannelInput& in = epoch.channels[i];
    ChannelState& st = channel(in.prn);
    const auto rep = period_replicas_.find(in.prn);
    double jump = NAN, predicted_m = NAN, measured_m = NAN, predicted_doppler = NAN;
    if (in.has_measurement) {
      measured_m = in.measured_pseudorange_m + shift_m;
      if (const auto p = previous.find(in.prn); p != previous.end()) {
        const double t_mid = t_k - static_cast<double>(epoch.sample - in.measurement_sample) / epoch.fs_hz;
        predicted_m = p->second.pseudorange_m + p->second.range_rate_mps * (t_mid - p->second.t_start_s);
      }
    }
    bool vector = false;
    if (in.synchronised && rep != period_replicas_.end()) {
      const fusion::ReplicaCommand& r = rep->second;
      predicted_doppler = r.nco.carrier_frequency_hz;
      double dt = static_cast<double>(in.next_epoch_sample - epoch.sample) / epoch.fs_hz;
      // Both on the receiver clock as it reads now: the replica left at its code rate vs the prediction.
      double replica_m =
          in.replica_pseudorange_m + kC * (1.0 - in.code_rate_chips_per_s / signals::kCaChipRate_hz) * dt;
      if (epoch.command_sample > epoch.sample) {
        // Pipelined: this command reaches the channel at command_sample; the one sent at the previous epoch takes
        // effect at next_epoch_sample (its jump there, its code rate from there), and this one at the first epoch
        // start at or after command_sample (20 ms of code at that rate later; a start that lands within half a
        // sample of command_sample counts as after it).
        double rate = in.code_rate_chips_per_s;
        if (st.commanded) {
          replica_m -= st.sent_jump_chips * kChip_m;
          rate = st.sent_code_rate_chips_per_s;
        }
        const double epoch_s = kEpochChips / rate;
        const double until_s = (static_cast<double>(epoch.command_sample - epoch.sample) - 0.5) / epoch.fs_hz;
        while (dt < until_s) {
          dt += epoch_s;
          replica_m += kC * (1.0 - rate / signals::kCaChipRate_hz) * epoch_s;
        }
      }
      const double prediction_m = r.pseudorange_m + r.range_rate_mps * dt - shift_m;
      jump = (replica_m - prediction_m) / kChip_m;  // replica too far away: advance it
      st.coast_s = in.coasting ? st.coast_s + ut_.period_s : 0.0;
      vector = std::abs(jump) <= ut_.max_jump_chips && st.coast_s <= ut_.max_coast_s && !st.runaway_given_up &&
               !st.nis_released;
      if (vector) {
        commands[i].vector = true;
        commands[i].filter_driven = true;
        commands[i].clock_steered = clock_loop_.has_value();
        commands[i].code_rate_chips_per_s = r.nco.code_rate_chips_per_s;
        commands[i].code_phase_jump_chips = jump;
        st.sent_code_rate_chips_per_s = r.nco.code_rate_chips_per_s;
        st.sent_jump_chips = jump;
        const auto change = aid_change.find(in.prn);
        if (!st.commanded || !std::isfinite(st.aid_hz) || change == aid_change.end())
          st.aid_hz = r.nco.carrier_frequency_hz;  // joins (the channel only uses changes of it)
        else
          st.aid_hz += change->second + clock_change_hz;
        // Carrier runaway: the aiding steps once by minus the offset of the last 5 epochs, which the channel adds to
        // its PLL's frequency (ScalarTracking::aid_frequency), putting it back on the prediction; the phase is flagged
        // while the channel is judged off (its phase is not the signal's, and the step starts a new arc).
        if (st.pending_step_hz != 0.0) {
          st.aid_hz += st.pending_step_hz;
          st.pending_step_hz = 0.0;
          ++runaway_recentres_;
        }
        commands[i].carrier_slip = st.runaway_off;
        commands[i].carrier_frequency_hz = st.aid_hz;
        // Pipelined, the aid reaches the PLL one period later: lead it by the period's change (the propagated
        // Doppler's ramp continued; 10 Hz per period in the 10 g turn, which lagging cost lock there).
        if (epoch.command_sample > epoch.sample && st.commanded && change != aid_change.end())
          commands[i].carrier_frequency_hz += change->second;
        ++commanded;
        ++channel_epochs_;
        if (in.coasting) ++coasting_channel_epochs_;
      }
    }
    if (st.commanded && !vector) {
      ++releases_;
      const char* why = !in.synchronised                ? "lost"
                        : rep == period_replicas_.end() ? "not_predicted"
                        : st.nis_released               ? "channel_nis"
                        : st.runaway_given_up           ? "runaway"
                        : st.coast_s > ut_.max_coast_s  ? "coast"
                                                        : "jump";
      release_log_.add(log_.time_s, in.prn, why, st.nis_released ? st.nis_detail : "");
    }
    if (!in.synchronised) {  // lost: a new track starts afresh
      st.runaway_given_up = false;
      if (st.nis_released) nis_.forget(in.prn);
      st.nis_released = false;
    }
    if (!vector) {
      st.runaway_repeats = 0;
      st.runaway.reset();
      st.runaway_off = false;
      st.pending_step_hz = 0.0;
    }
    st.ever = st.ever || vector;
    st.commanded = vector;
    const auto u = updates.find(in.prn);
    const fusion::UltraTightSatelliteUpdate* up = u == updates.end() ? nullptr : u->second;
    UltraTightChannelLog& l = log_.channels.emplace_back();
    l.prn = in.prn;
    l.synchronised = in.synchronised;
    l.ultratight = vector;
    l.coasting = in.coasting;
    l.coast_s = st.coast_s;
    l.cn0_dbhz = in.cn0_dbhz;
    l.measured_pseudorange_m = measured_m;
    l.predicted_pseudorange_m = predicted_m;
    l.measured_doppler_hz = in.has_doppler ? in.measured_doppler_hz : NAN;
    l.predicted_doppler_hz = predicted_doppler;
    l.replica_carrier_hz = in.has_measurement ? in.replica_carrier_frequency_hz : NAN;
    l.replica_code_rate_chips_per_s = in.code_rate_chips_per_s;
    l.predicted_code_rate_chips_per_s = vector ? commands[i].code_rate_chips_per_s : NAN;
    l.code_jump_chips = jump;
    l.updated = up != nullptr;
    l.accepted = up && up->accepted;
    l.nis = up ? up->nis : NAN;
    for (int k = 0; k < 6; ++k)
      l.innovation[static_cast<std::size_t>(k)] = up && k < up->innovation.size() ? up->innovation(k) : NAN;
    l.carrier_offset_hz = in.has_measurement ? st.last_offset_hz : NAN;
    l.carrier_runaway = vector && st.runaway_off;
  }
  sink_.on_ultratight_epoch(log_);
  if (commanded > 0) ++vector_epochs_;
}

void UltraTightLoop::update(const receiver::VectorEpochInput& epoch,
                            std::span<receiver::VectorChannelCommand> commands) {
  if (!driver_) {
    if (fusion_.handed_over() || !fusion_.integration() || !epoch.ephemerides) return;
    const auto origin = fusion_.imu_time_origin();
    const auto last = fusion_.last_epoch_time();
    if (!origin || !last) return;
    origin_ = *origin;
    const double t_k = last->second + static_cast<double>(epoch.sample - last->first) / epoch.fs_hz;
    const double t_ins = fusion_.integration()->output().nav.t_s;
    if (!first_integration_t_s_) first_integration_t_s_ = t_k;
    // The INS must not be ahead of this epoch (it steps whole IMU rows up to the observation epoch).
    if (t_k - *first_integration_t_s_ < ut_.handover_after_s || t_ins > t_k - 1e-6) return;
    start(epoch, t_k);
    feed_imu_to(t_k);
    driver_->start_period(ut_.period_s);
    period_open_ = true;
    command(epoch, t_k, commands, {});
    return;
  }
  const double t_k = imu_time(epoch, epoch.sample);
  // The last vector epochs of a file whose IMU rows end with the signal (as `simulate` writes them) may lie a
  // few ms past the last row: the loop stops there (the channels finish scalar); further out is an InputError.
  if (t_k > fusion_.imu().back().t_s + 1e-9 && t_k <= fusion_.imu().back().t_s + 0.1) return;
  feed_imu_to(t_k);
  const std::map<int, double> aid_change = propagated_doppler_change();
  for (auto& [prn, st] : channels_) st.last_offset_hz = NAN;  // set again by this epoch's measurements
  if (period_open_) {
    driver_->finish_period(correlations(epoch, t_k));
    nis_tests(static_cast<double>(epoch.sample) / epoch.fs_hz);
    if (driver_->counters().accepted > accepted_before_) gnss_last_used_s_ = t_ins_;
    accepted_before_ = driver_->counters().accepted;
  }
  // Sets decoded since the hand-over (the engine appends them): a satellite without one at the hand-over, or a new
  // IODE, is predicted from them from this period on (each from the set valid at its transmit time).
  if (epoch.ephemerides && epoch.ephemerides->size() > ephemerides_seen_) {
    const std::vector<signals::Ephemeris> fresh(
        epoch.ephemerides->begin() + static_cast<std::ptrdiff_t>(ephemerides_seen_), epoch.ephemerides->end());
    ephemerides_seen_ = epoch.ephemerides->size();
    driver_->add_ephemerides(fresh);
    ephemerides_.insert(ephemerides_.end(), fresh.begin(), fresh.end());
  }
  const double clock_change_hz = common_clock_update(epoch);
  driver_->start_period(ut_.period_s);
  period_open_ = true;
  for (const auto& in : epoch.channels) {
    ChannelState& st = channel(in.prn);
    if (st.was_coasting && !in.coasting && in.vector_mode) ++relocks_;
    if (in.coasting) nis_.forget(in.prn);  // a new arc after the re-lock
    st.since_relock_s = in.coasting ? 0.0 : st.since_relock_s + ut_.period_s;
    st.was_coasting = in.coasting;
  }
  last_sample_ = epoch.sample;
  last_t_s_ = t_k;
  command(epoch, t_k, commands, aid_change, clock_change_hz);
}

double UltraTightLoop::common_clock_update(const receiver::VectorEpochInput& epoch) {
  if (!clock_loop_) return 0.0;
  std::vector<receiver::ChannelPrompt> prompts;
  for (const auto& in : epoch.channels) {
    const auto it = channels_.find(in.prn);
    if (it == channels_.end()) continue;
    const ChannelState& st = it->second;
    if (!st.commanded || st.runaway_off || st.nis_released) continue;
    // A channel re-locking after a coast (a tunnel's exit) pulls its own phase in for its first second: its prompt
    // says nothing yet about the common clock (with it the loop was pushed 3 Hz off at a tunnel's exit).
    if (st.since_relock_s < ut_.nis_settle_s) continue;
    if (in.coasting || !fresh_prompt(in, ut_.period_s) || !std::isfinite(in.cn0_dbhz) || !(in.iq_scale > 0.0)) continue;
    // An epoch the fade gate dropped still counts once the channel's C/N0 estimate (0.2 s) reads below 30 dB-Hz:
    // after a step down to ~20 dB-Hz the gate drops most epochs until the 1 s presence window follows, and the loop,
    // short of channels, held while the TCXO moved (steered 2 Hz PLLs slipped 0.7-0.9 s after the step). Above
    // 30 dB-Hz the estimate still reads the signal of before a fade, and would weight its noise as that signal's.
    // (A signal test on the prompts' excess energy, to hold the loop on noise, was tried and dropped: on oracle-bit
    // files of campaigns/weak_signal.toml it came with whole files lost to a loop that ran off with every channel.)
    constexpr double kUngatedBelowDbHz = 30.0;
    if (!in.has_measurement && !(in.cn0_dbhz < kUngatedBelowDbHz)) continue;
    // The bit by the in-phase sign even where it is known: a channel that re-locked half a cycle off (a Costas
    // PLL may) has every known bit inverted, and its prompt would pull every channel by pi (seen at a tunnel's exit).
    prompts.push_back({in.iq_i[1], in.iq_q[1], 0, in.cn0_dbhz});
  }
  const double before = clock_loop_->frequency_hz();
  return clock_loop_->update(prompts) - before;
}

void UltraTightLoop::nis_tests(double t_s) {
  for (const auto& u : driver_->last_updates())
    if (channel(u.prn).since_relock_s >= ut_.nis_settle_s)
      nis_.add(u.prn, u.nis, static_cast<int>(u.innovation.size()));
  const fusion::NisVerdict v = nis_.evaluate();
  if (v.filter) {
    // Most channels contradict the filter at once: the filter is wrong, not they. Its covariance re-opens (what
    // the correlations observe: position, velocity, attitude, clock; biases kept) so that they pull it back.
    const double p = 0.5 * ut_.reopen_position_sigma_m, v_mps = 0.5 * ut_.reopen_velocity_sigma_mps;
    driver_->set_covariance(fusion::inflate_for_recovery(
        driver_->covariance(), Eigen::Vector3d::Constant(p),
        std::optional<Eigen::Vector3d>(Eigen::Vector3d::Constant(v_mps)), 1.0, fusion::LockoutRecoveryOptions{}, p));
    ++filter_reopens_;
    release_log_.add(t_s, 0, "filter_nis", v.reasons.front());
    return;
  }
  for (std::size_t i = 0; i < v.released.size(); ++i) {
    ChannelState& st = channel(v.released[i]);
    st.nis_released = true;
    st.nis_detail = v.reasons[i];
  }
}

void UltraTightLoop::finish(std::int64_t end_sample) {
  if (driver_ && last_sample_) {
    const double t_end = last_t_s_ + static_cast<double>(end_sample - *last_sample_) / options_.fs_hz;
    feed_imu_to(std::min(t_end, fusion_.imu().back().t_s));
  }
  record_odometer();
}

std::string UltraTightLoop::summary_json() const {
  const ReceiveOptions& s = fusion_.options();
  std::string j = fmt::format(
      "\"ultratight\": {{\"filter\": \"{}\", \"measurement\": \"{}\", \"handed_over\": {}, \"loop\": \"{}\"",
      s.filter == fusion::FilterKind::Ekf ? "ekf" : "ukf",
      s.ut_form == fusion::UltraTightForm::Iq ? "iq" : "discriminator", driver_.has_value(),
      s.ut_pipelined ? "pipelined" : "serial");
  if (!driver_) return j + "}";
  long long channels = 0;
  for (const auto& [prn, st] : channels_) channels += st.ever;
  const auto& k = driver_->counters();
  const auto& o = driver_->output();
  j += fmt::format(
      ", \"handover_t_s\": {:.3f}, \"handover_sample\": {}, \"end_t_s\": {:.3f}, \"channels_handed_over\": {}, "
      "\"vector_epochs\": {}, \"channel_epochs\": {}, \"coasting_channel_epochs\": {}, \"relocks\": {}, "
      "\"releases\": {}, \"measurements\": {}, \"known_bits\": {}, \"not_wiped\": {}, \"periods\": {}, \"updates\": "
      "{}, "
      "\"accepted\": {}, \"rejected\": {}, \"coasting_satellite_periods\": {}, \"aided_only_satellite_periods\": {}, "
      "\"carrier_recentres\": {}, \"runaway_left_out\": {}, \"runaway_releases\": {}",
      handover_t_s_, handover_sample_, o.nav.t_s, channels, vector_epochs_, channel_epochs_, coasting_channel_epochs_,
      relocks_, releases_, measurements_, known_bits_, not_wiped_, k.periods, k.updates, k.accepted, k.rejected,
      k.coasting, k.aided_only, runaway_recentres_, runaway_left_out_, runaway_releases_);
  j += fmt::format(
      ", \"carrier_rate\": {{\"window_s\": {:g}, \"updates\": {}, \"accepted\": {}, \"rows\": {}, \"screened\": {}}}",
      ut_.carrier_rate_window_s, k.rate_updates, k.rate_accepted, k.rate_rows, k.rate_screened);
  if (clock_loop_)
    j += fmt::format(", \"common_clock\": {{\"bandwidth_hz\": {:g}, \"updates\": {}, \"frequency_hz\": {:.4f}}}",
                     ut_.common_clock_bw_hz, clock_loop_->updates(), clock_loop_->frequency_hz());
  else
    j += ", \"common_clock\": null";
  j += fmt::format(", \"nis_window\": {}, \"nis_probability\": {:g}, \"filter_reopens\": {}, {}", ut_.nis.window,
                   ut_.nis.probability, filter_reopens_, release_log_.json_members());
  j += fmt::format(
      ", \"final_sigma\": {{\"north_m\": {:.6g}, \"east_m\": {:.6g}, \"down_m\": {:.6g}, "
      "\"clock_bias_m\": {:.6g}, \"clock_drift_mps\": {:.6g}}}}}",
      o.sigma_pos_ned_m.x(), o.sigma_pos_ned_m.y(), o.sigma_pos_ned_m.z(), o.sigma_clock_bias_m,
      o.sigma_clock_drift_mps);
  return j;
}

std::string UltraTightLoop::report() const {
  if (!driver_)
    return "receive: ultra-tight: never handed over (the tight integration did not start or ran too briefly)";
  const auto& k = driver_->counters();
  long long channels = 0;
  for (const auto& [prn, st] : channels_) channels += st.ever;
  return fmt::format(
      "receive: ultra-tight {} ({}) from {:.3f} s: {} channels handed over, {} channel-epochs "
      "commanded ({} coasting), {} re-locks, {} releases; updates accepted {}, rejected {}; "
      "satellite-periods aided only (below the measurement mask) {}; carrier runaways re-centred {}, released {}; "
      "released by their NIS {}, filter re-opened {}; carrier-phase rate updates accepted {} of {} ({} rows, {} "
      "screened out)",
      fusion_.options().filter == fusion::FilterKind::Ekf ? "EKF" : "UKF",
      fusion_.options().ut_form == fusion::UltraTightForm::Iq ? "I&Q" : "discriminators", handover_t_s_, channels,
      channel_epochs_, coasting_channel_epochs_, relocks_, releases_, k.accepted, k.rejected, k.aided_only,
      runaway_recentres_, runaway_releases_, release_log_.count("channel_nis"), filter_reopens_, k.rate_accepted,
      k.rate_updates, k.rate_rows, k.rate_screened);
}

}  // namespace ultratrack::pipelines
