// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack attitude`: the multi-antenna receiver end to end (pipelines/attitude_file.hpp). N IF files recorded on
// one clock (antenna 0 the master); the scalar receiver acquires and tracks each satellite on the master and
// correlates every antenna against the master's replica (ReceiverOptions::num_antennas), each antenna's phase
// follows from the between-antenna prompt phase (receiver/antenna_phase_tracker.hpp), and the AttitudeSolver turns
// each epoch into roll, pitch and yaw.
// Outputs (receiver/attitude_outputs.hpp): attitude.csv, antenna_phases.csv, summary.json, position/ (as `receive`).
// Exit: 0 with at least one attitude; 2 for bad input; 3 when the signal ended before an attitude (outputs written).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "config/antenna_config_toml.hpp"
#include "interrupt_guard.hpp"
#include "io/why_invalid.hpp"
#include "pipelines/attitude_file.hpp"
#include "receiver/receiver_summary.hpp"
#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::tools {
namespace {

struct AttitudeArgs {
  std::vector<std::string> inputs;
  std::string format, fs, if_hz = "0", antennas, nav, out, duration, reference_week, interval, prns, threads;
  bool quiet = false;
};

void run_attitude(const AttitudeArgs& args) {
  const auto format = signals::parse_sample_format(args.format);
  if (!format)
    throw signals::InputError("command line",
                              "--format: unknown sample format '" + args.format + "' (i8, i16, f32, r8, r16)");
  const config::AntennaConfig antennas = config::read_antenna_config(args.antennas);
  const auto n_ant = antennas.solver.array.lever_arm_body_m.size();
  if (args.inputs.size() != n_ant)
    throw signals::InputError("command line", fmt::format("--input: {} files for the {} antennas of {}",
                                                          args.inputs.size(), n_ant, args.antennas));
  pipelines::AttitudeFileJob job;
  job.inputs.assign(args.inputs.begin(), args.inputs.end());
  job.format = *format;
  job.solver = antennas.solver;
  job.line_bias_cycles = antennas.line_bias_cycles;
  job.out = args.out;
  job.source.fs_hz = parse_double_option("--fs", args.fs);
  job.source.if_hz = parse_double_option("--if", args.if_hz);

  receiver::ReceiverOptions& options = job.options;
  options.fs_hz = job.source.fs_hz;
  options.num_antennas = static_cast<int>(n_ant);
  if (!args.prns.empty()) options.prns = parse_prn_list_option("--prn", args.prns);
  if (!args.threads.empty()) options.threads = parse_int_option("--threads", args.threads);
  if (!args.interval.empty()) options.observation_interval_s = parse_double_option("--interval", args.interval);
  if (!args.nav.empty()) job.navigation = signals::read_rinex_nav(args.nav);
  if (!args.reference_week.empty()) {
    options.reference_week = parse_int_option("--reference-week", args.reference_week);
    options.reference_week_is_signal_week = true;
  } else if (job.navigation.ephemerides.empty()) {  // else the nav file dates it (pipelines::attitude_file)
    throw signals::InputError("command line", "give --nav or --reference-week (the full GPS week of the recording)");
  }
  if (const std::string why = io::why_invalid(options); !why.empty()) throw signals::InputError("command line", why);
  job.duration_s = args.duration.empty() ? 0.0 : parse_double_option("--duration", args.duration);
  if (job.duration_s < 0.0) throw signals::InputError("command line", "--duration: must not be negative");

  InterruptGuard interrupt;  // Ctrl-C ends the loop; the outputs are still finished
  double next_progress_s = 10.0;
  const pipelines::AttitudeFileResult r = pipelines::attitude_file(
      std::move(job), interrupt.token(), [&](const receiver::ReceiverEngine& engine, const receiver::AttitudeStats& s) {
        const double t = receiver::processed_seconds(engine);
        if (args.quiet || t < next_progress_s) return;
        next_progress_s += 10.0;
        fmt::print(stderr, "attitude: {:.0f} s, tracking {}, attitude epochs {} (fixed {})\n", t,
                   engine.channels_in_use(), s.attitude_epochs, s.fixed_epochs);
      });
  const auto& s = r.stats;
  fmt::print("attitude: {:.1f} s of signal, {} antennas, in {:.1f} s ({:.1f}x real time, {} threads)\n", r.processed_s,
             n_ant, r.wall_s, r.wall_s > 0 ? r.processed_s / r.wall_s : 0.0, r.threads);
  fmt::print("attitude: epochs {}, with attitude {}, fixed {} ({:.1f} %); outputs in {}\n", s.epochs, s.attitude_epochs,
             s.fixed_epochs, s.epochs ? 100.0 * s.fixed_epochs / s.epochs : 0.0, args.out);
  if (s.attitude_epochs == 0)
    throw CommandExit(3, fmt::format("no attitude in {:.1f} s of signal (outputs in {})", r.processed_s, args.out));
}

}  // namespace

void add_attitude_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("attitude", "Multi-antenna carrier-phase attitude (roll, pitch, yaw) from N recordings");
  auto args = std::make_shared<AttitudeArgs>();
  cmd->add_option("--input", args->inputs, "IF sample files, one per antenna, master first")
      ->required()
      ->expected(2, 4);
  cmd->add_option("--format", args->format, "sample format: i8, i16, f32, r8, r16")->required();
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--antennas", args->antennas, "TOML file: [[antenna]] lever_arm_body_m (master first), [solver]")
      ->required();
  cmd->add_option("--nav", args->nav, "RINEX navigation file: ephemerides known from the start (hot start)");
  cmd->add_option("--reference-week", args->reference_week, "full GPS week of the recording (without --nav)");
  cmd->add_option("--out", args->out, "output folder (created when missing)")->required();
  cmd->add_option("--duration", args->duration, "seconds of signal to process (default: to the end)");
  cmd->add_option("--interval", args->interval, "attitude epoch interval, s (default 0.1)");
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15 (default all)");
  cmd->add_option("--threads", args->threads, "worker threads including the main one (default: all cores)");
  cmd->add_flag("--quiet", args->quiet, "no progress lines");
  cmd->callback([args] { run_attitude(*args); });
}

}  // namespace ultratrack::tools
