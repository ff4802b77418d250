#include "receiver/scalar_tracking.hpp"

#include <algorithm>
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

constexpr double kSmoothing_s = 0.1;
constexpr double kBitPeriod_s = 0.02;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr int kCoherentEpochChoices[] = {1, 2, 5, 10, 20};
constexpr double kCn0Slow_s = 1.0;  // C/N0 low-pass for the long-coherent loss test
// The PLI's time constant in long updates (its spread from one update at SNR c T = 10, 20 dB-Hz at 100 ms, is
// ~0.6; over 10 updates ~0.2); the loss test then waits at least as long.
constexpr double kPliUpdates = 10.0;
// Longest stretch of unknown bits bridged on 20 ms with the long updates' loss test: a subframe 4 and 5 pair
// whose pages are unknown (9.6 s).
constexpr double kBridge_s = 10.0;

int epochs_in(double window_s, double t_s) { return std::max(1, static_cast<int>(std::lround(window_s / t_s))); }

// The moments method estimates the noise as a small difference of large moments at high SNR: it needs more
// epochs per window than the noise-tap ratio (50 keeps its spread below ~0.5 dB at 45 dB-Hz, 20 ms).
int cn0_window_epochs(Cn0Method method, double window_s, double t_s) {
  const int n = epochs_in(window_s, t_s);
  return method == Cn0Method::kMoments ? std::max(n, 50) : n;
}

// The 1 s estimate's spread at 16-18 dB-Hz is ~1.5 dB (the level averages up to three): 2 dB of margin.
constexpr double kPresenceMarginDb = 2.0;
constexpr int kPresenceRelockWindows = 2;

PresenceMonitorOptions presence_options(const ScalarTrackingOptions& o) {
  PresenceMonitorOptions p;
  p.window_epochs = epochs_in(o.presence_window_s, kBitPeriod_s);
  p.epoch_s = kBitPeriod_s;
  p.threshold_dbhz = o.presence_threshold_dbhz;
  p.max_windows = o.presence_max_windows;
  p.false_loss_per_min = o.presence_false_loss_per_min;
  p.margin_db = kPresenceMarginDb;
  p.relock_threshold_dbhz = o.presence_relock_dbhz;
  p.relock_windows = kPresenceRelockWindows;
  return p;
}

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
  c.check(o.fll_fine_time_s >= 0 && o.fll_fine_time_s <= 5, "fll_fine_time_s", o.fll_fine_time_s, "[0, 5] s");
  c.check(o.fll_fine_bw_hz > 0 && o.fll_fine_bw_hz <= 10, "fll_fine_bw_hz", o.fll_fine_bw_hz, "(0, 10] Hz");
  c.check(o.pullin_search_hz >= 0 && o.pullin_search_hz <= 500, "pullin_search_hz", o.pullin_search_hz, "[0, 500] Hz");
  c.check(o.pullin_search_time_s >= 0.05 && o.pullin_search_time_s <= 0.5, "pullin_search_time_s",
          o.pullin_search_time_s, "[0.05, 0.5] s");
  c.check(o.pll_bw_weak_hz > 0 && o.pll_bw_weak_hz <= 50, "pll_bw_weak_hz", o.pll_bw_weak_hz, "(0, 50] Hz");
  c.check(o.weak_cn0_dbhz >= 0 && o.weak_cn0_dbhz <= 60, "weak_cn0_dbhz", o.weak_cn0_dbhz, "[0, 60] dB-Hz");
  const double acquire_s = o.pullin_search_hz > 0 ? o.pullin_search_time_s : o.fll_wide_time_s + o.fll_narrow_time_s;
  const double pullin_min_s = acquire_s + o.fll_fine_time_s + o.pli_time_constant_s + o.pullin_lock_time_s;
  c.check(o.pullin_timeout_s > pullin_min_s, "pullin_timeout_s", o.pullin_timeout_s,
          "(search or wide + narrow FLL time, + fine FLL time + pli_time_constant_s + pullin_lock_time_s, 30] s");
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
  c.check(o.bit_sync.min_lead_sigma >= 3 && o.bit_sync.min_lead_sigma <= 100, "bit_sync.min_lead_sigma",
          o.bit_sync.min_lead_sigma, "[3, 100]");
  c.check(o.bit_sync.min_energy_bits >= 10 && o.bit_sync.min_energy_bits <= 1000, "bit_sync.min_energy_bits",
          o.bit_sync.min_energy_bits, "[10, 1000]");
  c.check(o.bit_sync.min_energy_sigma >= 3 && o.bit_sync.min_energy_sigma <= 100, "bit_sync.min_energy_sigma",
          o.bit_sync.min_energy_sigma, "[3, 100]");
  c.check(o.bit_sync.max_periods >= 200, "bit_sync.max_periods", o.bit_sync.max_periods, "[200, inf)");
  c.check(o.cn0_window_s >= 0.02 && o.cn0_window_s <= 5, "cn0_window_s", o.cn0_window_s, "[0.02, 5] s");
  c.check(o.cn0_loss_threshold_dbhz >= 0 && o.cn0_loss_threshold_dbhz <= 45, "cn0_loss_threshold_dbhz",
          o.cn0_loss_threshold_dbhz, "[0, 45] dB-Hz");
  c.check(o.pli_time_constant_s >= 0.005 && o.pli_time_constant_s <= 5, "pli_time_constant_s", o.pli_time_constant_s, "[0.005, 5] s");
  c.check(o.pli_lock_threshold > 0 && o.pli_lock_threshold < 1, "pli_lock_threshold", o.pli_lock_threshold, "(0, 1)");
  c.check(o.pli_loss_threshold >= -1 && o.pli_loss_threshold < o.pli_lock_threshold, "pli_loss_threshold",
          o.pli_loss_threshold, "[-1, pli_lock_threshold)");
  c.check(o.loss_of_lock_time_s >= 0.02 && o.loss_of_lock_time_s <= 10, "loss_of_lock_time_s", o.loss_of_lock_time_s, "[0.02, 10] s");
  c.check(o.max_coherent_ms == 20 || o.max_coherent_ms == 40 || o.max_coherent_ms == 100 || o.max_coherent_ms == 200 ||
              o.max_coherent_ms == 400,
          "max_coherent_ms", o.max_coherent_ms, "{20, 40, 100, 200, 400} ms");
  c.check(o.coherent_jitter_deg > 0 && o.coherent_jitter_deg <= 30, "coherent_jitter_deg", o.coherent_jitter_deg, "(0, 30] deg");
  c.check(o.coherent_hysteresis_db >= 0 && o.coherent_hysteresis_db <= 10, "coherent_hysteresis_db",
          o.coherent_hysteresis_db, "[0, 10] dB");
  c.check(o.coherent_max_bn_t > 0 && o.coherent_max_bn_t <= 0.25, "coherent_max_bn_t", o.coherent_max_bn_t, "(0, 0.25]");
  c.check(o.presence_window_s >= 0.1 && o.presence_window_s <= 5, "presence_window_s", o.presence_window_s, "[0.1, 5] s");
  c.check(o.presence_threshold_dbhz >= 0 && o.presence_threshold_dbhz <= 30, "presence_threshold_dbhz",
          o.presence_threshold_dbhz, "[0, 30] dB-Hz");
  c.check(o.presence_max_windows >= 1 && o.presence_max_windows <= 10, "presence_max_windows", o.presence_max_windows,
          "[1, 10]");
  c.check(o.presence_false_loss_per_min > 0 && o.presence_false_loss_per_min < 1, "presence_false_loss_per_min",
          o.presence_false_loss_per_min, "(0, 1)");
  c.check(o.presence_relock_dbhz >= o.presence_threshold_dbhz && o.presence_relock_dbhz <= 40, "presence_relock_dbhz",
          o.presence_relock_dbhz, "[presence_threshold_dbhz, 40] dB-Hz");
  return c.error;
}

double pll_thermal_jitter_rad(double bn_hz, double t_s, double cn0_dbhz) {
  const double c = std::pow(10.0, cn0_dbhz / 10.0);
  return std::sqrt(bn_hz / c * (1.0 + 1.0 / (2.0 * t_s * c)));
}

double long_coherent_pll_bw_hz(const ScalarTrackingOptions& o, int epochs) {
  return std::min(o.pll_bw_coherent_hz, o.coherent_max_bn_t / (epochs * kBitPeriod_s));
}

int choose_coherent_epochs(const ScalarTrackingOptions& o, double cn0_dbhz, int current) {
  const int max_epochs = std::max(1, o.max_coherent_ms / 20);
  const auto shortest = [&](double cn0) {
    int chosen = 1;
    for (const int n : kCoherentEpochChoices) {
      if (n > max_epochs) break;
      chosen = n;
      if (pll_thermal_jitter_rad(long_coherent_pll_bw_hz(o, n), n * kBitPeriod_s, cn0) <= o.coherent_jitter_deg * kDegToRad)
        break;
    }
    return chosen;
  };
  if (!o.adaptive_coherent) return max_epochs;
  const int longer = shortest(cn0_dbhz);
  if (longer > current) return longer;  // weaker: longer at once
  const int shorter = shortest(cn0_dbhz - o.coherent_hysteresis_db);
  return shorter < current ? shorter : current;
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
    case TrackingState::kCoasting: return "coasting";
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
      // The PLL pulls in as 2nd order (a 3rd-order loop's rate state random-walks while cycles slip) and takes the
      // configured order at phase lock.
      carrier_(2, options.pll_bw_hz, 0.0, initial.carrier_frequency_hz),
      command_(initial),
      pli_(options.pli_time_constant_s),
      cn0_(options.cn0_method, cn0_window_epochs(options.cn0_method, options.cn0_window_s, 1e-3)),
      bit_sync_(options.bit_sync),
      presence_(presence_options(options)) {
  command_.code_phase_jump_chips = 0.0;
  command_.carrier_phase_jump_cycles = 0.0;
  const bool search = opt_.pullin_search_hz > 0.0;
  search_end_s_ = search ? opt_.pullin_search_time_s : 0.0;
  wide_end_s_ = search_end_s_ + (search ? 0.0 : opt_.fll_wide_time_s);
  narrow_end_s_ = wide_end_s_ + (search ? 0.0 : opt_.fll_narrow_time_s);
  pll_start_s_ = narrow_end_s_ + opt_.fll_fine_time_s;
  initial_frequency_hz_ = initial.carrier_frequency_hz;
  pll_bw_now_hz_ = opt_.pll_bw_hz;
}

// The frequency offset of the buffered 1 ms prompts (carrier held constant while they were taken): argmax over a
// 2.5 Hz grid of the energy of 10 ms coherent blocks summed over blocks (a block holding a bit edge loses
// coherence but keeps its energy near the true offset), refined by a parabola through the peak and neighbours.
double ScalarTracking::search_frequency_offset_hz() const {
  constexpr int kBlock = 10;
  constexpr double kStep_hz = 2.5;
  const int blocks = search_count_ / kBlock;
  if (blocks == 0) return 0.0;
  const int half = static_cast<int>(std::ceil(opt_.pullin_search_hz / kStep_hz));
  const auto energy = [&](double f_hz) {
    const std::complex<double> step = std::polar(1.0, -kTwoPi * f_hz * 1e-3);
    std::complex<double> rotation = 1.0;
    double sum = 0.0;
    for (int b = 0; b < blocks; ++b) {
      std::complex<double> block{};
      for (int k = 0; k < kBlock; ++k) {
        block += std::complex<double>(search_prompts_[static_cast<std::size_t>(b * kBlock + k)]) * rotation;
        rotation *= step;
      }
      sum += std::norm(block);
    }
    return sum;
  };
  int best = 0;
  double best_e = -1.0, previous_e = 0.0, before_best = 0.0, after_best = 0.0;
  bool need_after = false;
  for (int i = -half; i <= half; ++i) {
    const double e = energy(i * kStep_hz);
    if (need_after) {
      after_best = e;
      need_after = false;
    }
    if (e > best_e) {
      best_e = e;
      best = i;
      before_best = previous_e;
      need_after = true;
    }
    previous_e = e;
  }
  if (best == -half || best == half) return best * kStep_hz;  // at the edge of the range: no parabola
  const double den = before_best - 2.0 * best_e + after_best;
  const double delta = den < 0.0 ? std::clamp(0.5 * (before_best - after_best) / den, -0.5, 0.5) : 0.0;
  return (best + delta) * kStep_hz;
}

double ScalarTracking::fine_fll(std::complex<float> prompt, double t_s, double* frequency_error_hz) {
  constexpr int kFineSumEpochs = 5;  // 5 ms sums: +-50 Hz range, at most one bit edge inside (bit-tolerant)
  fine_sum_ += std::complex<double>(prompt);
  fine_time_s_ += t_s;
  if (++fine_count_ < kFineSumEpochs) return carrier_.frequency_hz();
  double frequency = carrier_.frequency_hz();
  if (fine_have_previous_) {
    const std::complex<float> a(fine_previous_), b(fine_sum_);
    CrossDot cd = cross_dot(a, b);
    if (cd.dot < 0.0) cd = {-cd.cross, -cd.dot};
    *frequency_error_hz = std::atan2(cd.cross, cd.dot) / (kTwoPi * fine_time_s_);
    frequency = carrier_.update_fll_only(*frequency_error_hz, opt_.fll_fine_bw_hz, fine_time_s_);
  }
  fine_previous_ = fine_sum_;
  fine_have_previous_ = true;
  fine_sum_ = {};
  fine_count_ = 0;
  fine_time_s_ = 0.0;
  return frequency;
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
  presence_.reset();
  presence_absent_ = false;
  loss_time_s_ = 0.0;
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
  block_count_ = 0;  // a partial long sum of the PLL is void either way
  if (commanded) {
    target_epochs_ = 1;
    if (long_enabled() && state_ == TrackingState::kBitSynced) set_loop_epochs(1);
    return;
  }
  // Back to the PLL: it starts from the commanded frequency with no rate; the PLI, which read the FLL's wandering
  // phase, restarts (empty, it reads 0: the loss test waits loss_of_lock_time_s while the PLL pulls in).
  carrier_.reset(command_.carrier_frequency_hz, 0.0);
  pli_.reset();
  loss_time_s_ = 0.0;
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
  if (!long_enabled() || state_ != TrackingState::kBitSynced || carrier_commanded_) return 0;
  return target_epochs_ > 1 || block_count_ > 0 ? std::max(target_epochs_, block_epochs_) : 0;
}

// The loops' settings for updates every `epochs` x 20 ms (1: the plain 20 ms loop); the PLI restarts (its sums'
// scale changes with the length) with a time constant of at least 3 updates, and keeps that of the chosen length
// while 20 ms updates bridge unknown bits.
void ScalarTracking::set_loop_epochs(int epochs) {
  const int pli_epochs = epochs > 1 || bridging() ? std::max(epochs, target_epochs_) : 1;
  const double tau = pli_epochs == 1 ? opt_.pli_time_constant_s
                                     : std::max(opt_.pli_time_constant_s, kPliUpdates * pli_epochs * kBitPeriod_s);
  rereference_carrier_state(epochs);  // also when a block of another length was dropped before its update
  if (epochs == loop_epochs_ && tau == pli_tau_s_) return;
  if (epochs != loop_epochs_) {
    carrier_.set_bandwidths(epochs == 1 ? opt_.pll_bw_coherent_hz : long_coherent_pll_bw_hz(opt_, epochs), 0.0);
    pli_.reset();
  }
  loop_epochs_ = epochs;
  pli_tau_s_ = tau;
  pli_.set_time_constant(tau);
}

// The carrier loop filter's frequency state leads the command it gives by one update: tracking a Doppler ramp
// (rate rho) in steady state, the command for the next update of length T is the true Doppler at that update's
// middle, f(t + T / 2), and the state is f(t + T) (loop_filters.hpp: the output is the mean of the state before
// and after the update, which steps by rho T). A new T re-references the state by rho (T_new - T_old). Without
// it a switch from 20 to 100 ms at 4 Hz/s started the 2 Hz loop 0.32 Hz off: a 40-80 deg phase excursion.
void ScalarTracking::rereference_carrier_state(int epochs) {
  if (epochs == state_epochs_) return;
  const double rate = carrier_.frequency_rate_hzps();
  carrier_.reset(carrier_.frequency_hz() + rate * (epochs - state_epochs_) * kBitPeriod_s, rate);
  state_epochs_ = epochs;
}

TrackingReport ScalarTracking::update(const CorrelationEpoch& e, KnownBits known) {
  TrackingReport r;
  const double t = e.integration_time_s;
  const CorrelatorTaps& taps = e.master();
  time_s_ += t;
  r.loop_integration_ms = e.num_code_periods;
  // Long coherent integration: a block of target_epochs_ epochs starts only where that many bits are known; a
  // gap or an unknown bit inside a block drops its partial sum (the command given stays in force).
  const bool long_ready =
      long_enabled() && state_ == TrackingState::kBitSynced && e.num_code_periods == 20 && !carrier_commanded_;
  if (block_count_ > 0 && (!long_ready || known.sign == 0 || e.first_code_period != block_next_period_)) block_count_ = 0;
  const bool long_path = long_ready && known.sign != 0 &&
                         (block_count_ > 0 || (target_epochs_ > 1 && known.ahead >= target_epochs_));

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
    if (long_enabled()) {
      // The choice follows each estimate (the hysteresis absorbs its ~1 dB spread; a fade must reach the longer
      // integration before the 20 ms loop fails); the loss test in long mode reads the slow one (in dB: it
      // follows a loss of signal, whose estimates read 0 dB-Hz, within about a second).
      cn0_slow_dbhz_ = have_slow_cn0_ ? cn0_slow_dbhz_ + std::min(1.0, opt_.cn0_window_s / kCn0Slow_s) * (*c - cn0_slow_dbhz_) : *c;
      have_slow_cn0_ = true;
      if (state_ == TrackingState::kBitSynced) target_epochs_ = choose_coherent_epochs(opt_, *c, target_epochs_);
    }
  }
  r.cn0_dbhz = cn0_dbhz_;
  r.phase_locked = r.pli >= opt_.pli_lock_threshold;
  // Filter-driven: the presence test on every 20 ms epoch (long sums included: energy, not phase); while
  // coasting it looks for the signal's return.
  presence_absent_ = presence_found_ = false;
  if (filter_driven_ && (state_ == TrackingState::kBitSynced || state_ == TrackingState::kCoasting) &&
      e.num_code_periods == 20) {
    if (presence_.add(taps.prompt, taps.noise, t)) {
      presence_absent_ = state_ == TrackingState::kBitSynced && presence_.lost();
      presence_found_ = state_ == TrackingState::kCoasting && presence_.found();
    }
  } else {
    presence_.reset();
  }

  r.phase_error_cycles = costas_atan_cycles(taps.prompt);
  // Frequency error from cross and dot averaged over ~4 epochs: halves of this epoch in the wide stage, this and
  // the previous prompt (dot sign removed: bit-tolerant) afterwards.
  const bool wide_fll = (time_s_ > search_end_s_ && time_s_ <= wide_end_s_) || previous_t_s_ == 0.0;
  if (wide_fll != wide_fll_) fll_average_ = {};
  wide_fll_ = wide_fll;
  CrossDot cd = wide_fll ? cross_dot(e.prompt_halves[0], e.prompt_halves[1]) : cross_dot(previous_prompt_, taps.prompt);
  if (!wide_fll && cd.dot < 0.0) cd = {-cd.cross, -cd.dot};
  constexpr double kFllAverage = 0.25;
  fll_average_.cross += kFllAverage * (cd.cross - fll_average_.cross);
  fll_average_.dot += kFllAverage * (cd.dot - fll_average_.dot);
  const double fll_dt = wide_fll ? 0.5 * t : 0.5 * (previous_t_s_ + t);
  r.frequency_error_hz = std::atan2(fll_average_.cross, fll_average_.dot) / (kTwoPi * fll_dt);
  previous_prompt_ = taps.prompt;
  previous_t_s_ = t;
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
    const double pll_start_s = pll_start_s_;
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
  // judge the C/N0 as the long updates do; with no long update for kBridge_s, the plain 20 ms test holds.)
  const bool weak_bridge = bridging();
  const bool low_cn0 = weak_bridge ? slow_cn0_below(opt_.cn0_loss_threshold_dbhz - 10.0 * std::log10(target_epochs_))
                                   : cn0_dbhz_ && *cn0_dbhz_ < opt_.cn0_loss_threshold_dbhz;
  // (A carrier the vector FLL commands is not phase-locked: its PLI says nothing about the signal.)
  const bool fll = carrier_commanded_ && state_ == TrackingState::kBitSynced;
  const bool low_pli = ever_locked_ && r.pli < opt_.pli_loss_threshold && !fll;
  loss_time_s_ = (low_cn0 || low_pli) ? loss_time_s_ + t : 0.0;
  if (filter_driven_ && state_ == TrackingState::kBitSynced) loss_time_s_ = presence_absent_ ? opt_.loss_of_lock_time_s : 0.0;
  if (loss_time_s_ >= opt_.loss_of_lock_time_s) {
    const bool coast = coasting_allowed_ && state_ == TrackingState::kBitSynced;
    state_ = coast ? TrackingState::kCoasting : TrackingState::kLost;
    loss_time_s_ = 0.0;
    if (coast) return coast_epoch(e, r, false);
  }
  r.state = state_;
  if (state_ == TrackingState::kLost) {
    r.command = command_;  // coast on the last frequencies
    return r;
  }

  // Loops.
  // Pull-in stages (see ScalarTrackingOptions): a first-order FLL alone, then the PLL alone.
  const bool pullin = state_ == TrackingState::kPullIn;
  const bool search_stage = pullin && time_s_ <= search_end_s_;
  const bool wide_stage = pullin && !search_stage && time_s_ <= wide_end_s_;
  const bool fll_only = pullin && !search_stage && time_s_ <= narrow_end_s_;
  const bool fine_stage = pullin && !search_stage && !fll_only && time_s_ <= pll_start_s_;
  const bool coherent = state_ == TrackingState::kBitSynced;
  if (coherent && long_enabled()) set_loop_epochs(1);
  // After phase lock on 1 ms epochs: the narrower PLL while the signal is weak.
  if (state_ == TrackingState::kPhaseLocked && e.num_code_periods == 1 && cn0_dbhz_) {
    const double bw = *cn0_dbhz_ < opt_.weak_cn0_dbhz ? std::min(opt_.pll_bw_weak_hz, opt_.pll_bw_hz) : opt_.pll_bw_hz;
    if (bw != pll_bw_now_hz_) {
      carrier_.set_bandwidths(bw, 0.0);
      pll_bw_now_hz_ = bw;
    }
  }
  double f = 0.0;
  if (search_stage) {
    // hold the acquisition's frequency and buffer the prompts; estimate the offset at the stage's end
    if (e.num_code_periods == 1 && search_count_ < kMaxSearchEpochs)
      search_prompts_[static_cast<std::size_t>(search_count_++)] = taps.prompt;
    f = initial_frequency_hz_;
    if (time_s_ + t > search_end_s_) {  // the next epoch belongs to the fine FLL
      f = initial_frequency_hz_ + search_frequency_offset_hz();
      r.frequency_error_hz = f - initial_frequency_hz_;
      carrier_.reset(f, 0.0);
    }
  } else if (fll_only) {
    f = carrier_.update_fll_only(r.frequency_error_hz, wide_stage ? opt_.fll_bw_hz : opt_.fll_narrow_bw_hz, t);
  } else if (fine_stage) {
    f = fine_fll(taps.prompt, t, &r.frequency_error_hz);
  } else if (coherent && carrier_commanded_) {
    f = command_.carrier_frequency_hz;  // the vector FLL's (command_carrier)
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

bool ScalarTracking::bridging() const {
  return long_enabled() && state_ == TrackingState::kBitSynced && target_epochs_ > 1 && have_long_update_ &&
         time_s_ - last_long_update_s_ < kBridge_s;
}

bool ScalarTracking::slow_cn0_below(double threshold_dbhz) const {
  return have_slow_cn0_ && cn0_slow_dbhz_ < threshold_dbhz;
}

// Lock lost during long coherent integration: back to 20 ms loops, then coasting (when allowed) or lost.
TrackingReport ScalarTracking::lose_long_coherent_lock(const CorrelationEpoch& e, TrackingReport& r, bool add_bit) {
  loss_time_s_ = 0.0;
  target_epochs_ = 1;
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
  const CorrelatorTaps& taps = e.master();
  if (filter_driven_ && presence_absent_) {  // the presence window just ended without signal: the block is void
    block_count_ = 0;
    r.state = state_;
    r.loop_integration_ms = 20;
    return lose_long_coherent_lock(e, r, true);
  }
  if (block_count_ == 0) {
    block_epochs_ = target_epochs_;
    block_early_ = block_prompt_ = block_late_ = {};
    block_time_s_ = 0.0;
    if (block_epochs_ != state_epochs_) {
      // A block of a new length: the command held through it is the loop's state for that length, f(t + T / 2)
      // (the first epoch already ran on the previous command). The previous command carries the last shorter
      // update's proportional term, noise there (+-0.5-1 Hz on 20 ms updates at 30 dB-Hz), 5x as much phase
      // when held 100 ms: a 30-45 deg excursion before the first long update.
      rereference_carrier_state(block_epochs_);
      const double f = carrier_.frequency_hz() - 0.5 * carrier_.frequency_rate_hzps() * block_epochs_ * kBitPeriod_s;
      command_.code_rate_chips_per_s += signals::kCaChipRate_hz * (f - command_.carrier_frequency_hz) / signals::kL1Frequency_hz;
      command_.carrier_frequency_hz = f;
    }
  }
  const double s = sign;
  block_early_ += s * std::complex<double>(taps.early);
  block_prompt_ += s * std::complex<double>(taps.prompt);
  block_late_ += s * std::complex<double>(taps.late);
  block_time_s_ += e.integration_time_s;
  block_next_period_ = e.first_code_period + e.num_code_periods;
  ++block_count_;
  if (bits_) r.bit = bits_->add(e);
  r.state = state_;
  r.loop_integration_ms = block_epochs_ * 20;
  if (block_count_ < block_epochs_) {
    r.pli = pli_.value();
    r.phase_locked = r.pli >= opt_.pli_lock_threshold;
    r.command = command_;
    return r;
  }
  block_count_ = 0;
  have_long_update_ = true;
  last_long_update_s_ = time_s_;
  const int n = block_epochs_;
  const double t = block_time_s_;
  set_loop_epochs(n);
  const std::complex<float> prompt(block_prompt_);
  // The sum of n 20 ms epochs holds n times their noise power.
  r.pli = pli_.update(prompt, n * noise_power_, t);
  r.phase_locked = r.pli >= opt_.pli_lock_threshold;
  // Bits wiped: a filter-driven channel's PLL takes the full phase (atan2, +-1/2 cycle, no squaring loss).
  r.phase_error_cycles = filter_driven_ ? pll_atan2_cycles(prompt) : costas_atan_cycles(prompt);
  r.frequency_error_hz = 0.0;
  r.code_error_chips = dll_nelp_chips(std::complex<float>(block_early_), std::complex<float>(block_late_),
                                      opt_.early_late_offset_chips);
  const bool low_cn0 = slow_cn0_below(opt_.cn0_loss_threshold_dbhz - 10.0 * std::log10(n));
  const bool low_pli = r.pli < opt_.pli_loss_threshold;
  loss_time_s_ = (low_cn0 || low_pli) ? loss_time_s_ + t : 0.0;
  if (filter_driven_) loss_time_s_ = 0.0;
  if (loss_time_s_ >= std::max(opt_.loss_of_lock_time_s, pli_tau_s_)) return lose_long_coherent_lock(e, r, false);
  const double f = carrier_.update(r.phase_error_cycles, 0.0, t);
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
  loss_time_s_ = 0.0;
  locked_time_s_ = 0.0;
  target_epochs_ = 1;
  block_count_ = 0;
  loop_epochs_ = 1;
  state_epochs_ = 1;  // the state below is for 20 ms updates (rereference_carrier_state)
  carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, 0.0);
  carrier_.reset(command_.carrier_frequency_hz, 0.0);
  pli_.reset();
  pli_.set_time_constant(opt_.pli_time_constant_s);
  pli_tau_s_ = opt_.pli_time_constant_s;
  presence_.reset();
}

TrackingReport ScalarTracking::coast_epoch(const CorrelationEpoch& e, TrackingReport& r, bool add_bit) {
  const double t = e.integration_time_s;
  if (filter_driven_ && presence_found_) {
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
    pli_tau_s_ = opt_.pli_time_constant_s;
    loop_epochs_ = 1;
    state_epochs_ = 1;
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
      loss_time_s_ = 0.0;
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
      if (carrier_.fll_bw_hz() != opt_.relock_assist_bw_hz) carrier_.set_bandwidths(opt_.pll_bw_coherent_hz, opt_.relock_assist_bw_hz);
      f = carrier_.update(r.phase_error_cycles, r.frequency_error_hz, t);
    }
    // locked: the PLI holds and the frequency discriminator agrees (a PLL can hold a Costas lock 1 / t off)
    const bool on_frequency = std::abs(r.frequency_error_hz) < 0.25 / t;
    locked_time_s_ = relock_s_ > opt_.relock_fll_time_s && r.phase_locked && on_frequency ? locked_time_s_ + t : 0.0;
    if (locked_time_s_ >= opt_.pullin_lock_time_s) {
      state_ = TrackingState::kBitSynced;
      relocking_ = false;
      loss_time_s_ = 0.0;
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
