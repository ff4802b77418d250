// SPDX-License-Identifier: GPL-3.0-or-later
// The one loss-of-lock rule of threshold comparisons, the same for every coupling: each tracking channel judged
// against the simulator's truth (satellite_truth.csv of `ultratrack simulate`), not by its receiver's own
// detectors (a scalar channel's C/N0 test, a filter-driven channel's presence test), so that a threshold gap
// between couplings means the same thing for each.
// Per record of tracking.csv (its sample, doppler_hz, and code_phase_chips at the epoch's first sample):
//   code error       replica code phase minus the signal's at that sample, wrapped to [-511.5, 511.5) chips; the
//                    signal's is the nearest truth row's advanced at its code rate 1.023 MHz x (1 + f_D / f_L1)
//                    (truth rows every 0.1 s: the code rate's change over 50 ms moves it < 1e-3 chip)
//   frequency error  replica carrier frequency minus the signal's Doppler (linear between truth rows), Hz
// A satellite is kept over [from_s, end_s] when records cover the span (no gap over max_gap_s, the first within
// max_gap_s of from_s and the last within max_gap_s of end_s), every record's |code error| <= code_error_chips, and
// the mean frequency error of every window_s window (from from_s on) lies within frequency_error_hz.
// Why these bounds: beyond half a chip the prompt has left the correlation peak's main half (the DLL cannot pull
// back); 2.5 Hz is half of the nearest false-lock offset of a Costas loop over 100 ms of coherent integration
// (1 / (2 T) = 5 Hz), so a channel that has slipped onto a false frequency is lost while a locked channel's
// 1 s mean (its jitter averaged) stays far inside.
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace ultratrack::pipelines {

struct TruthLockOptions {
  double from_s = 0.0;  // judged from this time on (seconds since the first sample), e.g. a C/N0 step
  double end_s = 0.0;   // the signal's end; 0: the last truth row
  double code_error_chips = 0.5;
  double frequency_error_hz = 2.5;
  double window_s = 1.0;
  double max_gap_s = 0.2;

  // Bounds and window positive and finite, from_s >= 0, end_s 0 or after from_s.
  bool IsValid(std::string* why) const;
};

struct TruthLockOutcome {
  int prn = 0;
  std::string outcome;  // kept, lost, not_tracked (no record in the span)
  std::string reason;   // lost: "code", "frequency", "gap" or "end"; otherwise empty
  double lost_s = std::numeric_limits<double>::quiet_NaN();  // where the first bound broke (lost only)
  double max_code_error_chips = 0.0;                         // largest |code error| up to the loss (or the end)
  double max_frequency_error_hz = 0.0;  // largest |window mean frequency error| up to the loss (or the end)
  int records = 0;                      // records judged
};

// Every satellite of satellite_truth.csv transmitted at from_s, in PRN order. Throws io::InputError naming the file
// for a missing or malformed file (or fewer than two truth rows), std::invalid_argument for invalid options.
std::vector<TruthLockOutcome> truth_lock_outcomes(const std::filesystem::path& satellite_truth_csv,
                                                  const std::filesystem::path& tracking_csv,
                                                  const TruthLockOptions& options);

// truth_lock_outcomes.csv of a campaign run: prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,
// records (lost_s empty unless lost), written atomically; the reader throws io::InputError naming the file.
std::string truth_lock_outcomes_text(const std::vector<TruthLockOutcome>& outcomes);  // the CSV's text
void write_truth_lock_outcomes_csv(const std::filesystem::path& file, const std::vector<TruthLockOutcome>& outcomes);
std::vector<TruthLockOutcome> read_truth_lock_outcomes_csv(const std::filesystem::path& file);

}  // namespace ultratrack::pipelines
