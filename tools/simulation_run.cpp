// SPDX-License-Identifier: GPL-3.0-or-later
#include "simulation_run.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "config/scenario_toml.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::tools {
sim::SimulationResult run_simulation(const sim::Scenario& scenario, const std::filesystem::path& out_dir,
                                     std::FILE* progress, std::stop_token stop) {
  const auto print = [progress](const sim::SimulationProgress& p) {
    if (p.stage == sim::SimulationProgress::Stage::Imu) {
      fmt::print(stderr, "simulate: IMU {}%\n", p.percent);
      return;
    }
    if (!progress) return;
    fmt::print(progress, "simulate: {:5.1f} / {:.1f} s of signal ({:3d}%), {:.1f}x real time\n", p.done_s, p.total_s,
               p.percent, p.done_s / std::max(p.wall_s, 1e-9));
    std::fflush(progress);
  };
  return sim::simulate_to_folder(scenario, out_dir, config::to_toml(scenario), std::move(stop), print);
}

}  // namespace ultratrack::tools
