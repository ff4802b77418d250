// SPDX-License-Identifier: GPL-3.0-or-later
// One run of a campaign over the filter-level stationary alignment Monte Carlo (pipelines/alignment_monte_carlo.hpp,
// benchmarks/alignment_mc.sh): the seed's closed-form IMU at rest and noisy GPS attitudes, aligned; the final
// errors and the filter's 1-sigma per axis. Run k of a campaign with seed = k is run k of alignment_monte_carlo with
// first_seed = 1 (the same draws), so that the campaign's report reproduces the program's table.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "fusion/stationary_alignment.hpp"
#include "pipelines/alignment_monte_carlo.hpp"

namespace ultratrack::pipelines {

struct CampaignAlignmentJob {
  StationaryScenario scenario;
  fusion::StationaryAlignmentOptions options;
  std::uint64_t seed = 1;
};

// Scalars (degrees, "%.17g"): roll_error_deg, pitch_error_deg, yaw_error_deg (estimate minus truth, yaw wrapped to
// +-180) and roll_sigma_deg, pitch_sigma_deg, yaw_sigma_deg (the filter's final 1-sigma).
std::map<std::string, std::string> campaign_alignment_scalars(const CampaignAlignmentJob& job);

}  // namespace ultratrack::pipelines
