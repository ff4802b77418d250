// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate --scenario S.toml --out DIR`: synthesise IF samples and truth from a scenario
// (config/scenario_toml.hpp for the keys, sim/simulation_files.hpp for the outputs). Ctrl-C stops the run
// early and still finishes the files.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "config/scenario_toml.hpp"
#include "interrupt_guard.hpp"
#include "io/input_error.hpp"
#include "simulation_run.hpp"

namespace ultratrack::tools {

void add_simulate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Synthesise IF samples, IMU data and truth from a scenario");
  auto scenario_path = std::make_shared<std::string>();
  auto out_dir = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  auto settings = std::make_shared<std::vector<std::string>>();
  cmd->add_option("--scenario", *scenario_path, "Scenario file (TOML)")->required();
  cmd->add_option("--set", *settings,
                  "Change a scenario key before it is read: KEY=VALUE, the key dotted (signal.cn0_dbhz=35), the value "
                  "as TOML or a bare string; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--out", *out_dir, "Output folder (created when missing)")->required();
  cmd->add_flag("--quiet", *quiet, "No progress lines");
  cmd->callback([scenario_path, out_dir, quiet, settings] {
    std::vector<config::TomlOverride> overrides;
    for (const std::string& s : *settings) {
      try {
        overrides.push_back(config::parse_toml_override(s));
      } catch (const std::invalid_argument& e) {
        throw io::InputError("--set", e.what());
      }
    }
    const sim::Scenario scenario = config::read_scenario(*scenario_path, overrides);
    const InterruptGuard interrupt;
    const auto r = run_simulation(scenario, *out_dir, *quiet ? nullptr : stderr, interrupt.token());
    const std::string inertial =
        scenario.trajectory_enabled()
            ? fmt::format("imu.csv ({} rows at {} Hz, preset {}), {}", r.imu_rows, scenario.imu_rate_hz,
                          scenario.imu_preset, scenario.odometer ? "odometer.csv, " : "")
            : std::string();
    if (!scenario.signal) {
      fmt::print(
          "simulate: no [signal]: IMU and truth only in {:.1f} s\noutputs in {}: {}truth.csv, scenario.toml, "
          "summary.json\n",
          r.wall_s, *out_dir, inertial);
      return;
    }
    fmt::print("simulate: {:.1f} s of {} at {:.3f} MHz ({} antenna{}) in {:.1f} s ({:.1f}x real time){}\n", r.signal_s,
               signals::to_string(scenario.format), scenario.sample_rate_hz / 1e6, r.sample_files.size(),
               r.sample_files.size() == 1 ? "" : "s", r.wall_s, r.signal_s / std::max(r.wall_s, 1e-9),
               r.interrupted ? " - interrupted, files hold what was done" : "");
    fmt::print("satellites in view at the start (PRN  el deg  az deg  C/N0  Doppler Hz  code phase chips):\n");
    for (const auto& v : r.satellites) {
      fmt::print("  {:3d} {:6.1f} {:7.1f} {:5.1f} {:10.1f} {:9.3f}\n", v.prn, v.elevation_rad * 180.0 / M_PI,
                 v.azimuth_rad * 180.0 / M_PI, v.cn0_dbhz, v.doppler_hz, v.code_phase_chips);
    }
    fmt::print("outputs in {}: {}, {}truth.csv, {}satellites.csv, satellite_truth.csv, scenario.toml, summary.json\n",
               *out_dir, r.sample_files.front().filename().string(), inertial,
               scenario.trajectory_enabled() ? "antenna_truth.csv, " : "");
  });
}

}  // namespace ultratrack::tools
