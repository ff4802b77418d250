// SPDX-License-Identifier: GPL-3.0-or-later
// The per-channel carrier states of the vector PLL (VectorCarrier::kPll, fusion/vector_tracking.hpp).
//
// Which vector PLL this is. The literature has two families. (a) Absolute phase in the navigation filter
// (Henkel-style, or a carrier-phase float filter): the Costas discriminator of each channel is a phase measurement
// of the filter's range, and each channel carries an ambiguity state initialised at the hand-over; the filter is
// then 8 + N states with a mm-level measurement model (ionosphere divergence, multipath and the filter's own
// lag all land in the ambiguities). (b) Delta-range / cascaded (Lashley & Bevly's VDFLL extended to phase, Peng &
// Morton's VPLL): the navigation filter is updated with time-differenced carrier phase (the replica's phase change
// plus the change of the Costas discriminator between epochs: a delta range), predicts every line of sight's
// Doppler, and each channel's phase is closed through a correction the filter commands, the discriminator
// updating a small per-channel carrier state. This is (b): the 8-state navigation filter stays as it is (the
// vector FLL's rows, here phase-locked delta ranges), and this class is the per-channel part, inside the vector
// filter: no loop filter runs in the channel, whose carrier NCO takes the frequency and a phase jump from here.
// (b) because the absolute form needs a variable-size filter whose ambiguities absorb everything the 8-state model
// lacks, and the vector FLL already provides the navigation half.
//
// State (one channel): psi, the signal's carrier phase in the replica NCO's frame (cycles; its origin is fixed at
// the hand-over by the replica's phase plus the discriminator there: the per-channel ambiguity), at sample
// t_psi; nu, the line of sight's Doppler minus the navigation filter's prediction (Hz): the filter's latency lag
// in a manoeuvre (no acceleration state: 4-5 Hz in a 2 g turn) and its errors, a Gauss-Markov process. Propagation
// psi += (f_pred + nu) dt, f_pred the filter's predicted Doppler; measurement: the Costas discriminator
// atan(Q / I) / 2 pi = psi - replica phase at the epoch's middle, modulo half a cycle (the innovation is wrapped to
// +-1/4 cycle: the data bits are unknown to this loop), variance costas_phase_variance_cycles2 at the channel's
// C/N0. Process noise: nu's driving noise and the prediction's own Doppler variance (propagate). The resulting
// Kalman gains make a second-order loop whose bandwidth follows the C/N0 and the prediction's quality.
//
// Caveat of the cascade: the channel's phase updates psi/nu and, as a delta range, the navigation filter; both
// use the same discriminators (nu is a residual on top of the prediction, not independent of it).
//
// Lock: the Costas lock indicator mean(I^2 - Q^2) / mean(I^2 + Q^2) (cos 2 phi) over lock_average_s; below
// lock_threshold for loss_time_s (after lock_average_s) the channel's phase is declared lost and it falls back to the
// vector FLL (the filter commands the frequency alone, the channel detects bits differentially and flags its phase:
// LLI). Units: cycles, Hz, s, samples.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>

namespace ultratrack::fusion {

struct VectorPllOptions {
  // nu's driving noise, Hz^2/s (random-walk part), and its correlation time (it decays to the prediction when no
  // discriminator updates it). 0.5 Hz^2/s: with the prediction's variance, a loop of Bn ~13 Hz (w0 ~ 24 rad/s) at
  // 45 dB-Hz and ~6 Hz at 30, which takes a 2 g turn entry (the prediction's lag grows to ~4.6 Hz within ~50 ms)
  // at a ~0.1-cycle peak (measured 0.125, ReceiveVectorPll.TwoGTurnKeepsEveryPhaseArcWithoutSlips).
  double frequency_psd_hz2ps = 0.5;
  double frequency_correlation_s = 2.0;
  double initial_sigma_frequency_hz = 1.0;  // nu at the hand-over (from the measured minus predicted Doppler)
  double gate_sigma = 3.89;  // innovation gate, in its predicted sigmas (two-sided normal 0.9999, as the filter's rows)
  // The indicator's running mean: with noise alone each 20 ms sample of (I^2 - Q^2) / mean(I^2 + Q^2) has sigma 1,
  // so 0.5 s (~49 samples' worth of exponential memory) leaves a sigma ~0.14 about 0, rarely above the threshold
  // (0.2 s left ~0.23 and reset the loss timer every few epochs).
  double lock_average_s = 0.5;
  double lock_threshold = 0.3;
  double loss_time_s = 0.3;
  // A channel fallen back to the FLL re-enters the PLL (a new phase arc) after this long usable at
  // min_cn0_dbhz + relock_margin_dbhz or more.
  double relock_after_s = 1.0;
  double relock_margin_dbhz = 3.0;
};

// The Costas discriminator of a prompt, cycles in [-1/4, 1/4].
double costas_discriminator_cycles(double i, double q);

// Noise bandwidth (Hz) of the second-order loop a steady phase/frequency gain pair closes at update interval t_s:
// per update psi += k_phase e, nu += k_freq e (e in cycles, k_freq in Hz per cycle), i.e. the continuous loop
// s^2 + (k_phase / t) s + k_freq / t, whose Bn = (k_phase / t + k_freq / k_phase) / 4 (Kaplan & Hegarty table 5.6
// with 2 zeta w0 = k_phase / t, w0^2 = k_freq / t). A continuous approximation: it reads low once Bn t nears 0.2.
double loop_noise_bandwidth_hz(double k_phase, double k_freq, double t_s);

class VectorCarrierPhase {
 public:
  VectorCarrierPhase() = default;
  explicit VectorCarrierPhase(const VectorPllOptions& options) : opt_(options) {}

  bool active() const { return active_; }  // tracking the phase (not fallen back)
  // Starts a phase arc at sample `at`: psi = replica phase + discriminator, nu = nu0 (Hz).
  void start(std::int64_t at, double replica_phase_cycles, double discriminator_cycles, double nu0_hz,
             double disc_variance_cycles2);
  void stop() {
    active_ = false;
    fell_back_ = true;
    fallback_s = 0.0;
  }
  // Stopped after a start (a lost lock): the owner waits relock_after_s before a new arc.
  bool fell_back() const { return fell_back_; }

  // Propagates to sample `to` (fs_hz) with the prediction's mean Doppler over the interval (Hz) and that
  // prediction's error variance (Hz^2, from the navigation filter's covariance): the phase the prediction carries
  // psi over the interval is uncertain by that times the interval squared. The navigation filter's velocity, free to
  // follow manoeuvres (white acceleration), moves by ~0.2 Hz per 20 ms update on a line of sight at 45 dB-Hz, and
  // its Doppler error is re-drawn that fast: without this term the loop would be narrowed below what that noise
  // allows (measured: 2.7x the closed-form jitter of the resulting bandwidth).
  void propagate(std::int64_t to, double fs_hz, double mean_predicted_doppler_hz, double prediction_variance_hz2 = 0.0);
  // One discriminator (prompt I, Q of an epoch whose middle is the state's sample): the lock indicator always, the
  // state if the gated innovation passes. variance: costas_phase_variance_cycles2 at the C/N0. Returns whether it
  // was accepted.
  bool update(double prompt_i, double prompt_q, double replica_phase_cycles, double variance_cycles2, double epoch_s);
  // psi extrapolated to sample `to` with the prediction's mean Doppler there (no state change).
  double phase_at(std::int64_t to, double fs_hz, double mean_predicted_doppler_hz) const;
  // Lock test: false once the indicator stayed below the threshold for loss_time_s (after lock_average_s).
  bool locked() const { return below_s_ < opt_.loss_time_s; }

  std::int64_t sample() const { return sample_; }
  double psi_cycles() const { return x_(0); }
  double nu_hz() const { return x_(1); }
  double sigma_phase_cycles() const { return std::sqrt(P_(0, 0)); }
  // The phase 1-sigma before the latest discriminator update (the prior): the replica, commanded from the states
  // before the next discriminator arrives, follows the prior, so this is the loop's own prediction of its error.
  double prior_sigma_phase_cycles() const { return prior_sigma_; }
  double lock_indicator() const { return power_ > 0.0 ? dot_ / power_ : 0.0; }
  double last_discriminator_cycles() const { return disc_; }
  double last_innovation_cycles() const { return innovation_; }
  double last_bandwidth_hz() const { return bn_hz_; }
  // The forward predictions the replica was commanded with: base_hz (the prediction alone, nu not included) from
  // sample `from` on. psi propagates over an interval with the one in effect at its middle, so that nu is the
  // signal's Doppler minus the prediction as it was made for that interval (ahead of time: the navigation filter's
  // latency lag in a manoeuvre), not minus the filter's later, retrospective view of it, which already holds the
  // manoeuvre and would leave the lag to the phase jumps alone (a first-order loop). NaN: none in effect.
  void record_command(std::int64_t from, double base_hz);
  double commanded_base_hz(std::int64_t at) const;
  // Time the channel has spent fallen back (for relock), kept by the owner.
  double fallback_s = 0.0;

 private:
  VectorPllOptions opt_;
  bool active_ = false, fell_back_ = false;
  std::int64_t sample_ = 0;
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero();
  Eigen::Matrix2d P_ = Eigen::Matrix2d::Zero();
  double dot_ = 0.0, power_ = 0.0, averaged_s_ = 0.0, below_s_ = 0.0;
  double disc_ = NAN, innovation_ = NAN, bn_hz_ = NAN, prior_sigma_ = NAN;
  std::array<std::int64_t, 4> command_from_{};
  std::array<double, 4> command_base_hz_{NAN, NAN, NAN, NAN};
};

}  // namespace ultratrack::fusion
