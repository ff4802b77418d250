// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/scalar_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/why_invalid.hpp"
#include "receiver/discriminators.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kSmoothing_s = 0.1;
constexpr double kBitPeriod_s = 0.02;

int epochs_in(double window_s, double t_s) { return std::max(1, static_cast<int>(std::lround(window_s / t_s))); }

// The moments method estimates the noise as a small difference of large moments at high SNR: it needs more
// epochs per window than the noise-tap ratio (50 keeps its spread below ~0.5 dB at 45 dB-Hz, 20 ms).
int cn0_window_epochs(Cn0Method method, double window_s, double t_s) {
  const int n = epochs_in(window_s, t_s);
  return method == Cn0Method::kMoments ? std::max(n, 50) : n;
}

const ScalarTrackingOptions& valid(const ScalarTrackingOptions& o) {
  if (auto e = io::why_invalid(o); !e.empty()) throw std::invalid_argument(e);
  return o;
}

}  // namespace

const char* to_string(TrackingState s) {
  switch (s) {
    case TrackingState::kPullIn:
      return "pull-in";
    case TrackingState::kPhaseLocked:
      return "phase-locked";
    case TrackingState::kBitSynced:
      return "bit-synced";
    case TrackingState::kLost:
      return "lost";
    case TrackingState::kCoasting:
      return "coasting";
  }
  return "?";
}

ScalarTracking::ScalarTracking(const ScalarTrackingOptions& options, const NcoCommand& initial)
    : opt_(valid(options)),
      // The PLL pulls in as 2nd order (a 3rd-order loop's rate state random-walks while cycles slip) and takes the
      // configured order at phase lock.
      carrier_(2, options.pll_bw_hz, 0.0, initial.carrier_frequency_hz),
      command_(initial),
      pli_(options.pli_time_constant_s),
      cn0_(options.cn0_method, cn0_window_epochs(options.cn0_method, options.cn0_window_s, 1e-3)),
      bit_sync_(options.bit_sync),
      pull_in_(options, initial.carrier_frequency_hz),
      long_(options),
      loss_(options) {
  command_.code_phase_jump_chips = 0.0;
  command_.carrier_phase_jump_cycles = 0.0;
  pll_bw_now_hz_ = opt_.pll_bw_hz;
}

void ScalarTracking::apply(const ScalarTrackingControl& c) {
  allow_coasting(c.coasting_allowed);
  set_filter_driven(c.filter_driven);
  clock_steered_ = c.clock_steered;
  const bool commanded = c.carrier != CarrierControl::kAided;
  set_carrier_commanded(commanded, c.carrier == CarrierControl::kFrequencyAndPhase);
  if (commanded) {
    command_carrier(c.carrier_frequency_hz);
  } else if (c.aid == CarrierAid::kStart) {
    start_aiding();
  } else if (c.aid == CarrierAid::kShift) {
    aid_frequency(c.aid_delta_hz);
  }
}

ScalarTrackingControl ScalarTracking::control() const {
  ScalarTrackingControl c;
  c.coasting_allowed = coasting_allowed_;
  c.filter_driven = filter_driven_;
  c.clock_steered = clock_steered_;
  c.carrier = !carrier_commanded_     ? CarrierControl::kAided
              : carrier_phase_locked_ ? CarrierControl::kFrequencyAndPhase
                                      : CarrierControl::kFrequency;
  return c;
}

void ScalarTracking::aid_frequency(double delta_hz) {
  if ((state_ != TrackingState::kBitSynced && state_ != TrackingState::kCoasting) || !std::isfinite(delta_hz)) return;
  carrier_.reset(carrier_.frequency_hz() + delta_hz, carrier_.frequency_rate_hzps());
  command_.carrier_frequency_hz += delta_hz;
}

void ScalarTracking::start_aiding() {
  if (state_ != TrackingState::kBitSynced) return;
  carrier_.reset(carrier_.frequency_hz(), 0.0);
}

void ScalarTracking::set_filter_driven(bool driven) {
  if (driven == filter_driven_) return;
  filter_driven_ = driven;
  loss_.reset_presence();
  loss_.clear_presence_absent();
  loss_.restart();
}

void ScalarTracking::set_carrier_commanded(bool commanded, bool phase_locked) {
  phase_locked = commanded && phase_locked;
  if (commanded == carrier_commanded_) {
    if (commanded && phase_locked != carrier_phase_locked_ && bits_) bits_->set_differential(!phase_locked);
    carrier_phase_locked_ = phase_locked;
    return;
  }
  carrier_commanded_ = commanded;
  carrier_phase_locked_ = phase_locked;
  if (bits_) bits_->set_differential(commanded && !phase_locked);
  long_.drop_block();  // a partial long sum of the PLL is void either way
  if (commanded) {
    long_.set_target_epochs(1);
    if (long_.enabled() && state_ == TrackingState::kBitSynced) set_loop_epochs(1);
    return;
  }
  // Back to the PLL: it starts from the commanded frequency with no rate; the PLI, which read the FLL's wandering
  // phase, restarts (empty, it reads 0: the loss test waits loss_of_lock_time_s while the PLL pulls in).
  carrier_.reset(command_.carrier_frequency_hz, 0.0);
  pli_.reset();
  loss_.restart();
}

void ScalarTracking::command_carrier(double frequency_hz) {
  if (!carrier_commanded_ || !std::isfinite(frequency_hz)) return;
  if (state_ != TrackingState::kBitSynced && state_ != TrackingState::kCoasting) return;
  carrier_.reset(frequency_hz, 0.0);
  command_.carrier_frequency_hz = frequency_hz;
}

void ScalarTracking::allow_coasting(bool allowed) {
  coasting_allowed_ = allowed;
  if (!allowed && state_ == TrackingState::kCoasting) {
    state_ = TrackingState::kLost;
    relocking_ = false;
  }
}

int ScalarTracking::known_bits_wanted() const {
  if (!long_.enabled() || state_ != TrackingState::kBitSynced || carrier_commanded_) return 0;
  return long_.known_bits_wanted();
}

void ScalarTracking::set_loop_epochs(int epochs) { long_.set_loop_epochs(epochs, bridging(), carrier_, pli_); }

bool ScalarTracking::bridging() const { return long_.bridging(state_ == TrackingState::kBitSynced, time_s_); }

TrackingReport ScalarTracking::update(const CorrelationEpoch& e, KnownBits known) {
  TrackingReport r;
  const double t = e.integration_time_s;
  const CorrelatorTaps& taps = e.master();
  time_s_ += t;
  r.loop_integration_ms = e.num_code_periods;
  // Long coherent integration: a block of target_epochs epochs starts only where that many bits are known; a
  // gap or an unknown bit inside a block drops its partial sum (the command given stays in force).
  const bool long_ready =
      long_.enabled() && state_ == TrackingState::kBitSynced && e.num_code_periods == 20 && !carrier_commanded_;
  if (long_.block_count() > 0 && (!long_ready || known.sign == 0 || !long_.continues_block(e))) long_.drop_block();
  const bool long_path =
      long_ready && known.sign != 0 &&
      (long_.block_count() > 0 || (long_.target_epochs() > 1 && known.ahead >= long_.target_epochs()));

  // Lock detectors. Their statistics depend on the epoch length: restart them when it changes.
  if (e.num_code_periods != cn0_epoch_periods_) {
    cn0_epoch_periods_ = e.num_code_periods;
    cn0_ = Cn0Estimator(opt_.cn0_method, cn0_window_epochs(opt_.cn0_method, opt_.cn0_window_s, t));
    pli_.reset();
  }
  if (opt_.cn0_method == Cn0Method::kNoiseTap) {
    const double n2 = std::norm(std::complex<double>(taps.noise));
    if (e.num_code_periods != noise_epoch_periods_ || noise_power_ == 0.0) {
      noise_epoch_periods_ = e.num_code_periods;
      noise_power_ = n2;
    } else {
      noise_power_ += std::min(1.0, t / opt_.cn0_window_s) * (n2 - noise_power_);
    }
  }
  r.pli = long_path ? pli_.value() : pli_.update(taps.prompt, noise_power_, t);
  if (auto c = cn0_.add(taps.prompt, taps.noise, t)) {
    cn0_dbhz_ = *c;
    if (long_.enabled()) long_.add_cn0(*c, state_ == TrackingState::kBitSynced, clock_steered_);
  }
  r.cn0_dbhz = cn0_dbhz_;
  fade_.add(taps.prompt, taps.noise, cn0_dbhz_, t);
  r.phase_locked = r.pli >= opt_.pli_lock_threshold;
  // Filter-driven: the presence test on every 20 ms epoch (long sums included: energy, not phase); while
  // coasting it looks for the signal's return.
  loss_.presence_epoch(filter_driven_ && (state_ == TrackingState::kBitSynced || state_ == TrackingState::kCoasting) &&
                           e.num_code_periods == 20,
                       state_ == TrackingState::kBitSynced, state_ == TrackingState::kCoasting, taps.prompt, taps.noise,
                       t);

  r.phase_error_cycles = costas_atan_cycles(taps.prompt);
  r.frequency_error_hz = pull_in_.frequency_error_hz(e, time_s_);
  r.code_error_chips = dll_nelp_chips(taps.early, taps.late, opt_.early_late_offset_chips);
  if (long_path) return long_coherent_epoch(e, r, known.sign);

  if (state_ == TrackingState::kLost) {
    r.state = state_;
    r.command = command_;
    return r;
  }

  if (state_ == TrackingState::kCoasting) return coast_epoch(e, r, true);

  // State machine.
  if (state_ == TrackingState::kPullIn) {
    // Phase lock can only be judged once the PLL runs (after the FLL stages) and the PLI has settled on it.
    const double pll_start_s = pull_in_.pll_start_s();
    if (time_s_ > pll_start_s && time_s_ - t <= pll_start_s) pli_.reset();
    const bool judged = time_s_ > pll_start_s + opt_.pli_time_constant_s;
    locked_time_s_ = judged && r.phase_locked ? locked_time_s_ + t : 0.0;
    if (locked_time_s_ >= opt_.pullin_lock_time_s) {
      state_ = TrackingState::kPhaseLocked;
      ever_locked_ = true;
      carrier_.set_bandwidths(opt_.pll_bw_hz, 0.0);
      pll_bw_now_hz_ = opt_.pll_bw_hz;
      carrier_.set_order(opt_.pll_order);
    } else if (time_s_ > opt_.pullin_timeout_s) {
      state_ = TrackingState::kLost;
    }
  }
  if (state_ == TrackingState::kPhaseLocked) {
    if (e.num_code_periods == 1 && !bit_sync_.synchronised()) bit_sync_.add(e.first_code_period, taps.prompt);
    if (bit_sync_.synchronised() && !coherent_requested_) {
      coherent_requested_ = true;
      r.set_coherent = true;
      r.coherent_periods = opt_.coherent_ms;
      r.aligned_period = bit_sync_.edge_period();
      bits_.emplace(bit_sync_.edge_period());
    }
    if (coherent_requested_ && e.num_code_periods == opt_.coherent_ms) {
      state_ = TrackingState::kBitSynced;
      carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, 0.0);
      // The wide 1 ms loop's frequency, and much more its frequency rate, carry noise that would make the narrow
      // loop ring for seconds: restart it from the smoothed frequency and no rate (a static receiver sees
      // < 1 Hz/s, which the narrow loop then acquires within ~2 s).
      carrier_.reset(smoothed_frequency_hz_, 0.0);
    }
  }
  if (bits_) r.bit = bits_->add(e);

  // Loss of lock: low C/N0 at any time, or (once phase lock was achieved) a low PLI, held for the loss time.
  // (While weak enough for long coherent integration, 20 ms updates bridging unknown bits between long updates
  // judge the C/N0 as the long updates do; with no long update for 10 s, the plain 20 ms test holds.)
  const bool weak_bridge = bridging();
  const bool low_cn0 =
      weak_bridge ? long_.slow_cn0_below(opt_.cn0_loss_threshold_dbhz - 10.0 * std::log10(long_.target_epochs()))
                  : cn0_dbhz_ && *cn0_dbhz_ < opt_.cn0_loss_threshold_dbhz;
  // (A carrier the vector FLL commands is not phase-locked: its PLI says nothing about the signal.)
  const bool fll = carrier_commanded_ && state_ == TrackingState::kBitSynced;
  const bool low_pli = ever_locked_ && r.pli < opt_.pli_loss_threshold && !fll;
  if (loss_.epoch_lost(low_cn0 || low_pli, filter_driven_ && state_ == TrackingState::kBitSynced, t)) {
    const bool coast = coasting_allowed_ && state_ == TrackingState::kBitSynced;
    state_ = coast ? TrackingState::kCoasting : TrackingState::kLost;
    if (coast) return coast_epoch(e, r, false);
  }
  r.state = state_;
  if (state_ == TrackingState::kLost) {
    r.command = command_;  // coast on the last frequencies
    return r;
  }

  // Loops.
  // Pull-in stages (see ScalarTrackingOptions): a frequency search or first-order FLLs alone, a fine FLL, then
  // the PLL alone.
  const PullInStage pullin_stage = state_ == TrackingState::kPullIn ? pull_in_.stage(time_s_) : PullInStage::kPll;
  const bool coherent = state_ == TrackingState::kBitSynced;
  if (coherent && long_.enabled()) set_loop_epochs(1);
  // After phase lock on 1 ms epochs: the narrower PLL while the signal is weak.
  if (state_ == TrackingState::kPhaseLocked && e.num_code_periods == 1 && cn0_dbhz_) {
    const double bw = *cn0_dbhz_ < opt_.weak_cn0_dbhz ? std::min(opt_.pll_bw_weak_hz, opt_.pll_bw_hz) : opt_.pll_bw_hz;
    if (bw != pll_bw_now_hz_) {
      carrier_.set_bandwidths(bw, 0.0);
      pll_bw_now_hz_ = bw;
    }
  }
  double f = 0.0;
  if (pullin_stage != PullInStage::kPll) {
    f = pull_in_.step(pullin_stage, e, time_s_, carrier_, &r.frequency_error_hz);
  } else if (coherent && carrier_commanded_) {
    f = command_.carrier_frequency_hz;  // the vector FLL's (command_carrier)
  } else if (aided_hold()) {
    f = carrier_.frequency_hz();  // faded: the aiding alone moves the carrier
  } else {
    f = carrier_.update(r.phase_error_cycles, 0.0, t);
  }
  const double dll_bw = coherent ? opt_.dll_bw_coherent_hz : opt_.dll_bw_hz;
  if (state_ == TrackingState::kPhaseLocked) {  // smoothed over kSmoothing_s for the switch to coherent epochs
    if (!smoothing_started_) smoothed_frequency_hz_ = f;
    smoothing_started_ = true;
    smoothed_frequency_hz_ += std::min(1.0, t / kSmoothing_s) * (f - smoothed_frequency_hz_);
  }
  command_.carrier_frequency_hz = f;
  command_.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 + f / signals::kL1Frequency_hz) +
                                   dll_rate_correction_chips_per_s(r.code_error_chips, dll_bw);
  r.command = command_;
  return r;
}

// Lock lost during long coherent integration: back to 20 ms loops, then coasting (when allowed) or lost.
TrackingReport ScalarTracking::lose_long_coherent_lock(const CorrelationEpoch& e, TrackingReport& r, bool add_bit) {
  loss_.restart();
  long_.set_target_epochs(1);
  set_loop_epochs(1);
  if (coasting_allowed_) {
    state_ = TrackingState::kCoasting;
    return coast_epoch(e, r, add_bit);
  }
  state_ = TrackingState::kLost;
  r.state = state_;
  r.command = command_;
  return r;
}

// One 20 ms epoch of long coherent integration: its taps, sign-corrected, go into the block; at the block's end
// the loops, the PLI and the loss test run once on the block's sums with T = its length.
TrackingReport ScalarTracking::long_coherent_epoch(const CorrelationEpoch& e, TrackingReport& r, int sign) {
  if (filter_driven_ && loss_.presence_absent()) {  // the presence window just ended without signal: the block is void
    long_.drop_block();
    r.state = state_;
    r.loop_integration_ms = 20;
    return lose_long_coherent_lock(e, r, true);
  }
  if (long_.block_count() == 0 && long_.start_block(carrier_)) {
    // A block of a new length: the command held through it is the loop's state for that length, f(t + T / 2)
    // (the first epoch already ran on the previous command). The previous command carries the last shorter
    // update's proportional term, noise there (+-0.5-1 Hz on 20 ms updates at 30 dB-Hz), 5x as much phase
    // when held 100 ms: a 30-45 deg excursion before the first long update.
    const double f =
        carrier_.frequency_hz() - 0.5 * carrier_.frequency_rate_hzps() * long_.block_epochs() * kBitPeriod_s;
    command_.code_rate_chips_per_s +=
        signals::kCaChipRate_hz * (f - command_.carrier_frequency_hz) / signals::kL1Frequency_hz;
    command_.carrier_frequency_hz = f;
  }
  const bool complete = long_.add(e, sign);
  if (bits_) r.bit = bits_->add(e);
  r.state = state_;
  r.loop_integration_ms = long_.block_epochs() * 20;
  if (!complete) {
    r.pli = pli_.value();
    r.phase_locked = r.pli >= opt_.pli_lock_threshold;
    r.command = command_;
    return r;
  }
  const CoherentBlockSums block = long_.finish_block(time_s_);
  const int n = block.epochs;
  const double t = block.time_s;
  set_loop_epochs(n);
  const std::complex<float> prompt(block.prompt);
  // The sum of n 20 ms epochs holds n times their noise power.
  r.pli = pli_.update(prompt, n * noise_power_, t);
  r.phase_locked = r.pli >= opt_.pli_lock_threshold;
  // Bits wiped: a filter-driven channel's PLL takes the full phase (atan2, +-1/2 cycle, no squaring loss).
  r.phase_error_cycles = filter_driven_ ? pll_atan2_cycles(prompt) : costas_atan_cycles(prompt);
  r.frequency_error_hz = 0.0;
  r.code_error_chips =
      dll_nelp_chips(std::complex<float>(block.early), std::complex<float>(block.late), opt_.early_late_offset_chips);
  const bool low_cn0 = long_.slow_cn0_below(opt_.cn0_loss_threshold_dbhz - 10.0 * std::log10(n));
  const bool low_pli = r.pli < opt_.pli_loss_threshold;
  if (loss_.long_update_lost(low_cn0 || low_pli, filter_driven_, t, long_.pli_time_constant_s()))
    return lose_long_coherent_lock(e, r, false);
  const double f = aided_hold() ? carrier_.frequency_hz() : carrier_.update(r.phase_error_cycles, 0.0, t);
  const double dll_bw = std::min(opt_.dll_bw_coherent_hz, opt_.coherent_max_bn_t / t);
  command_.carrier_frequency_hz = f;
  command_.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 + f / signals::kL1Frequency_hz) +
                                   dll_rate_correction_chips_per_s(r.code_error_chips, dll_bw);
  r.command = command_;
  return r;
}

// Coasting: the carrier holds the aided (predicted) frequency and the code the nominal rate at that frequency (the
// vector loop's commands replace it) while the signal is gone; once the C/N0 estimate is back above the loss
// threshold plus relock_margin_dbhz, an FLL-assisted Costas PLL starts from that frequency, and a PLI held for
// pullin_lock_time_s ends coasting. Bits keep being assembled on the known bit edges (noise while faded).
// A filter-driven channel whose presence test finds the signal again: bit-synced at once, the carrier loop
// restarted (20 ms, no rate) from the frequency it coasted on (the filter's prediction); long coherent
// integration resumes with the next C/N0 estimate. No frequency pull-in: the replica never left the prediction,
// and at the weak levels this serves (15-20 dB-Hz) the relock FLL's two 10 ms halves carry no usable phase.
void ScalarTracking::relock_from_presence() {
  state_ = TrackingState::kBitSynced;
  relocking_ = false;
  loss_.restart();
  locked_time_s_ = 0.0;
  long_.set_target_epochs(1);
  long_.drop_block();
  long_.restart_20ms_loops();  // the carrier state below is for 20 ms updates (rereference_carrier_state)
  carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, 0.0);
  carrier_.reset(command_.carrier_frequency_hz, 0.0);
  pli_.reset();
  pli_.set_time_constant(opt_.pli_time_constant_s);
  loss_.reset_presence();
}

TrackingReport ScalarTracking::coast_epoch(const CorrelationEpoch& e, TrackingReport& r, bool add_bit) {
  const double t = e.integration_time_s;
  if (filter_driven_ && loss_.presence_found()) {
    relock_from_presence();
    if (bits_ && add_bit) r.bit = bits_->add(e);
    r.state = state_;
    r.command = command_;
    return r;
  }
  const bool strong = cn0_dbhz_ && *cn0_dbhz_ >= opt_.cn0_loss_threshold_dbhz + opt_.relock_margin_dbhz;
  if (strong && !relocking_) {
    relocking_ = true;
    locked_time_s_ = 0.0;
    carrier_.reset(command_.carrier_frequency_hz, 0.0);
    carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, 0.0);
    pli_.reset();
    pli_.set_time_constant(opt_.pli_time_constant_s);
    long_.restart_20ms_loops();
    relock_fll_ = {};
    relock_s_ = 0.0;
  } else if (!strong && relocking_) {
    relocking_ = false;  // faded again: hold the frequency the PLL reached
  }
  double f = command_.carrier_frequency_hz;
  if (carrier_commanded_) {
    // Vector FLL: the carrier is the filter's whether the signal is there or not; once the C/N0 is back the
    // channel is bit-synced again (no phase to re-lock). The differential bit chain runs on through the fade on
    // noise: its polarity may come back inverted, which the decoder's next preamble resolves.
    relocking_ = false;
    if (strong) {
      state_ = TrackingState::kBitSynced;
      loss_.restart();
    }
  } else if (relocking_) {
    // Frequency error from the epoch's two halves (bit-edge free: +-1 / t, i.e. +-50 Hz at 20 ms, where the
    // successive-epoch discriminator is bit-ambiguous beyond +-1 / (4 t) and would let the PLL lock 1 / t off).
    const CrossDot cd = cross_dot(e.prompt_halves[0], e.prompt_halves[1]);
    relock_fll_.cross += 0.5 * (cd.cross - relock_fll_.cross);
    relock_fll_.dot += 0.5 * (cd.dot - relock_fll_.dot);
    r.frequency_error_hz = std::atan2(relock_fll_.cross, relock_fll_.dot) / (kTwoPi * 0.5 * t);
    relock_s_ += t;
    if (relock_s_ <= opt_.relock_fll_time_s) {  // FLL alone first, then the PLL alone (as the pull-in)
      f = carrier_.update_fll_only(r.frequency_error_hz, opt_.relock_fll_bw_hz, t);
      if (relock_s_ + t > opt_.relock_fll_time_s) pli_.reset();
    } else {
      if (carrier_.fll_bw_hz() != opt_.relock_assist_bw_hz)
        carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, opt_.relock_assist_bw_hz);
      f = carrier_.update(r.phase_error_cycles, r.frequency_error_hz, t);
    }
    // locked: the PLI holds and the frequency discriminator agrees (a PLL can hold a Costas lock 1 / t off)
    const bool on_frequency = std::abs(r.frequency_error_hz) < 0.25 / t;
    locked_time_s_ = relock_s_ > opt_.relock_fll_time_s && r.phase_locked && on_frequency ? locked_time_s_ + t : 0.0;
    if (locked_time_s_ >= opt_.pullin_lock_time_s) {
      state_ = TrackingState::kBitSynced;
      relocking_ = false;
      loss_.restart();
      carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, 0.0);
      carrier_.reset(carrier_.frequency_hz(), 0.0);  // the aiding brings the dynamics; pull-in noise goes
    }
  }
  if (bits_ && add_bit) r.bit = bits_->add(e);
  command_.carrier_frequency_hz = f;
  command_.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 + f / signals::kL1Frequency_hz);
  r.state = state_;
  r.command = command_;
  return r;
}

}  // namespace ultratrack::receiver
