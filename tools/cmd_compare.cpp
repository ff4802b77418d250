// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack compare --solution S --truth T [--skip S] [--json]`: a receiver's solution.csv against a
// simulation's truth.csv (pipelines/solution_compare.hpp): position errors (3-D, horizontal, vertical RMS, max,
// mean ENU bias) and velocity errors, over the fixes the truth covers. Exit 3 when no fix could be compared.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "io/input_error.hpp"
#include "pipelines/solution_compare.hpp"

namespace ultratrack::tools {

namespace {

struct CompareArgs {
  std::string solution, truth, skip = "0";
  bool json = false;
};

void run_compare(const CompareArgs& args) {
  pipelines::ComparisonOptions options;
  options.skip_s = parse_double_option("--skip", args.skip);
  if (!(options.skip_s >= 0.0)) throw io::InputError("command line", "--skip: must be >= 0 s");
  const auto solution = pipelines::read_solution_csv(args.solution);
  const auto truth = pipelines::read_simulation_truth_csv(args.truth);
  const pipelines::SolutionComparison c = pipelines::compare_solution(solution, truth, options);
  if (args.json) {
    fmt::print("{}", pipelines::to_json(c));
  } else {
    fmt::print("compare: {} fixes (tow {:.1f} .. {:.1f} s){}\n", c.fixes, c.first_tow_s, c.last_tow_s,
               c.fixes_outside_truth ? fmt::format(", {} outside the truth's span", c.fixes_outside_truth) : "");
    fmt::print(
        "position error: 3-D RMS {:.3f} m (horizontal {:.3f}, vertical {:.3f}), max {:.3f} m, "
        "mean ENU [{:.3f}, {:.3f}, {:.3f}] m\n",
        c.rms_3d_m, c.rms_horizontal_m, c.rms_vertical_m, c.max_3d_m, c.mean_enu_m.x(), c.mean_enu_m.y(),
        c.mean_enu_m.z());
    fmt::print("velocity error: 3-D RMS {:.4f} m/s (horizontal {:.4f}, vertical {:.4f}), max {:.4f} m/s\n",
               c.rms_velocity_mps, c.rms_velocity_horizontal_mps, c.rms_velocity_vertical_mps, c.max_velocity_mps);
  }
  if (c.fixes == 0) throw CommandExit(3, "no fix of the solution lies inside the truth's time span");
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("compare", "Compare a receiver's solution.csv with a simulation's truth.csv");
  auto args = std::make_shared<CompareArgs>();
  cmd->add_option("--solution", args->solution, "solution.csv written by `ultratrack receive`")->required();
  cmd->add_option("--truth", args->truth, "truth.csv written by `ultratrack simulate`")->required();
  cmd->add_option("--skip", args->skip, "seconds after the first fix left out (settling)")->capture_default_str();
  cmd->add_flag("--json", args->json, "machine-readable output");
  cmd->callback([args] { run_compare(*args); });
}

}  // namespace ultratrack::tools
