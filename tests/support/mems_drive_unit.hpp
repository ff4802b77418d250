// SPDX-License-Identifier: GPL-3.0-or-later
// One simulated unit of the ADIS16405-class MEMS drive (scenarios/mems_drive_adis16405.toml, IMU errors drawn with
// imu_seed) written under dir and read back as `fuse` would, with the drive's 5 Hz fixes at non-integer times
// (0.5/0.5/1 m; with_velocity adds 0.05 m/s velocity noise). Shared by the MEMS fusion tests.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "config/scenario_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/truth_interpolator.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "sim/simulation_files.hpp"
#include "sim/truth_csv.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines::test_support {

struct MemsDriveUnit {
  sim::Scenario scenario;
  sim::SimulationResult simulated;
  std::vector<ins::ImuIncrement> imu;
  ins::TruthInterpolator truth;
  GnssFixSimulationOptions fix_options;
  std::vector<GnssFixRow> fixes;
};

inline MemsDriveUnit simulate_mems_drive_unit(const std::filesystem::path& dir, std::uint64_t imu_seed,
                                              bool with_velocity) {
  const auto scenario_file = test::scenarios_dir() / "mems_drive_adis16405.toml";
  sim::Scenario scenario = config::read_scenario(scenario_file);
  scenario.imu_seed = imu_seed;
  sim::SimulationResult simulated = sim::simulate_to_folder(scenario, dir / "sim", test::read_text_file(scenario_file));
  ins::TruthInterpolator truth(truth_samples_from_nav(sim::read_truth_csv(dir / "sim" / "truth.csv")));
  GnssFixSimulationOptions fixes;
  fixes.rate_hz = 5.0;
  fixes.first_time_s = 0.137;
  fixes.sigma_ned_m = Eigen::Vector3d(0.5, 0.5, 1.0);
  fixes.with_velocity = with_velocity;
  fixes.sigma_velocity_mps = 0.05;
  fixes.seed = imu_seed;
  std::vector<GnssFixRow> rows = simulate_gnss_fixes(truth, fixes);
  return {
      std::move(scenario), std::move(simulated), ins::read_imu_csv(dir / "sim" / "imu.csv"), std::move(truth), fixes,
      std::move(rows)};
}

}  // namespace ultratrack::pipelines::test_support
