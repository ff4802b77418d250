// SPDX-License-Identifier: GPL-3.0-or-later
// The antenna file of `ultratrack attitude`: the [solver] switches reach the solver's options, a wrong type is an
// InputError naming the key.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "config/antenna_config_toml.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

using namespace ultratrack;
using namespace ultratrack::config;

namespace {

std::filesystem::path write_antennas(const std::string& name, const std::string& solver) {
  const auto path = test::scratch_dir() / name;
  std::ofstream(path)
      << "[[antenna]]\nlever_arm_body_m = [0.0, 0.0, 0.0]\n[[antenna]]\nlever_arm_body_m = [1.0, 0.0, 0.0]\n"
         "[[antenna]]\nlever_arm_body_m = [0.0, 1.025, 0.0]\n[solver]\n"
      << solver;
  return path;
}

}  // namespace

TEST(AntennaConfig, SolverSwitchesReachTheSolverOptions) {
  const auto defaults = config::read_antenna_config(write_antennas("antennas_default.toml", ""));
  EXPECT_TRUE(defaults.solver.multi_epoch);
  EXPECT_TRUE(defaults.solver.use_length_constraint);
  EXPECT_EQ(defaults.solver.array.lever_arm_body_m.size(), 3u);
  const auto off = config::read_antenna_config(
      write_antennas("antennas_off.toml", "multi_epoch = false\nuse_length_constraint = false\n"));
  EXPECT_FALSE(off.solver.multi_epoch);
  EXPECT_FALSE(off.solver.use_length_constraint);
  try {
    config::read_antenna_config(write_antennas("antennas_bad.toml", "multi_epoch = 3\n"));
    FAIL() << "no InputError";
  } catch (const signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("solver.multi_epoch"), std::string::npos) << e.what();
  }
}
