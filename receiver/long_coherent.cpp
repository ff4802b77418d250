// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/long_coherent.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "io/units.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kBitPeriod_s = 0.02;
constexpr int kCoherentEpochChoices[] = {1, 2, 5, 10, 20};
constexpr double kCn0Slow_s = 1.0;  // C/N0 low-pass for the long-coherent loss test
// The PLI's time constant in long updates (its spread from one update at SNR c T = 10, 20 dB-Hz at 100 ms, is
// ~0.6; over 10 updates ~0.2); the loss test then waits at least as long.
constexpr double kPliUpdates = 10.0;
// Longest stretch of unknown bits bridged on 20 ms with the long updates' loss test: a subframe 4 and 5 pair
// whose pages are unknown (9.6 s).
constexpr double kBridge_s = 10.0;

}  // namespace

double pll_thermal_jitter_rad(double bn_hz, double t_s, double cn0_dbhz) {
  const double c = std::pow(10.0, cn0_dbhz / 10.0);
  return std::sqrt(bn_hz / c * (1.0 + 1.0 / (2.0 * t_s * c)));
}

double pll_oscillator_jitter_rad(double bn_hz, int pll_order, double h0, double h_minus2) {
  constexpr double kTwoPiL1 = 2.0 * std::numbers::pi * signals::kL1Frequency_hz;
  const double q_w = kTwoPiL1 * kTwoPiL1 * h0 / 2.0;
  const double q_rw = kTwoPiL1 * kTwoPiL1 * 2.0 * std::numbers::pi * std::numbers::pi * h_minus2;
  double w0 = 0.0, i_w = 0.0, i_rw = 0.0;
  if (pll_order == 2) {
    w0 = bn_hz / kSecondOrderBnPerW0;
    i_w = i_rw = 1.0 / (2.0 * std::numbers::sqrt2);
  } else {
    w0 = bn_hz / kThirdOrderBnPerW0;
    constexpr double kB3 = 2.4, kA3 = 1.1;  // loop_filters.cpp's third-order coefficients
    i_w = kA3 / (2.0 * (kB3 * kA3 - 1.0));
    i_rw = 1.0 / (2.0 * (kB3 * kA3 - 1.0));
  }
  return std::sqrt(q_w * i_w / w0 + q_rw * i_rw / (w0 * w0 * w0));
}

double long_coherent_pll_bw_hz(const ScalarTrackingOptions& o, int epochs) {
  return std::min(o.pll_bw_coherent_hz, o.coherent_max_bn_t / (epochs * kBitPeriod_s));
}

int choose_coherent_epochs(const ScalarTrackingOptions& o, double cn0_dbhz, int current, bool oscillator_tracked) {
  const int max_epochs = std::max(1, o.max_coherent_ms / 20);
  const auto jitter_rad = [&](int n, double cn0) {
    const double bn = long_coherent_pll_bw_hz(o, n);
    const double thermal = pll_thermal_jitter_rad(bn, n * kBitPeriod_s, cn0);
    const double clock =
        oscillator_tracked ? 0.0 : pll_oscillator_jitter_rad(bn, o.pll_order, o.oscillator_h0, o.oscillator_h_minus2);
    return std::sqrt(thermal * thermal + clock * clock);
  };
  const auto shortest = [&](double cn0) {
    std::vector<std::pair<int, double>> jitters;
    for (const int n : kCoherentEpochChoices) {
      if (n > max_epochs) break;
      const double j = jitter_rad(n, cn0);
      if (j <= o.coherent_jitter_deg * io::kRadPerDeg) return n;
      jitters.emplace_back(n, j);
    }
    // None within the bound. Without an oscillator the longest (thermal jitter falls with T); with one the
    // shortest within 5 % of the least total jitter (a longer block that gains less is not worth its bits).
    if (oscillator_tracked || !(o.oscillator_h0 > 0.0 || o.oscillator_h_minus2 > 0.0)) return jitters.back().first;
    double least = jitters.front().second;
    for (const auto& [n, j] : jitters) least = std::min(least, j);
    for (const auto& [n, j] : jitters)
      if (j <= 1.05 * least) return n;
    return jitters.back().first;
  };
  if (!o.adaptive_coherent) return max_epochs;
  const int longer = shortest(cn0_dbhz);
  if (longer > current) return longer;  // weaker: longer at once
  const int shorter = shortest(cn0_dbhz - o.coherent_hysteresis_db);
  return shorter < current ? shorter : current;
}

int LongCoherentIntegration::known_bits_wanted() const {
  return target_epochs_ > 1 || block_count_ > 0 ? std::max(target_epochs_, block_epochs_) : 0;
}

void LongCoherentIntegration::add_cn0(double cn0_dbhz, bool bit_synced, bool oscillator_tracked) {
  // The choice follows each estimate (the hysteresis absorbs its ~1 dB spread; a fade must reach the longer
  // integration before the 20 ms loop fails); the loss test in long mode reads the slow one (in dB: it
  // follows a loss of signal, whose estimates read 0 dB-Hz, within about a second).
  oscillator_tracked_ = oscillator_tracked;
  cn0_slow_dbhz_ = have_slow_cn0_
                       ? cn0_slow_dbhz_ + std::min(1.0, opt_.cn0_window_s / kCn0Slow_s) * (cn0_dbhz - cn0_slow_dbhz_)
                       : cn0_dbhz;
  have_slow_cn0_ = true;
  if (bit_synced) target_epochs_ = choose_coherent_epochs(opt_, cn0_dbhz, target_epochs_, oscillator_tracked);
}

bool LongCoherentIntegration::slow_cn0_below(double threshold_dbhz) const {
  return have_slow_cn0_ && cn0_slow_dbhz_ < threshold_dbhz;
}

bool LongCoherentIntegration::bridging(bool bit_synced, double time_s) const {
  return enabled() && bit_synced && target_epochs_ > 1 && have_long_update_ && time_s - last_long_update_s_ < kBridge_s;
}

// The PLI restarts (its sums' scale changes with the length) with a time constant of at least 3 updates, and
// keeps that of the chosen length while 20 ms updates bridge unknown bits. A channel whose oscillator another loop
// tracks runs its 20 ms updates (bits unknown) at the bandwidth of the chosen length too: with the clock and the
// dynamics taken out (common clock loop, INS aiding) only thermal noise is left to its loop, and the 5 Hz one
// slips on it below ~22 dB-Hz (a 20 ms Costas loop at 2 Hz has 9 deg of thermal jitter at 20 dB-Hz, 14 at 5 Hz).
void LongCoherentIntegration::set_loop_epochs(int epochs, bool bridging, CarrierLoopFilter& carrier,
                                              PhaseLockIndicator& pli) {
  const int pli_epochs = epochs > 1 || bridging ? std::max(epochs, target_epochs_) : 1;
  const double tau = pli_epochs == 1 ? opt_.pli_time_constant_s
                                     : std::max(opt_.pli_time_constant_s, kPliUpdates * pli_epochs * kBitPeriod_s);
  rereference_carrier_state(epochs, carrier);  // also when a block of another length was dropped before its update
  const double bn_hz = epochs > 1                                  ? long_coherent_pll_bw_hz(opt_, epochs)
                       : oscillator_tracked_ && target_epochs_ > 1 ? long_coherent_pll_bw_hz(opt_, target_epochs_)
                                                                   : opt_.pll_bw_coherent_hz;
  if (epochs == loop_epochs_ && tau == pli_tau_s_ && bn_hz == loop_bw_hz_) return;
  if (bn_hz != loop_bw_hz_) carrier.set_bandwidths(bn_hz, 0.0);
  if (epochs != loop_epochs_) pli.reset();
  loop_bw_hz_ = bn_hz;
  loop_epochs_ = epochs;
  pli_tau_s_ = tau;
  pli.set_time_constant(tau);
}

// The carrier loop filter's frequency state leads the command it gives by one update: tracking a Doppler ramp
// (rate rho) in steady state, the command for the next update of length T is the true Doppler at that update's
// middle, f(t + T / 2), and the state is f(t + T) (loop_filters.hpp: the output is the mean of the state before
// and after the update, which steps by rho T). A new T re-references the state by rho (T_new - T_old). Without
// it a switch from 20 to 100 ms at 4 Hz/s started the 2 Hz loop 0.32 Hz off: a 40-80 deg phase excursion.
void LongCoherentIntegration::rereference_carrier_state(int epochs, CarrierLoopFilter& carrier) {
  if (epochs == state_epochs_) return;
  const double rate = carrier.frequency_rate_hzps();
  carrier.reset(carrier.frequency_hz() + rate * (epochs - state_epochs_) * kBitPeriod_s, rate);
  state_epochs_ = epochs;
}

void LongCoherentIntegration::restart_20ms_loops() {
  loop_epochs_ = 1;
  loop_bw_hz_ = opt_.pll_bw_coherent_hz;
  state_epochs_ = 1;
  pli_tau_s_ = opt_.pli_time_constant_s;
}

bool LongCoherentIntegration::start_block(CarrierLoopFilter& carrier) {
  block_epochs_ = target_epochs_;
  block_early_ = block_prompt_ = block_late_ = {};
  block_time_s_ = 0.0;
  if (block_epochs_ == state_epochs_) return false;
  rereference_carrier_state(block_epochs_, carrier);
  return true;
}

bool LongCoherentIntegration::add(const CorrelationEpoch& e, int sign) {
  const CorrelatorTaps& taps = e.master();
  const double s = sign;
  block_early_ += s * std::complex<double>(taps.early);
  block_prompt_ += s * std::complex<double>(taps.prompt);
  block_late_ += s * std::complex<double>(taps.late);
  block_time_s_ += e.integration_time_s;
  block_next_period_ = e.first_code_period + e.num_code_periods;
  ++block_count_;
  return block_count_ >= block_epochs_;
}

CoherentBlockSums LongCoherentIntegration::finish_block(double time_s) {
  block_count_ = 0;
  have_long_update_ = true;
  last_long_update_s_ = time_s;
  return {block_epochs_, block_time_s_, block_early_, block_prompt_, block_late_};
}

}  // namespace ultratrack::receiver
