// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive`: the receiver end to end on a recording (pipelines/receive_file.hpp), writing solution.csv,
// NMEA, KML, RINEX 3.04 obs + nav, tracking.csv and summary.json into --out, and the coupling's logs.
// Options: command-line flags over --config (TOML, config/receive_config_toml.hpp) over the defaults; the coupling's in
// tools/receive_fusion_options.hpp. A progress bar on a terminal, plain lines otherwise.
// Exit: 0 with a fix; 2 (InputError) for bad input, including a file in which no satellite is found (no
// outputs then); 3 when satellites were tracked but the file ended before a fix (outputs written, summary
// says "fix": false). SIGINT stops the loop and still finishes every output.
// --coupling vector: one vector filter closes the channels' code loops: vector.csv, vector_state.csv.
// --imu F --coupling loose|tight: GNSS/INS integration on the way: nav.csv and a "fusion" object in summary.json;
// exit 3 also when the integration never started, 0 with a fused solution but no PVT fix.
// --imu F --coupling ultra-tight: tight pull-in, then the ultra-tight loop drives the channels: ultratight.csv and
// an "ultratight" object in summary.json.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <memory>
#include <string>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "config/receive_config_toml.hpp"
#include "format_options.hpp"
#include "interrupt_guard.hpp"
#include "io/why_invalid.hpp"
#include "pipelines/receive_file.hpp"
#include "receive_fusion_options.hpp"
#include "receive_progress.hpp"
#include "receiver/sample_source.hpp"
#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::tools {

namespace {

struct ReceiveArgs {
  std::string input, fs, if_hz = "0", config, nav, nav_bits, oscillator, out;
  std::string elevation_mask, troposphere, ionosphere, channels, prns, duration, skip, reference_week, threads;
  FormatArgs format;
  ReceiveFusionArgs fusion;
  bool iq_swap = false, q_negate = false, quiet = false;
};

void run_receive(const ReceiveArgs& args) {
  pipelines::ReceiveFileJob job;
  job.input = args.input;
  job.out = args.out;
  job.format = parse_format(args.format);
  receiver::SampleSourceOptions& source = job.source;
  source.two_bit = parse_two_bit_layout(args.format);
  source.fs_hz = parse_double_option("--fs", args.fs);
  source.if_hz = parse_double_option("--if", args.if_hz);
  source.iq_swap = args.iq_swap;
  source.q_negate = args.q_negate;
  const double skip_s = args.skip.empty() ? 0.0 : parse_double_option("--skip", args.skip);
  if (skip_s < 0.0) throw signals::InputError("command line", "--skip: must not be negative");
  source.start_sample = std::llround(skip_s * source.fs_hz);

  receiver::ReceiverOptions& options = job.options.receiver;
  options.fs_hz = source.fs_hz;
  if (!args.config.empty()) config::apply_receive_config(args.config, options);
  if (!args.elevation_mask.empty())
    options.pvt.elevation_mask_rad = parse_double_option("--elevation-mask-deg", args.elevation_mask) * M_PI / 180.0;
  if (!args.troposphere.empty())
    options.pvt.troposphere = parse_on_off_option("--troposphere", args.troposphere, "on", "off");
  if (!args.ionosphere.empty())
    options.pvt.ionosphere = parse_on_off_option("--ionosphere", args.ionosphere, "broadcast", "off");
  if (!args.channels.empty()) options.channels = parse_int_option("--channels", args.channels);
  if (!args.threads.empty()) options.threads = parse_int_option("--threads", args.threads);
  if (!args.nav_bits.empty())
    options.nav_bits = receiver::parse_nav_bit_source("command line: --nav-bits", args.nav_bits);
  if (!args.oscillator.empty() && !receiver::set_tracking_oscillator(options.tracking, args.oscillator))
    throw signals::InputError("command line",
                              "--oscillator: must be tcxo, ocxo or ideal, not '" + args.oscillator + "'");
  if (!args.prns.empty()) options.prns = parse_prn_list_option("--prn", args.prns);
  if (!args.nav.empty()) job.navigation = signals::read_rinex_nav(args.nav);
  if (!args.reference_week.empty()) {
    options.reference_week = parse_int_option("--reference-week", args.reference_week);
    options.reference_week_is_signal_week = true;
  }
  pipelines::date_recording(options, job.navigation, build_gps_week());
  job.duration_s = args.duration.empty() ? 0.0 : parse_double_option("--duration", args.duration);
  if (job.duration_s < 0.0) throw signals::InputError("command line", "--duration: must not be negative");
  if (args.out.empty()) throw signals::InputError("command line", "--out: an output folder is required");
  if (const std::string why = io::why_invalid(options); !why.empty())
    throw signals::InputError(args.config.empty() ? "command line" : args.config, why);
  apply_receive_coupling_args(args.fusion, job.options);
  if (std::string why; !job.options.IsValid(&why)) throw signals::InputError("command line", why);
  const bool fused = pipelines::uses_imu(job.options.coupling);
  if (fused) {
    job.imu = read_receive_imu(args.fusion.imu, {job.options.navigation.imu_max_gap_s});
    put_receive_imu_on_pps(args.fusion, job.imu, job.options);
  }

  ReceiveProgress progress(args.quiet);
  InterruptGuard interrupt;  // Ctrl-C ends the loop; every output is still finished
  const pipelines::ReceiveFileResult result = pipelines::receive_file(
      std::move(job), interrupt.token(), [&](const pipelines::ReceiveProgressEvent& e) { progress.update(e); });
  const pipelines::ReceiveSummary& summary = result.summary;
  const double wall_s = result.wall_s;
  const double t = summary.processed_s;
  fmt::print("receive: {:.1f} s of signal in {:.2f} s ({:.1f}x real time, {} threads){}\n", t, wall_s,
             wall_s > 0 ? t / wall_s : 0.0, summary.threads, summary.interrupted ? ", interrupted" : "");
  fmt::print("receive: satellites locked {}, used {}; fixes {}; ephemerides decoded {}\n", summary.satellites_tracked,
             summary.satellites_used, summary.fixes, summary.ephemerides_decoded);
  for (const std::string& line : summary.report) fmt::print("{}\n", line);
  if (fused && !summary.navigation_started)
    throw CommandExit(3, fmt::format("{}: no fused solution ({}); outputs up to the end are in {}", args.input,
                                     summary.navigation_not_started, args.out));
  if (summary.fixes == 0 && !(fused && summary.navigation_started))
    throw CommandExit(
        3, fmt::format("{}: no position fix in {:.1f} s of signal ({} satellites locked, {} ephemerides decoded; a "
                       "fix needs {}; for a shorter recording use `snapshot`); outputs up to the end are in {}",
                       args.input, t, summary.satellites_tracked, summary.ephemerides_decoded,
                       args.nav.empty() ? "about 30 s of signal to decode the ephemerides, or 6-10 s with --nav"
                                        : "6-10 s of signal with --nav (the time of week from the signal)",
                       args.out));
  if (summary.fixes == 0) return;  // a fused solution without any PVT fix (tight coupling)
  fmt::print("receive: first fix after {:.2f} s; mean position {:.7f} deg, {:.7f} deg, {:.2f} m; outputs in {}\n",
             summary.ttff_s, summary.mean_lat_deg, summary.mean_lon_deg, summary.mean_height_m, args.out);
}

}  // namespace

void add_receive_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("receive", "Receive a recording: acquisition, tracking, decoding, observables, PVT");
  auto args = std::make_shared<ReceiveArgs>();
  cmd->add_option("--input", args->input, "IF sample file")->required();
  add_format_options(cmd, args->format);
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--out", args->out, "output folder (created when missing)")->required();
  cmd->add_option("--config", args->config, "TOML file with [receiver], [acquisition], [tracking], [pvt] settings");
  cmd->add_option("--nav", args->nav, "RINEX navigation file: ephemerides known from the start (hot start)");
  cmd->add_option("--nav-bits", args->nav_bits,
                  "decoded|oracle: bits for data wipe-off (default decoded: from the signal; oracle: --nav re-encoded "
                  "as `simulate` does, for simulation studies)");
  cmd->add_option("--oscillator", args->oscillator,
                  "tcxo|ocxo|ideal: the front end's oscillator class for the tracking loops (default tcxo; ideal: a "
                  "perfect clock, e.g. a simulated file without clock noise)");
  cmd->add_option("--elevation-mask-deg", args->elevation_mask, "PVT elevation mask, degrees (default 10)");
  cmd->add_option("--troposphere", args->troposphere, "on|off (default on)");
  cmd->add_option(
      "--ionosphere", args->ionosphere,
      "broadcast|off (default broadcast: a default Klobuchar set until the nav file's or the broadcast one is known)");
  cmd->add_option("--channels", args->channels, "tracking channels (default 12)");
  cmd->add_option("--threads", args->threads, "worker threads including the main one (default: all cores)");
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15 (default all)");
  cmd->add_option("--duration", args->duration, "seconds of signal to process (default: to the end)");
  cmd->add_option("--skip", args->skip, "seconds of signal to skip at the start");
  cmd->add_option("--reference-week", args->reference_week,
                  "full GPS week near the recording, for the 10-bit week (default: nav file or build date)");
  cmd->add_flag("--iq-swap", args->iq_swap, "exchange I and Q (complex formats)");
  cmd->add_flag("--q-negate", args->q_negate, "negate Q (complex) / invert the spectrum (real IF)");
  add_receive_fusion_options(cmd, args->fusion);
  cmd->add_flag("--quiet", args->quiet, "no progress display");
  cmd->callback([args] { run_receive(*args); });
}

}  // namespace ultratrack::tools
