// SPDX-License-Identifier: GPL-3.0-or-later
// What a campaign run computes from its output files (lock outcomes, nav z-scores). Written per run, so that a
// report can be redone from the run folders alone:
//   lock outcomes   each simulated satellite of a receive classified from tracking.csv (the tracking threshold);
//   nav z-scores    the fused nav.csv against the simulation's truth.csv at fixed times, each NED position and
//                   velocity error divided by nav.csv's own 1-sigma (the filter's consistency);
//   weak part       the step protocol's position errors after the step: solution.csv's fixes and nav.csv's rows
//                   from a time on, 3-D RMS and maximum against truth.csv (benchmarks/tracking_threshold.sh's
//                   positions.csv and nav_positions.csv).
// Units: s, m, m/s. Times are seconds since the first sample (tracking.csv time_s, nav.csv and truth.csv t_s).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace ultratrack::pipelines {

// kept: locked (phase-locked or bit-synced) by the deadline (or, with strong_s > 0, within 0.2 s before the C/N0
// step at strong_s), then every record of the PRN locked with no gap > 0.2 s up to within 0.2 s of the end;
// lost: locked, then an unlocked record, a gap or an early end; never_locked: tracked but not locked by the
// deadline; not_locked_at_step: tracked but not locked at the step; not_acquired: no tracking record at all.
struct LockOutcomeOptions {
  double lock_deadline_s = 5.0;
  double strong_s = 0.0;  // > 0: the step protocol (strong signal for strong_s, then the level under test)
};

struct LockOutcome {
  int prn = 0;
  std::string outcome;       // kept, lost, never_locked, not_locked_at_step, not_acquired
  std::string first_lock_s;  // "%.3f" or empty
  std::string lock_end_s;    // "%.3f" or empty
};

// prns: the satellites that were in the signal; duration_s: the signal's length. A missing tracking.csv counts
// every PRN not acquired. Throws io::InputError for a malformed tracking.csv.
std::vector<LockOutcome> lock_outcomes(const std::vector<int>& prns, const std::filesystem::path& tracking_csv,
                                       double duration_s, const LockOutcomeOptions& options);
void write_lock_outcomes_csv(const std::filesystem::path& file, const std::vector<LockOutcome>& outcomes);
std::vector<LockOutcome> read_lock_outcomes_csv(const std::filesystem::path& file);

// At evaluation time t: the last nav.csv row at or before t, against truth.csv interpolated linearly (ECEF
// position, NED velocity) at that row's time. z = error / sigma; order N, E, D position then N, E, D velocity.
struct NavZ {
  double t_s = 0.0;  // the evaluation time asked for
  std::array<double, 6> z{}, error{}, sigma{};
};

// Times before the first nav.csv row are left out. Throws io::InputError for a missing or malformed file.
std::vector<NavZ> nav_z_scores(const std::filesystem::path& nav_csv, const std::filesystem::path& truth_csv,
                               const std::vector<double>& times_s);
void write_nav_z_csv(const std::filesystem::path& file, const std::vector<NavZ>& rows);
std::vector<NavZ> read_nav_z_csv(const std::filesystem::path& file);

// 3-D position errors (m) of the fixes (solution.csv, receiver time of week against truth.csv's tow_s) and of the
// fused rows (nav.csv, t_s) at and after from_s seconds since the first sample, against truth.csv interpolated
// linearly. rms and max are NaN where nothing was compared; a missing nav.csv counts no rows. Throws
// io::InputError for a malformed file.
struct WeakPartPositions {
  int fixes = 0;
  double rms_3d_m = 0.0, max_3d_m = 0.0;
  int nav_rows = 0;
  double nav_rms_3d_m = 0.0, nav_max_3d_m = 0.0;
};
WeakPartPositions weak_part_positions(const std::filesystem::path& solution_csv, const std::filesystem::path& nav_csv,
                                      const std::filesystem::path& truth_csv, double from_s);

}  // namespace ultratrack::pipelines
