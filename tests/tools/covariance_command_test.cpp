// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack covariance --coupling ultra-tight`: the options reach the analysis (the CSV history equals the
// library's run with the same settings) and bad choices are typed input errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fusion/covariance_analysis.hpp"
#include "io/input_error.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace {

using ultratrack::test_support::run_command;
namespace fusion = ultratrack::fusion;

std::vector<std::vector<double>> read_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

TEST(CovarianceCommand, UltraTightOptionsReachTheAnalysis) {
  const std::string csv = (ultratrack::test::scratch_dir() / "ultratight_cov.csv").string();
  run_command("covariance",
              {"--trajectory", "s", "--coupling", "ultra-tight", "--filter", "ukf", "--iq-measurement", "discriminator",
               "--cn0-dbhz", "38", "--integration-ms", "10", "--spacing-chips", "0.5", "--times", "0.5", "--csv", csv},
              false);
  auto o = fusion::seed001_ultratight_options("s", fusion::FilterKind::Ukf, fusion::IqForm::Discriminator);
  o.iq.cn0_dbhz = 38.0;
  o.iq.integration_time_s = 0.01;
  o.iq.tap_offset_chips = 0.25;
  o.update_interval_s = o.propagation_interval_s = 0.01;
  o.duration_s = 0.5;
  const auto r = fusion::run_covariance_analysis(o);
  const auto rows = read_csv(csv);
  ASSERT_EQ(rows.size(), r.samples.size());
  ASSERT_EQ(rows.size(), 51u);  // the prior and 50 updates at 100 Hz
  for (std::size_t k = 0; k < rows.size(); ++k)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(rows[k][1 + i], r.samples[k].sigma_pos_ned_m[i], 1e-9);
}

TEST(CovarianceCommand, BadUltraTightChoicesAreInputErrors) {
  EXPECT_THROW(run_command("covariance", {"--trajectory", "s", "--coupling", "loose"}, false),
               ultratrack::io::InputError);
  EXPECT_THROW(
      run_command("covariance", {"--trajectory", "s", "--coupling", "ultra-tight", "--iq-measurement", "phase"}, false),
      ultratrack::io::InputError);
  EXPECT_THROW(run_command("covariance", {"--trajectory", "s", "--absolute-carrier-phase"}, false),
               ultratrack::io::InputError);
  EXPECT_THROW(
      run_command("covariance", {"--trajectory", "s", "--coupling", "ultra-tight", "--spacing-chips", "1.5"}, false),
      ultratrack::io::InputError);
}

}  // namespace
