// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_alignment_run.hpp"

#include <fmt/core.h>

#include "io/units.hpp"

namespace ultratrack::pipelines {

std::map<std::string, std::string> campaign_alignment_scalars(const CampaignAlignmentJob& job) {
  // One run of the Monte Carlo: its mean is the run's error, its mean sigma the run's sigma.
  const AlignmentMonteCarloResult r = alignment_monte_carlo(job.scenario, job.options, 1, job.seed);
  std::map<std::string, std::string> scalars;
  const char* names[3] = {"roll", "pitch", "yaw"};
  const AxisStatistics* axes[3] = {&r.roll, &r.pitch, &r.yaw};
  for (int i = 0; i < 3; ++i) {
    scalars[std::string(names[i]) + "_error_deg"] = fmt::format("{:.17g}", axes[i]->mean / io::kRadPerDeg);
    scalars[std::string(names[i]) + "_sigma_deg"] = fmt::format("{:.17g}", axes[i]->mean_sigma / io::kRadPerDeg);
  }
  return scalars;
}

}  // namespace ultratrack::pipelines
