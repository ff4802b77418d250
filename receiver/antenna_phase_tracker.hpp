// SPDX-License-Identifier: GPL-3.0-or-later
// Per-channel between-antenna carrier phase: every antenna is correlated against the master antenna's one
// replica, so arg(P_k conj(P_0)) is the carrier phase of antenna k minus that of the master, free of the
// replica's error and of the navigation bit. This tracker unwraps it by continuity across correlation epochs
// (an alpha-beta predictor of phase and rate), and decides when that continuity is lost: the signal faded at
// antenna k (|P_k|^2 / |P_0|^2 collapses: blockage), a phase-rate jump (innovation above a threshold), the
// master's loop out of lock, or antenna k's C/N0 below a threshold. Units: cycles (RINEX sense: phase_k - phase_0
// grows as antenna k moves away from the satellite), Hz, dB-Hz, sample indices on the receiver's clock.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "receiver/antenna_phase.hpp"
#include "receiver/correlation_epoch.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

struct AntennaPhaseTrackerOptions {
  // |P_k|^2 / |P_0|^2 below fade_power_ratio in one epoch: the signal is absent at antenna k (-10 dB; at
  // 45 dB-Hz and 20 ms a present signal reads 1 +- 0.1, an absent one ~0.002). Back after recover_epochs
  // successive epochs above recover_power_ratio.
  double fade_power_ratio = 0.1;
  double recover_power_ratio = 0.3;
  int recover_epochs = 3;
  // |innovation| of the between-antenna phase (measured - predicted) above this: continuity lost (slip).
  // The epoch-to-epoch jitter is ~0.01-0.02 cycles at 45 dB-Hz with 3 mm of extra phase noise.
  double slip_threshold_cycles = 0.2;
  double rate_gain = 0.05;           // beta of the alpha-beta predictor (alpha = 1: the output is the measurement)
  double min_cn0_dbhz = 25.0;        // antenna k's C/N0 below this: unusable
  double cn0_time_constant_s = 0.2;  // smoothing of the per-antenna power estimates
};

// The state of antenna k's between-antenna phase at one sample.
struct AntennaPhaseSample {
  double phase_cycles = 0.0;  // phase_k - phase_0, cycles, RINEX sense, extrapolated to the sample
  double cn0_dbhz = NAN;      // from antenna k's prompt and noise tap; NaN without a noise tap (or no noise)
  double power_ratio = 0.0;   // smoothed |P_k|^2 / |P_0|^2
  bool usable = false;
  // Continuity was lost since the previous usable report: raised with the first usable phase after the break
  // (never while unusable), cleared by report().
  bool slip = false;
};

class AntennaPhaseTracker {
 public:
  explicit AntennaPhaseTracker(int num_antennas, const AntennaPhaseTrackerOptions& options = {});

  // One completed correlation epoch of the channel; master_locked: the master's loop holds carrier phase lock.
  // Allocates nothing.
  void update(const CorrelationEpoch& e, bool master_locked, double fs_hz);

  // Antenna k (1..num_antennas-1) at sample_index. report() clears the slip flag once it has been given with a
  // usable phase (a slip seen while unusable is reported at the first usable epoch after it).
  AntennaPhaseSample peek(int k, std::int64_t sample_index, double fs_hz) const;
  AntennaPhaseSample report(int k, std::int64_t sample_index, double fs_hz);
  int num_antennas() const { return num_antennas_; }

 private:
  struct State {
    bool started = false;  // continuity holds from the last (re)start
    bool faded = false;
    int good_epochs = 0;
    bool slip_pending = true;   // the first report after a (re)start is a slip
    double phase_cycles = 0.0;  // unwrapped phase_k - phase_0 at sample_mid
    double rate_hz = 0.0;
    double sample_mid = 0.0;
    double signal_power = 0.0, noise_power = 0.0, master_power = 0.0;  // smoothed |P_k|^2, |noise_k|^2, |P_0|^2
    bool have_power = false;
    double cn0_dbhz = NAN;
  };
  void restart(State& s);

  int num_antennas_;
  AntennaPhaseTrackerOptions options_;
  bool master_locked_ = false;
  std::array<State, kMaxAntennas> state_{};
};

// One satellite's AntennaPhaseObservation: the master's carrier phase (RINEX sense, from the channel's
// measurement) plus each antenna's between-antenna phase, and the line of sight from the master position to the
// satellite at its transmit time (receive_time - pseudorange / c, corrected by the fix's clock bias, Sagnac
// rotated). master_slip: the master's track is new (its phase restarted).
AntennaPhaseObservation make_antenna_observation(AntennaPhaseTracker& tracker, int prn, double master_phase_cycles,
                                                 double master_cn0_dbhz, bool master_slip, double pseudorange_m,
                                                 const signals::Ephemeris& eph, const signals::GpsTime& receive_time,
                                                 double clock_bias_m, const Eigen::Vector3d& master_position_e,
                                                 std::int64_t sample_index, double fs_hz);

}  // namespace ultratrack::receiver
