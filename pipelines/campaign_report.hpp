// SPDX-License-Identifier: GPL-3.0-or-later
// A campaign's report: what is complete, failed and missing, and the tables the campaign asks for. They reduce
// whatever runs are complete (pipelines/campaign_run.hpp's folders). The reductions print the tables the
// benchmark scripts printed (benchmarks/tracking_threshold.sh, ultratight_consistency.sh), in the same format:
//   lock threshold   per level of a parameter (C/N0, dB-Hz): satellite-runs kept, lost, never locked, not
//                    acquired; the fraction kept with its Wilson 68 % interval, of acquired and of locked
//                    satellites, and the level above which it stays >= 0.9 (interpolated; its range from the
//                    interval curves);
//   nav consistency  per evaluation time: mean z and mean z^2 per NED axis of position and velocity over the runs
//                    (95 % bands +-1.96/sqrt(N) and chi2(N)/N, Wilson-Hilferty), RMS error and RMS sigma;
//   stats            a run scalar (complete.csv) or parameter: count, mean with its 95 % Student-t interval,
//                    median, standard deviation, minimum and maximum;
//   rms, table, error_stats   the fuse and alignment Monte Carlos' tables (pipelines/campaign_tables.hpp).
// The step protocol (LockOutcomeOptions::strong_s) adds the not_locked_at_step column when a satellite was not
// locked at its step; its position RMS columns are run scalars ([compute] weak_part_from_s) for `stats`. Each
// reduction may split the runs by parameters (`group`): one table per combination, in the sorted order of their
// values (as the scripts sort couplings and filters).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipelines/campaign_plan.hpp"

namespace ultratrack::pipelines {

struct CampaignReduction {
  enum class Kind { kLockThreshold, kNavConsistency, kStats, kRms, kTable, kErrorStats };
  Kind kind = Kind::kStats;
  std::vector<std::string> group;   // parameters that split the runs
  std::string level = "cn0_dbhz";   // kLockThreshold: the parameter whose values are the levels (numbers)
  std::vector<double> times_s;      // kNavConsistency: the evaluation times (those the runs computed)
  std::string value;                // kStats: a complete.csv scalar or a parameter (numbers)
  std::vector<std::string> values;  // kRms: values; kTable: columns; kErrorStats: axes (pipelines/campaign_tables.hpp)
};

// The report's text. Reads complete.csv, lock_outcomes.csv and nav_z.csv of the complete runs; throws
// io::InputError for a malformed one.
std::string campaign_report(const std::filesystem::path& campaign_dir, const std::vector<CampaignRun>& runs,
                            const std::vector<CampaignReduction>& reductions);

// Wilson score interval of k successes in n at z sigmas ((0, 1) when n = 0).
std::pair<double, double> wilson_interval(int k, int n, double z);

}  // namespace ultratrack::pipelines
