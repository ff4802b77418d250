// SPDX-License-Identifier: GPL-3.0-or-later
// The fuse and alignment Monte Carlo reductions (pipelines/campaign_tables.hpp) against closed forms, the JSON
// scalars they read (io/json_lookup.hpp), and the alignment campaign run (pipelines/campaign_alignment_run.hpp)
// against the Monte Carlo program's own statistics over the same seeds.
#include "pipelines/campaign_tables.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "io/input_error.hpp"
#include "io/json_lookup.hpp"
#include "io/units.hpp"
#include "pipelines/campaign_alignment_run.hpp"

namespace {

using ultratrack::io::json_scalar_at;
using ultratrack::pipelines::CampaignRunValues;

TEST(JsonScalarAt, FindsNestedKeysAndArrayElementsAsWritten) {
  const std::string json = R"({"a": {"b": 1.50, "c": [3, {"d": "x\"y"}]}, "outages": [{"e": -2e-3}], "t": true})";
  EXPECT_EQ(json_scalar_at(json, "a.b"), "1.50");
  EXPECT_EQ(json_scalar_at(json, "a.c.0"), "3");
  EXPECT_EQ(json_scalar_at(json, "a.c.1.d"), "x\"y");
  EXPECT_EQ(json_scalar_at(json, "outages.0.e"), "-2e-3");
  EXPECT_EQ(json_scalar_at(json, "t"), "true");
  EXPECT_FALSE(json_scalar_at(json, "a"));      // an object, not a scalar
  EXPECT_FALSE(json_scalar_at(json, "a.c.2"));  // no such element
  EXPECT_FALSE(json_scalar_at(json, "b"));      // no such key
  EXPECT_FALSE(json_scalar_at(json, "a.b.c"));  // below a scalar
  EXPECT_THROW(json_scalar_at(R"({"a": 1,})", "a"), std::invalid_argument);
  EXPECT_THROW(json_scalar_at(R"({"a": 1} x)", "a"), std::invalid_argument);
  EXPECT_THROW(json_scalar_at(R"({"a": 1.2.3})", "a"), std::invalid_argument);
  EXPECT_THROW(json_scalar_at(R"({"a": "open)", "a"), std::invalid_argument);
}

TEST(CampaignTables, RmsIsTheRootMeanSquareAndTheLargestMagnitude) {
  const std::vector<CampaignRunValues> runs{{{"d", "3"}, {"s", "1"}}, {{"d", "-4"}, {"s", "1"}}};
  EXPECT_EQ(ultratrack::pipelines::rms_table("navigation", runs, {"d", "s"}),
            "navigation: 2 runs; d RMS 3.536 (max |d| 4.000); s RMS 1.000 (max |s| 1.000)\n");  // sqrt(12.5)
  EXPECT_THROW(ultratrack::pipelines::rms_table("x", runs, {"missing"}), ultratrack::io::InputError);
}

TEST(CampaignTables, RunTableFormatsColumnsAndMarksWhatIsMissing) {
  const std::vector<CampaignRunValues> runs{{{"mode", "gated"}, {"m", "2.345"}}, {{"mode", "always"}}};
  EXPECT_EQ(ultratrack::pipelines::run_table(runs, {"mode", "m:.1f"}),
            "| mode | m |\n|---|---|\n| gated | 2.3 |\n| always | - |\n");
  EXPECT_THROW(ultratrack::pipelines::run_table(runs, {"m:q"}), ultratrack::io::InputError);
}

TEST(CampaignTables, ErrorStatsAreMeanSampleStdRmsMeanSigmaAndOutliers) {
  // errors 1, -1, 4 (sigma 1): mean 4/3, std sqrt((1/9 + 49/9 + 64/9) / 2) = sqrt(19/3), RMS sqrt(18/3)
  const std::vector<CampaignRunValues> runs{{{"roll_error_deg", "1"}, {"roll_sigma_deg", "1"}},
                                            {{"roll_error_deg", "-1"}, {"roll_sigma_deg", "1"}},
                                            {{"roll_error_deg", "4"}, {"roll_sigma_deg", "1"}}};
  EXPECT_EQ(ultratrack::pipelines::error_stats_table("ekf", runs, {"roll"}),
            "ekf: 3 runs\n| axis | mean | std | RMS | mean 1-sigma | > 3 sigma |\n|---|---|---|---|---|---|\n"
            "| roll | 1.3333 | 2.5166 | 2.4495 | 1.0000 | 1 |\n");
}

TEST(CampaignAlignmentRun, SeedsOneToNReproduceTheMonteCarloOfNRuns) {
  ultratrack::pipelines::CampaignAlignmentJob job;
  job.scenario.lat_rad = 36.37 * ultratrack::io::kRadPerDeg;
  job.scenario.imu = ultratrack::ins::imu_preset("hg1700ae");
  job.scenario.gps_sigma_euler_rad = Eigen::Vector3d(0.255, 0.263, 0.087) * ultratrack::io::kRadPerDeg;
  job.options.imu = job.scenario.imu;
  const int n = 4;
  std::vector<CampaignRunValues> runs;
  for (int seed = 1; seed <= n; ++seed) {
    job.seed = static_cast<std::uint64_t>(seed);
    runs.push_back(ultratrack::pipelines::campaign_alignment_scalars(job));
  }
  const auto whole = ultratrack::pipelines::alignment_monte_carlo(job.scenario, job.options, n, 1);
  const double d = ultratrack::io::kRadPerDeg;
  const ultratrack::pipelines::AxisStatistics* axes[3] = {&whole.roll, &whole.pitch, &whole.yaw};
  const char* names[3] = {"roll", "pitch", "yaw"};
  for (int i = 0; i < 3; ++i) {
    double sum = 0, sum2 = 0, sigma = 0;
    for (const auto& run : runs) {
      const double e = std::stod(run.at(std::string(names[i]) + "_error_deg"));
      sum += e, sum2 += e * e, sigma += std::stod(run.at(std::string(names[i]) + "_sigma_deg"));
    }
    EXPECT_NEAR(sum / n, axes[i]->mean / d, 1e-12) << names[i];
    EXPECT_NEAR(std::sqrt(sum2 / n), axes[i]->rms / d, 1e-12) << names[i];
    EXPECT_NEAR(sigma / n, axes[i]->mean_sigma / d, 1e-12) << names[i];
    EXPECT_GT(std::abs(sum), 0.0);  // the runs did align with noise
  }
}

}  // namespace
