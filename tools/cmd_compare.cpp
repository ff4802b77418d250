// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack compare --solution S --truth T [--skip S] [--json]`: a receiver's solution.csv against a
// simulation's truth.csv (pipelines/solution_compare.hpp): position errors (3-D, horizontal, vertical RMS, max,
// mean ENU bias) and velocity errors, over the fixes the truth covers. Exit 3 when no fix could be compared.
// `ultratrack compare --tracking tracking.csv --satellite-truth satellite_truth.csv [--from S] [--end S]`: each
// channel against the signal by the common loss-of-lock rule (pipelines/truth_lock_rule.hpp), one line per
// satellite (prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,records) as CSV on stdout.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "io/input_error.hpp"
#include "pipelines/solution_compare.hpp"
#include "pipelines/truth_lock_rule.hpp"

namespace ultratrack::tools {

namespace {

struct CompareArgs {
  std::string solution, truth, skip = "0";
  std::string tracking, satellite_truth, from = "0", end = "0", code_error = "0.5", frequency_error = "2.5";
  bool json = false;
};

void run_lock_rule(const CompareArgs& args) {
  pipelines::TruthLockOptions options;
  options.from_s = parse_double_option("--from", args.from);
  options.end_s = parse_double_option("--end", args.end);
  options.code_error_chips = parse_double_option("--code-error-chips", args.code_error);
  options.frequency_error_hz = parse_double_option("--frequency-error-hz", args.frequency_error);
  if (std::string why; !options.IsValid(&why)) throw io::InputError("command line", why);
  const auto outcomes = pipelines::truth_lock_outcomes(args.satellite_truth, args.tracking, options);
  fmt::print("{}", pipelines::truth_lock_outcomes_text(outcomes));
}

void run_compare(const CompareArgs& args) {
  if (!args.tracking.empty() || !args.satellite_truth.empty()) {
    if (args.tracking.empty() || args.satellite_truth.empty())
      throw io::InputError("command line", "--tracking and --satellite-truth go together");
    if (!args.solution.empty() || !args.truth.empty())
      throw io::InputError("command line", "--tracking compares channels, --solution fixes: one at a time");
    run_lock_rule(args);
    return;
  }
  if (args.solution.empty() || args.truth.empty())
    throw io::InputError("command line", "give --solution and --truth (or --tracking and --satellite-truth)");
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
  cmd->add_option("--solution", args->solution, "solution.csv written by `ultratrack receive`");
  cmd->add_option("--truth", args->truth, "truth.csv written by `ultratrack simulate`");
  cmd->add_option("--skip", args->skip, "seconds after the first fix left out (settling)")->capture_default_str();
  cmd->add_flag("--json", args->json, "machine-readable output");
  cmd->add_option("--tracking", args->tracking,
                  "tracking.csv of `ultratrack receive`: each channel judged by the common loss-of-lock rule");
  cmd->add_option("--satellite-truth", args->satellite_truth, "satellite_truth.csv written by `ultratrack simulate`");
  cmd->add_option("--from", args->from, "with --tracking: judged from this time (s since the first sample)")
      ->capture_default_str();
  cmd->add_option("--end", args->end, "with --tracking: the signal's end in s (0: the truth's last row)")
      ->capture_default_str();
  cmd->add_option("--code-error-chips", args->code_error, "with --tracking: the code error bound")
      ->capture_default_str();
  cmd->add_option("--frequency-error-hz", args->frequency_error,
                  "with --tracking: the bound of each 1 s mean carrier frequency error")
      ->capture_default_str();
  cmd->callback([args] { run_compare(*args); });
}

}  // namespace ultratrack::tools
