// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate`'s run of a scenario into a folder (sim/simulation_files.hpp lists the files):
// sim::simulate_to_folder with scenario.toml = to_toml(scenario), progress lines on a stream, and a stop
// token (the command's tools/interrupt_guard.hpp).
#pragma once

#include <cstdio>
#include <filesystem>
#include <stop_token>

#include "sim/simulation.hpp"

namespace ultratrack::tools {

// progress: where to print progress lines (nullptr: silent; long IMU runs still report on stderr).
sim::SimulationResult run_simulation(const sim::Scenario& scenario, const std::filesystem::path& out_dir,
                                     std::FILE* progress = nullptr, std::stop_token stop = {});

}  // namespace ultratrack::tools
