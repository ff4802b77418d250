// SPDX-License-Identifier: GPL-3.0-or-later
// The report tables of the fuse and alignment Monte Carlos: rms, table and error_stats. pipelines/campaign_report.hpp
// calls them with the complete runs of one group, each run as its values (parameters and complete.csv scalars):
//   rms          per value: runs, RMS and largest magnitude (benchmarks/fuse_outage_mc.sh's line);
//   table        one markdown row per run, columns "name" or "name:.3f" (a number formatted so), in run order
//                (benchmarks/odometer_tables.sh's tables);
//   error_stats  per axis: mean, standard deviation (n - 1), RMS of {axis}_error_deg, the mean of
//                {axis}_sigma_deg and the runs whose error exceeds 3 of their sigma (benchmarks/alignment_mc.sh's
//                table, degrees).
// A value a run lacks is an io::InputError naming it (table: printed as "-").
#pragma once

#include <map>
#include <string>
#include <vector>

namespace ultratrack::pipelines {

using CampaignRunValues = std::map<std::string, std::string>;

std::string rms_table(const std::string& label, const std::vector<CampaignRunValues>& runs,
                      const std::vector<std::string>& values);
std::string run_table(const std::vector<CampaignRunValues>& runs, const std::vector<std::string>& columns);
std::string error_stats_table(const std::string& label, const std::vector<CampaignRunValues>& runs,
                              const std::vector<std::string>& axes);

}  // namespace ultratrack::pipelines
