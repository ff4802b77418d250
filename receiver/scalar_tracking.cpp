#include "receiver/scalar_tracking.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "receiver/discriminators.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

// Appends "name = value outside range" when !ok, for the first failure only.
struct Checker {
  std::string error;
  void check(bool ok, const char* name, double value, const char* range) {
    if (ok || !error.empty()) return;
    std::ostringstream s;
    s << "tracking option " << name << " = " << value << " is outside " << range;
    error = s.str();
  }
};

int epochs_in(double window_s, double t_s) { return std::max(1, static_cast<int>(std::lround(window_s / t_s))); }

}  // namespace

std::string validation_error(const ScalarTrackingOptions& o) {
  Checker c;
  c.check(o.pll_order == 2 || o.pll_order == 3, "pll_order", o.pll_order, "{2, 3}");
  c.check(o.pll_bw_hz > 0 && o.pll_bw_hz <= 50, "pll_bw_hz", o.pll_bw_hz, "(0, 50] Hz");
  c.check(o.pll_bw_coherent_hz > 0 && o.pll_bw_coherent_hz <= 15, "pll_bw_coherent_hz", o.pll_bw_coherent_hz, "(0, 15] Hz");
  c.check(o.fll_bw_hz > 0 && o.fll_bw_hz <= 50, "fll_bw_hz", o.fll_bw_hz, "(0, 50] Hz");
  c.check(o.fll_wide_time_s >= 0.01 && o.fll_wide_time_s <= 5, "fll_wide_time_s", o.fll_wide_time_s, "[0.01, 5] s");
  c.check(o.fll_narrow_time_s >= 0 && o.fll_narrow_time_s <= 5, "fll_narrow_time_s", o.fll_narrow_time_s, "[0, 5] s");
  c.check(o.fll_narrow_bw_hz > 0 && o.fll_narrow_bw_hz <= 20, "fll_narrow_bw_hz", o.fll_narrow_bw_hz, "(0, 20] Hz");
  c.check(o.pullin_lock_time_s >= 0.01 && o.pullin_lock_time_s <= 2, "pullin_lock_time_s", o.pullin_lock_time_s, "[0.01, 2] s");
  c.check(o.pullin_timeout_s >= 0.1 && o.pullin_timeout_s <= 30, "pullin_timeout_s", o.pullin_timeout_s, "[0.1, 30] s");
  c.check(o.dll_bw_hz > 0 && o.dll_bw_hz <= 10, "dll_bw_hz", o.dll_bw_hz, "(0, 10] Hz");
  c.check(o.dll_bw_coherent_hz > 0 && o.dll_bw_coherent_hz <= 5, "dll_bw_coherent_hz", o.dll_bw_coherent_hz, "(0, 5] Hz");
  c.check(o.early_late_offset_chips > 0 && o.early_late_offset_chips <= 0.5, "early_late_offset_chips",
          o.early_late_offset_chips, "(0, 0.5] chips");
  c.check(!o.very_early_late || (o.very_early_late_offset_chips > o.early_late_offset_chips && o.very_early_late_offset_chips <= 2),
          "very_early_late_offset_chips", o.very_early_late_offset_chips, "(early_late_offset_chips, 2] chips");
  c.check(o.coherent_ms == 1 || o.coherent_ms == 2 || o.coherent_ms == 4 || o.coherent_ms == 5 || o.coherent_ms == 10 ||
              o.coherent_ms == 20,
          "coherent_ms", o.coherent_ms, "{1, 2, 4, 5, 10, 20} ms");
  c.check(o.bit_sync.min_edges >= 3 && o.bit_sync.min_edges <= 1000, "bit_sync.min_edges", o.bit_sync.min_edges, "[3, 1000]");
  c.check(o.bit_sync.min_ratio >= 1.5 && o.bit_sync.min_ratio <= 100, "bit_sync.min_ratio", o.bit_sync.min_ratio, "[1.5, 100]");
  c.check(o.bit_sync.max_periods >= 200, "bit_sync.max_periods", o.bit_sync.max_periods, "[200, inf)");
  c.check(o.cn0_window_s >= 0.02 && o.cn0_window_s <= 5, "cn0_window_s", o.cn0_window_s, "[0.02, 5] s");
  c.check(o.cn0_loss_threshold_dbhz >= 0 && o.cn0_loss_threshold_dbhz <= 45, "cn0_loss_threshold_dbhz",
          o.cn0_loss_threshold_dbhz, "[0, 45] dB-Hz");
  c.check(o.pli_time_constant_s >= 0.005 && o.pli_time_constant_s <= 5, "pli_time_constant_s", o.pli_time_constant_s, "[0.005, 5] s");
  c.check(o.pli_lock_threshold > 0 && o.pli_lock_threshold < 1, "pli_lock_threshold", o.pli_lock_threshold, "(0, 1)");
  c.check(o.pli_loss_threshold >= -1 && o.pli_loss_threshold < o.pli_lock_threshold, "pli_loss_threshold",
          o.pli_loss_threshold, "[-1, pli_lock_threshold)");
  c.check(o.loss_of_lock_time_s >= 0.02 && o.loss_of_lock_time_s <= 10, "loss_of_lock_time_s", o.loss_of_lock_time_s, "[0.02, 10] s");
  return c.error;
}

ChannelConfig channel_config(const ScalarTrackingOptions& o, int prn, double sample_rate_hz, int num_antennas) {
  ChannelConfig c;
  c.prn = prn;
  c.sample_rate_hz = sample_rate_hz;
  c.num_antennas = num_antennas;
  c.layout.early_late_offset_chips = o.early_late_offset_chips;
  c.layout.very_early_late = o.very_early_late;
  c.layout.very_early_late_offset_chips = o.very_early_late_offset_chips;
  c.layout.noise = o.cn0_method == Cn0Method::kNoiseTap;
  return c;
}

const char* to_string(TrackingState s) {
  switch (s) {
    case TrackingState::kPullIn: return "pull-in";
    case TrackingState::kPhaseLocked: return "phase-locked";
    case TrackingState::kBitSynced: return "bit-synced";
    case TrackingState::kLost: return "lost";
  }
  return "?";
}

namespace {
const ScalarTrackingOptions& valid(const ScalarTrackingOptions& o) {
  if (auto e = validation_error(o); !e.empty()) throw std::invalid_argument(e);
  return o;
}
}  // namespace

ScalarTracking::ScalarTracking(const ScalarTrackingOptions& options, const NcoCommand& initial)
    : opt_(valid(options)),
      carrier_(options.pll_order, options.pll_bw_hz, options.fll_bw_hz, initial.carrier_frequency_hz),
      command_(initial),
      pli_(options.pli_time_constant_s),
      cn0_(options.cn0_method, epochs_in(options.cn0_window_s, 1e-3)),
      bit_sync_(options.bit_sync) {
  command_.code_phase_jump_chips = 0.0;
  command_.carrier_phase_jump_cycles = 0.0;
}

TrackingReport ScalarTracking::update(const CorrelationEpoch& e) {
  TrackingReport r;
  const double t = e.integration_time_s;
  const CorrelatorTaps& taps = e.master();
  time_s_ += t;

  // Lock detectors. Their statistics depend on the epoch length: restart them when it changes.
  if (e.num_code_periods != cn0_epoch_periods_) {
    cn0_epoch_periods_ = e.num_code_periods;
    cn0_ = Cn0Estimator(opt_.cn0_method, epochs_in(opt_.cn0_window_s, t));
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
  r.pli = pli_.update(taps.prompt, noise_power_, t);
  if (auto c = cn0_.add(taps.prompt, taps.noise, t)) cn0_dbhz_ = *c;
  r.cn0_dbhz = cn0_dbhz_;
  r.phase_locked = r.pli >= opt_.pli_lock_threshold;

  r.phase_error_cycles = costas_atan_cycles(taps.prompt);
  const bool wide_fll = time_s_ <= opt_.fll_wide_time_s || previous_t_s_ == 0.0;
  r.frequency_error_hz = wide_fll ? fll_atan2_hz(e.prompt_halves[0], e.prompt_halves[1], 0.5 * t)
                                  : fll_atan_hz(previous_prompt_, taps.prompt, 0.5 * (previous_t_s_ + t));
  previous_prompt_ = taps.prompt;
  previous_t_s_ = t;
  r.code_error_chips = dll_nelp_chips(taps.early, taps.late, opt_.early_late_offset_chips);

  if (state_ == TrackingState::kLost) {
    r.state = state_;
    r.command = command_;
    return r;
  }

  // State machine.
  if (state_ == TrackingState::kPullIn) {
    locked_time_s_ = r.phase_locked ? locked_time_s_ + t : 0.0;
    if (locked_time_s_ >= opt_.pullin_lock_time_s) {
      state_ = TrackingState::kPhaseLocked;
      ever_locked_ = true;
      carrier_.set_bandwidths(opt_.pll_bw_hz, 0.0);
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
      // The wide 1 ms loop's frequency (and more so its frequency rate) carries noise that would make the narrow
      // loop ring for seconds: restart it from the smoothed frequency, and no rate (a static or vehicle receiver sees < ~10 Hz/s).
      carrier_.reset(smoothed_frequency_hz_, 0.0);
    }
  }
  if (bits_) r.bit = bits_->add(e);

  // Loss of lock: low C/N0 at any time, or (once phase lock was achieved) a low PLI, held for the loss time.
  const bool low_cn0 = cn0_dbhz_ && *cn0_dbhz_ < opt_.cn0_loss_threshold_dbhz;
  const bool low_pli = ever_locked_ && r.pli < opt_.pli_loss_threshold;
  loss_time_s_ = (low_cn0 || low_pli) ? loss_time_s_ + t : 0.0;
  if (loss_time_s_ >= opt_.loss_of_lock_time_s) state_ = TrackingState::kLost;
  r.state = state_;
  if (state_ == TrackingState::kLost) {
    r.command = command_;  // coast on the last frequencies
    return r;
  }

  // Loops.
  if (state_ == TrackingState::kPullIn)
    carrier_.set_bandwidths(opt_.pll_bw_hz, time_s_ <= opt_.fll_wide_time_s ? opt_.fll_bw_hz : opt_.fll_narrow_bw_hz);
  const bool coherent = state_ == TrackingState::kBitSynced;
  // The wide FLL runs alone: a PLL fed with the phase of a signal it does not yet follow only random-walks
  // its integrators.
  const bool fll_only = state_ == TrackingState::kPullIn && time_s_ <= opt_.fll_wide_time_s + opt_.fll_narrow_time_s;
  const double f = carrier_.update(fll_only ? 0.0 : r.phase_error_cycles, r.frequency_error_hz, t);
  const double dll_bw = coherent ? opt_.dll_bw_coherent_hz : opt_.dll_bw_hz;
  if (state_ == TrackingState::kPhaseLocked) {
    smoothed_frequency_hz_ = smoothed_frequency_hz_ == 0.0 ? f : smoothed_frequency_hz_ + std::min(1.0, t / 0.1) * (f - smoothed_frequency_hz_);
  }
  command_.carrier_frequency_hz = f;
  command_.code_rate_chips_per_s = signals::kCaChipRate_hz * (1.0 + f / signals::kL1Frequency_hz) +
                                   dll_rate_correction_chips_per_s(r.code_error_chips, dll_bw);
  r.command = command_;
  return r;
}

}  // namespace ultratrack::receiver
