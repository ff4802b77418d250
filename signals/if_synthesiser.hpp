// SPDX-License-Identifier: GPL-3.0-or-later
// The IF signal synthesiser: GPS L1 C/A signals of a set of satellites as N antennas sampled on one
// receiver clock would record them (one sample stream per antenna, sample-synchronous), plus the exact
// truth of every signal. Times are seconds relative to the scenario start (options.start, true GPS time of
// sample 0); positions ECEF (WGS-84) m; phases in cycles; samples in the output format's units.
//
// Signal model (per satellite k, antenna a, sample n; tau = n / fs is the receiver's own time):
//   receiver clock error b(tau) (receiver clock - GPS time), true receive time t_r = tau - (b(tau) - b(0));
//   code: transmitted at t_tx = t_r - range/c - (I + T)/c, range from the iterated light time with the
//         satellite at t_tx and the Sagnac rotation; the SV clock reads t_sv = t_tx + dt_sv(t_tx) with
//         dt_sv = af0 + af1 dt + af2 dt^2 + relativistic - TGD (what an L1 C/A user corrects);
//         code phase = t_sv mod 1 ms in chips, data bit = LNAV bit on the air at t_sv;
//   carrier: the same with the ionosphere advancing it (-I), mixed with the receiver's LO
//         (which runs on the receiver clock b(0) + tau) and shifted to if_hz.
// So the pseudorange c * (receiver clock reading - t_sv) equals range + c (b - dt_sv) + I + T exactly.
// The exact values are computed at 1 ms nodes and interpolated linearly in between (error < 10 um of
// range for accelerations below 50 m/s^2); carrier from a 4096-entry phase table.
//
// Levels: complex white noise, sigma = 1 per component before gain (N0 = 2 sigma^2 / fs for the complex
// envelope), signal amplitude A = sigma * sqrt(2 C/N0 / fs): a correlator over T seconds then sees
// |signal|^2 / E|noise|^2 = C/N0 * T, the usual receiver definition. Real output (real formats, at if_hz):
// real noise sigma per sample, A = 2 sigma sqrt(C/N0 / fs) (the complex envelope after mixing down is A/2
// against noise of PSD sigma^2 / fs). Then one gain for the run (automatic gain): the expected RMS of each
// output component (noise plus all signals) becomes options.output_rms, e.g. 127/4 for 8-bit formats
// (clipping at 4 sigma: a fraction 6e-5 of samples clip; quantisation noise 1/12 LSB^2 is -41 dB).
#pragma once

#include <complex>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_transmitter.hpp"
#include "signals/receiver_clock.hpp"
#include "signals/receiver_motion.hpp"

namespace ultratrack::signals {

// Carrier impairments of one antenna (SynthesiserOptions::antenna_impairments[a]; missing entries are zero).
struct AntennaImpairment {
  // Constant offset of the antenna's carrier phase, cycles, RINEX sense (a longer cable reads more cycles).
  double line_bias_cycles = 0.0;
  // Extra carrier phase noise per satellite, 1 sigma, metres: a first-order Gauss-Markov process with
  // SynthesiserOptions::phase_noise_correlation_s, drawn at the 1 ms nodes (multipath/cable-like, on top of the
  // thermal noise the C/N0 gives).
  double phase_noise_m = 0.0;
};

// A phase step of `cycles` (RINEX sense) on one satellite's signal at one antenna from time_s on (receiver
// time since sample 0), with that signal absent for fade_s from time_s (a short fade, the usual cause of a
// slip). A whole number of cycles changes nothing a receiver can see once the signal is back: only the
// fade and the fractional part are observable; the receiver must flag the break in continuity.
struct CycleSlipEvent {
  int antenna = 0;
  int prn = 1;
  double time_s = 0.0;
  double cycles = 0.0;
  double fade_s = 0.1;
};

// Every satellite's signal absent at one antenna (noise only) for [start_s, start_s + duration_s).
struct BlockageEvent {
  int antenna = 0;
  double start_s = 0.0;
  double duration_s = 0.0;
};

// From the first sample at or after start_s (receiver time since sample 0: sample ceil(start_s fs)) on, the
// listed satellites (every satellite when `prns` is empty) arrive at antenna `antenna` with C/N0 cn0_dbhz,
// until a later step changes it (a weak-signal test: strong for acquisition and sync, then weak). Sample-exact,
// not resolved to the 1 ms blocks. The noise is not changed, nor the run's gain (set for each satellite's
// strongest level, so that a step up does not clip).
struct Cn0StepEvent {
  int antenna = 0;
  double start_s = 0.0;
  double cn0_dbhz = 45.0;
  std::vector<int> prns;  // empty: all
};

struct SynthesiserOptions {
  double sample_rate_hz = 4e6;      // > 0
  double if_hz = 0.0;               // output centre offset; |if_hz| < fs/2 (real output: 0 < if_hz < fs/2)
  bool real_output = false;         // real samples: the real part of the signal at if_hz, real noise
  double output_rms = 127.0 / 4.0;  // expected RMS of each output component (I, Q or real), output units
  GpsTime start;                    // true GPS time of sample 0
  double default_cn0_dbhz = 45.0;
  std::map<int, double> cn0_dbhz_by_prn;                             // per-PRN overrides
  double elevation_mask_rad = 5.0 * 3.14159265358979323846 / 180.0;  // seen from antenna 0
  bool include_unhealthy = false;  // transmit satellites whose ephemeris health is not 0
  bool ionosphere = true;          // Klobuchar with `klobuchar` (no delay when !klobuchar.valid)
  bool troposphere = false;        // standard troposphere (atmosphere.hpp)
  KlobucharParameters klobuchar;
  UtcParameters utc;     // broadcast in the LNAV message
  bool nav_data = true;  // modulate LNAV data bits (false: pure code, for tests)
  bool noise = true;     // add the receiver noise (false: signals only, same gain)
  ReceiverClockModel clock;
  std::uint64_t seed = 1;  // every random number comes from it
  // Another generator's conventions (a receiver must not depend on ours): the navigation message's encoding
  // (lnav_transmitter.hpp), and how often the exact signal parameters are computed. parameter_update_s = 1 ms
  // (ours) interpolates exact nodes every millisecond; a longer interval (e.g. 0.1 s, as gps-sdr-sim does)
  // computes them only at multiples of it and holds the code rate and the carrier frequency of the interval's
  // first millisecond until the next: the code phase is reset to the exact value at each update, the carrier
  // phase runs on continuously (integrated Doppler), so under acceleration it lags the geometry by half an
  // interval's frequency change. A multiple of 1 ms, 1 ms .. 1 s.
  LnavConventions lnav;
  double parameter_update_s = 1e-3;
  // Multi-antenna impairments. Event times are resolved to the 1 ms synthesis blocks.
  std::vector<AntennaImpairment> antenna_impairments;  // index = antenna
  double phase_noise_correlation_s = 0.1;              // > 0
  std::vector<CycleSlipEvent> cycle_slips;
  std::vector<BlockageEvent> blockages;
  std::vector<Cn0StepEvent> cn0_steps;

  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

// The first sample of a C/N0 step: the first sample at or after start_s (sample-exact).
std::int64_t cn0_step_first_sample(const Cn0StepEvent& step, double sample_rate_hz);

// A satellite as the receiver sees it from antenna 0 at one sample.
struct SatelliteView {
  int prn = 0;
  double elevation_rad = 0.0, azimuth_rad = 0.0;
  double cn0_dbhz = 0.0;          // at that sample (C/N0 steps applied)
  double doppler_hz = 0.0;        // d(carrier phase)/d(receiver time), IF removed; includes the rx clock drift
  double code_phase_chips = 0.0;  // chip of the code received at that sample, [0, 1023)
};

// The exact (not interpolated) signal parameters of one satellite at one sample of one antenna.
struct SignalTiming {
  double receive_time_s = 0.0;     // true GPS time of the sample since start
  double rx_clock_s = 0.0;         // receiver clock reading since start: b(0) + tau
  double code_sv_time_s = 0.0;     // SV clock time of the code received, since start
  double carrier_sv_time_s = 0.0;  // SV clock time of the carrier received, since start
  double pseudorange_m = 0.0;      // c * (rx_clock_s - code_sv_time_s)
  double geometric_range_m = 0.0;  // Sagnac-corrected, satellite at the code's true transmit time
  double iono_delay_m = 0.0;       // group delay (the carrier is advanced by as much)
  double tropo_delay_m = 0.0;
  double sv_clock_s = 0.0;            // dt_sv (af + relativistic - TGD)
  double rx_clock_bias_s = 0.0;       // b
  double code_phase_chips = 0.0;      // [0, 1023)
  double carrier_phase_cycles = 0.0;  // phase of the synthesised complex carrier (IF included), arbitrary origin
  double elevation_rad = 0.0, azimuth_rad = 0.0;
};

class IfSynthesiser {
 public:
  // ephemerides: at most one per PRN (the caller selects them for the start time); motion: the antennas.
  // Throws std::invalid_argument when the options are not valid (IsValid) or a PRN repeats.
  IfSynthesiser(SynthesiserOptions options, std::vector<Ephemeris> ephemerides,
                std::shared_ptr<const ReceiverMotion> motion);
  ~IfSynthesiser();
  IfSynthesiser(const IfSynthesiser&) = delete;
  IfSynthesiser& operator=(const IfSynthesiser&) = delete;

  int antenna_count() const;
  std::int64_t next_sample() const { return next_sample_; }

  // Writes the next out[a].size() samples of every antenna a (all spans the same size), in output units.
  void generate(std::span<const std::span<std::complex<float>>> out);

  // Satellites transmitted at a sample (above the mask at the last visibility check: every second).
  std::vector<SatelliteView> visible_satellites(std::int64_t sample);
  // Exact signal parameters; throws std::out_of_range for a PRN without ephemeris.
  SignalTiming timing(int prn, int antenna, std::int64_t sample);
  ReceiverClockState receiver_clock(std::int64_t sample);
  double receive_time_s(std::int64_t sample);  // true GPS time of a sample, since start
  const SynthesiserOptions& options() const { return options_; }
  const ReceiverMotion& motion() const { return *motion_; }

  double gain() const { return gain_; }         // output units per unit noise sigma
  double noise_sigma() const { return gain_; }  // per output component, output units
  double amplitude(int prn) const;              // signal amplitude in output units, at the scenario's C/N0
  // C/N0 of a satellite at one antenna and sample, the C/N0 steps applied; std::out_of_range for an unknown PRN.
  double cn0_dbhz(int prn, int antenna, std::int64_t sample) const;

 private:
  struct Impl;
  SynthesiserOptions options_;
  std::shared_ptr<const ReceiverMotion> motion_;
  std::unique_ptr<Impl> impl_;
  std::int64_t next_sample_ = 0;
  double gain_ = 1.0;
};

}  // namespace ultratrack::signals
