// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver oscillator's phase noise, tracked once for all the channels a vector loop drives. A front end's
// clock (a TCXO: random-walk frequency of ~1 Hz / sqrt(s) at L1) moves every channel's carrier phase by the same
// amount; each channel's own PLL must otherwise follow it alone, which keeps its bandwidth at 5 Hz and its
// coherent time at 20 ms (receiver/long_coherent.hpp: 12 deg of oscillator jitter there, 48 deg at 2 Hz) and its
// thermal jitter that of one weak signal. This loop closes on the phase of the channels' prompts summed
// coherently (each 20 ms prompt with its data bit wiped, by the known bit or else by the sign of its in-phase arm,
// and weighted by its amplitude: maximal-ratio combining), whose SNR is that of all channels together (10 dB above
// one with 10 equal ones), and its output frequency is added to every steered channel's carrier NCO (as carrier
// aiding). The channels' PLLs then see the oscillator's residual only and choose their coherent time and bandwidth
// on thermal jitter (ScalarTrackingControl::clock_steered): 2 Hz below 30 dB-Hz, over 100 ms where the bits are known
// and 20 ms where not.
// Loop: second order (a frequency step leaves no standing phase error), damping 0.707, the analogue design at
// bandwidth_hz discretised per update (integrator += w0^2 T e, frequency = integrator + 2 zeta w0 e, e the combined
// phase error in rad). Why these choices (benchmarks/validation/clock_loop_model.py, a discrete model independent of
// this code, 8 channels on a TCXO, the channels' loop filter as the receiver's): at 20 dB-Hz a channel PLL alone
// slips at 5 Hz / 20 ms (45-52 deg RMS) and at 2 Hz / 100 ms (52 deg); with this loop at 5 Hz the 2 Hz PLLs hold
// 16-17 deg and none slips when its frequency runs two epochs after the prompts it came from (the serial ultra-tight
// loop: a prompt's epoch ends up to a period before the vector epoch, the command runs from the channel's next epoch
// start). One epoch more (the pipelined loop, pipelines/receive_options.hpp) makes the loop and the 100 ms PLLs ring
// (25-27 deg, most slip; in the receiver 1.3 Hz RMS of common frequency error at ~2.8 Hz, and whole weak files lost);
// at 8 Hz the serial loop rings too (22-25 deg, some slip). Summing the prompts before the arctangent, rather than
// averaging per-channel arctangents, keeps the discriminator's S-curve steeper where a TCXO's 5 Hz/s excursions push
// it: at 20 dB-Hz a 45-60 deg error reads 38-42 deg against 32 (averaged arctangents lagged one such excursion by a
// cycle and a half on a foreign-convention file). Weights: the prompt's expected amplitude A = sqrt(2 c T) in
// unit-noise units, c = 10^(C/N0 / 10). Units: Hz, rad, seconds; C/N0 in dB-Hz.
#pragma once

#include <span>

namespace ultratrack::receiver {

struct CommonClockLoopOptions {
  double bandwidth_hz = 5.0;  // noise bandwidth; (0, 0.25 / period_s]
  double period_s = 0.020;    // update interval (the vector epoch)
  int min_channels = 4;       // fewer contributing phases: no update (the loop holds its frequency)
};

// One channel's latest 20 ms prompt against its replica, normalised to unit noise variance per arm, the data bit
// not removed; the bit when known (+1 / -1 makes the in-phase arm positive; 0: unknown, the in-phase arm's sign is
// taken), and the channel's C/N0.
struct ChannelPrompt {
  double i = 0.0, q = 0.0;
  int bit_sign = 0;
  double cn0_dbhz = 0.0;
};

class CommonClockLoop {
 public:
  // Throws std::invalid_argument for a bandwidth or period outside its range or min_channels < 1.
  explicit CommonClockLoop(const CommonClockLoopOptions& options = {});
  // One update from the channels' latest prompts (non-finite entries ignored); returns the loop's frequency (Hz),
  // unchanged when fewer than min_channels contribute.
  double update(std::span<const ChannelPrompt> prompts);
  // The frequency the loop adds to every steered channel's NCO (Hz; 0 at the start).
  double frequency_hz() const { return frequency_hz_; }
  // The latest update's phase error of the combined prompt (rad, in (-pi, pi]) and its 1-sigma at high SNR
  // (1 / sqrt(sum of A^2), rad), and how many channels it used.
  double mean_phase_rad() const { return mean_phase_rad_; }
  double mean_phase_sigma_rad() const { return mean_phase_sigma_rad_; }
  int channels_used() const { return channels_used_; }
  long long updates() const { return updates_; }
  const CommonClockLoopOptions& options() const { return opt_; }

 private:
  CommonClockLoopOptions opt_;
  double w0_rad_s_ = 0.0;
  double integrator_rad_s_ = 0.0;
  double frequency_hz_ = 0.0;
  double mean_phase_rad_ = 0.0, mean_phase_sigma_rad_ = 0.0;
  int channels_used_ = 0;
  long long updates_ = 0;
};

}  // namespace ultratrack::receiver
