// SPDX-License-Identifier: GPL-3.0-or-later
// Scalar-tracking options: every setting of the per-channel loops (pull-in, PLL, DLL, coherent integration, lock
// detection, coasting, long coherent integration, the filter-driven presence test) with its unit, range and
// default for L1 C/A, and their one validation. Units: Hz, chips, seconds, ms; C/N0 in dB-Hz.
#pragma once

#include <string>

#include "receiver/bit_sync.hpp"
#include "receiver/lock_detectors.hpp"
#include "receiver/tracking_channel.hpp"
#include "signals/oscillator_allan.hpp"

namespace ultratrack::receiver {

// All scalar-tracking settings, with defaults for L1 C/A in a static or vehicle receiver. Check with
// IsValid() at the edge (config file, command line) before constructing anything.
struct ScalarTrackingOptions {
  // Carrier loop
  int pll_order = 3;        // 2 or 3
  double pll_bw_hz = 15.0;  // PLL noise bandwidth with 1 ms epochs; (0, 50]
  // On 1 ms epochs after phase lock while the measured C/N0 is below weak_cn0_dbhz: a narrower PLL (thermal
  // phase jitter sqrt(Bn / (C/N0) (1 + 1 / (2 T C/N0))): 14 deg at 15 Hz, 27 dB-Hz, against 9 deg at 6 Hz), for
  // the second or two before bit sync; a static or vehicle receiver's line-of-sight dynamics (< 1 g) stay within
  // a 3rd-order 6 Hz loop's reach.
  double pll_bw_weak_hz = 6.0;      // (0, 50]
  double weak_cn0_dbhz = 33.0;      // [0, 60]
  double pll_bw_coherent_hz = 5.0;  // with 20 ms epochs after bit sync; (0, 15]. Design (analogue) value: at
                                    // Bn*T = 0.1 the digital loop's true Bn is ~20 % higher, at 0.2 ~55 %
  // Pull-in: (1) a wide FLL alone on the two halves of each code period (range +-1 kHz, bit-edge safe); (2) a
  // narrow FLL alone on successive 1 ms prompts (bit-tolerant, range +-250 Hz, 8x less noise); (3) the PLL alone
  // (2nd order while pulling in) until the phase lock indicator holds, then the PLL of pll_order. Both FLLs are
  // first order and average cross and dot over ~4 epochs before the arctangent.
  // (0) When pullin_search_hz > 0 (default): instead of stages (1) and (2), a frequency search on the first
  // pullin_search_time_s of 1 ms prompts with the carrier held at the acquisition's frequency: the energy of
  // 10 ms coherent blocks, summed over blocks, at offsets +-pullin_search_hz (2.5 Hz grid, parabola through the
  // peak). Its noise is that of an estimate from 0.2 s of signal (a few Hz at 27 dB-Hz), where the FLL stages
  // wander +-20-130 Hz below ~32 dB-Hz (frequency jitter of a 1st-order FLL on 0.5-1 ms cross products): the
  // FLL stages suit a 1 ms acquisition on strong signals (pullin_search_hz = 0), the search any acquisition
  // whose Doppler is good to +-pullin_search_hz (refined 4-10 ms acquisitions: a few tens of Hz at worst).
  double pullin_search_hz = 300.0;    // [0, 500]; 0 = FLL stages (1), (2)
  double pullin_search_time_s = 0.2;  // [0.05, 0.5]
  double fll_bw_hz = 10.0;            // wide FLL; (0, 50]
  double fll_wide_time_s = 0.25;      // stage (1) length; [0.01, 5]
  double fll_narrow_bw_hz = 2.0;      // narrow FLL; (0, 20]
  double fll_narrow_time_s = 0.25;    // stage (2) length; [0, 5]
  // (2b) a fine FLL on successive 5 ms prompt sums (bit-tolerant, range +-50 Hz, 5x the SNR per measurement):
  // brings the frequency within the PLL's few-Hz lock-in range at low C/N0.
  double fll_fine_bw_hz = 2.0;      // fine FLL; (0, 10]
  double fll_fine_time_s = 0.3;     // stage (2b) length; [0, 5]
  double pullin_lock_time_s = 0.1;  // PLI above pli_lock_threshold this long ends pull-in; [0.01, 2]
  double pullin_timeout_s = 2.0;    // pull-in that never locks is declared lost; [0.1, 30] and longer than
                                    // the FLL stages plus pli_time_constant_s plus pullin_lock_time_s
  // Code loop
  double dll_bw_hz = 2.0;                     // DLL noise bandwidth with 1 ms epochs; (0, 10]
  double dll_bw_coherent_hz = 1.0;            // after bit sync; (0, 5]
  double early_late_offset_chips = 0.5;       // E and L at +- this (E-L spacing twice it); (0, 0.5]; narrow: 0.1
  bool very_early_late = false;               // extra VE/VL taps in the epochs
  double very_early_late_offset_chips = 1.0;  // (early_late_offset_chips, 2]
  // Integration
  int coherent_ms = 20;  // coherent integration after bit sync, ms; 1, 2, 4, 5, 10 or 20
  BitSyncOptions bit_sync;
  // Lock detection
  Cn0Method cn0_method = Cn0Method::kNoiseTap;  // kMoments works without the noise tap (windows >= 50 epochs)
  double cn0_window_s = 0.2;                    // C/N0 averaging window; [0.02, 5] (a multiple of the epoch length)
  double cn0_loss_threshold_dbhz = 25.0;        // C/N0 below this counts toward loss of lock; [0, 45]
  double pli_time_constant_s = 0.1;             // phase lock indicator low-pass; [0.005, 5]
  double pli_lock_threshold = 0.7;              // PLI (cos 2 dphi) above this = phase locked; (0, 1)
  double pli_loss_threshold = 0.3;   // PLI below this (after lock) counts toward loss; [-1, pli_lock_threshold)
  double loss_of_lock_time_s = 0.3;  // continuous time with a loss condition before kLost; [0.02, 10]
  // Coasting (allow_coasting): re-lock starts when the C/N0 estimate is this far above cn0_loss_threshold_dbhz;
  // a first-order FLL of relock_fll_bw_hz (cross/dot of each epoch's two halves: +-50 Hz at 20 ms) alone for
  // relock_fll_time_s, then the PLL assisted by that FLL at relock_assist_bw_hz until the PLI holds, with the
  // FLL's error below 1 / (4 T), for pullin_lock_time_s.
  double relock_margin_dbhz = 3.0;
  double relock_fll_bw_hz = 6.0;
  double relock_fll_time_s = 0.2;
  double relock_assist_bw_hz = 2.0;
  // Long coherent integration with data wipe-off (issue 7). After bit sync, while the navigation bits ahead are
  // known (receiver/nav_bit_predictor.hpp), N consecutive 20 ms epochs are summed with each bit's sign removed
  // (the channel's epochs stay 20 ms: one correlator, summed epochs) and the loops run once per N x 20 ms with
  // T = N x 20 ms: PLL and DLL noise bandwidths min(their 20 ms value, coherent_max_bn_t / T) (the loop
  // filters' gains follow T; at Bn T = 0.2 the digital loop is ~55 % wider than its design), the PLI on the long
  // sums (noise power N x the 20 ms one, time constant max(pli_time_constant_s, 10 T); the loss test waits as
  // long), and the C/N0 loss test at cn0_loss_threshold_dbhz - 10 log10 N (the pre-detection SNR of a 20 ms
  // epoch at the threshold) on the C/N0 estimates low-passed (in dB) over 1 s. Where bits are unknown the
  // channel stays on 20 ms (bits and C/N0 always come from 20 ms epochs: non-coherent across them).
  // N per channel from the measured C/N0 (adaptive_coherent): the shortest N in {1, 2, 5, 10, 20} (N x 20 <=
  // max_coherent_ms) whose thermal Costas PLL jitter sqrt(Bn / c (1 + 1 / (2 T c))) (c = C/N0 in Hz, Bn at that
  // T) is at most coherent_jitter_deg, else the longest; a shorter N only once it also holds coherent_hysteresis_db
  // lower. With the defaults (5 Hz at 20 ms, Bn T <= 0.2, 4 deg): 20 ms above 30.21 dB-Hz, 40 ms (still 5 Hz)
  // down to 30.16, 100 ms (2 Hz) below; with max_coherent_ms 200 or 400, 200 ms (1 Hz) below 26.18 and 400 ms
  // (0.5 Hz) below 23.17; back to a shorter time 2 dB above its threshold. A 1 Hz 3rd-order loop at 100 ms (Bn T
  // = 0.1) tracked a 0.5 Hz/s Doppler ramp with ~30 deg slow swings (its rate state's noise from the 5 Hz loop):
  // hence 0.2. adaptive_coherent = false: always max_coherent_ms while bits are known.
  int max_coherent_ms = 100;  // 20 (off), 40, 100, 200 or 400
  bool adaptive_coherent = true;
  // The front end's oscillator (Allan coefficients, signals/oscillator_allan.hpp; 0 = a perfect clock): its phase
  // noise passes a PLL as jitter that grows as the bandwidth narrows (receiver/long_coherent.hpp), so with it the
  // choice of N minimises the total jitter, thermal and oscillator: a TCXO's random-walk frequency (Brown & Hwang,
  // h-2 2e-20) puts 48 deg into the 2 Hz loop of 100 ms integration and 12 deg into the 5 Hz one of 20 ms.
  // Default: a TCXO (oscillator_signal_preset("tcxo")), the clock of real front ends (RTL-SDR, MAX2769 and
  // HackRF boards, bladeRF). Assuming a perfect clock on a TCXO's signal picks 100 ms below 30.2 dB-Hz and loses
  // every satellite there; assuming a TCXO on a perfect clock's signal costs ~1 dB of threshold (29.0 against
  // 27.9 dB-Hz: docs/validation.md, section 16). set_tracking_oscillator() names the class.
  double oscillator_h0 = signals::oscillator_signal_preset("tcxo")->h0;              // white frequency, s; [0, 1e-17]
  double oscillator_h_minus2 = signals::oscillator_signal_preset("tcxo")->h_minus2;  // random walk, 1/s; [0, 1e-17]
  double coherent_jitter_deg = 4.0;                                                  // (0, 30]
  double coherent_hysteresis_db = 2.0;                                               // [0, 10]
  double coherent_max_bn_t = 0.2;                                                    // (0, 0.25]
  // Lock test of a channel whose replica a filter drives (ultra-tight: set_filter_driven): the scalar loss test
  // above (0.2 s C/N0 below cn0_loss_threshold_dbhz or PLI below pli_loss_threshold for loss_of_lock_time_s)
  // is replaced by receiver/presence_test.hpp on the 20 ms epochs: prompt power over the noise tap's over
  // non-overlapping presence_window_s windows, absent below presence_threshold_dbhz (one failing window: loss,
  // then coasting). With the defaults (1 s, 12 dB-Hz) a window misses an absent signal with probability 0.085
  // and calls a present one absent with 1.5e-3 at 18 dB-Hz, 7.5e-5 at 19, 1.0e-6 at 20 (exact: docs/validation.md):
  // a 60 s run is falsely lost with 8.7 % at 18, 0.45 % at 19, 0.006 % at 20 dB-Hz; an absent signal is declared
  // lost at the end of the first window without it with 91.5 % (1-2 s after it goes), one window later with 99.3 %.
  // Long coherent sums of such a channel use a pure (atan2) PLL discriminator: the bits are wiped.
  // Below ~22 dB-Hz one failing window no longer ends the lock: a loss needs k consecutive failing windows, k
  // the smallest up to presence_max_windows whose false-loss probability in a minute, exact at the channel's
  // level less 2 dB (the level: its latest windows reading >= presence_relock_dbhz), is at most
  // presence_false_loss_per_min (defaults: k = 1 for a level above 21.4 dB-Hz, as before; 2 down to 19.6, 3 to
  // 18.6, 4 to 17.8, then 5: a minute at 16 dB-Hz holds a false loss with probability 1.8e-5 (k = 5) instead of
  // 0.95, at 15 dB-Hz 1.9e-3, at 14 0.039; receiver/presence_test.hpp). A coasting
  // filter-driven channel re-locks when two consecutive windows read at least presence_relock_dbhz (noise does
  // so with probability 5.6e-5 per pair, a 16 dB-Hz signal with 0.48), as well as by the C/N0 rule above.
  double presence_window_s = 1.0;             // [0.1, 5]
  double presence_threshold_dbhz = 12.0;      // [0, 30]
  int presence_max_windows = 5;               // [1, 10]
  double presence_false_loss_per_min = 1e-3;  // (0, 1)
  double presence_relock_dbhz = 15.0;         // [presence_threshold_dbhz, 40]

  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

// The front end's oscillator class for the loops: "tcxo" or "ocxo" (signals::oscillator_signal_preset), or
// "ideal" (also "none": a perfect clock, for simulated files without clock noise). False for another name
// (nothing changes).
bool set_tracking_oscillator(ScalarTrackingOptions& options, const std::string& name);
// The class name the coefficients match ("tcxo", "ocxo", "ideal"), or "custom".
std::string tracking_oscillator_name(const ScalarTrackingOptions& options);

// The channel configuration these options need (correlator layout with the noise tap when kNoiseTap).
ChannelConfig channel_config(const ScalarTrackingOptions& options, int prn, double sample_rate_hz,
                             int num_antennas = 1);

}  // namespace ultratrack::receiver
