// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack snapshot`: a position from a short recording (tens to hundreds of ms) with broadcast ephemerides and
// an approximate time: acquisition and fine code/Doppler of every satellite (receiver/snapshot_measurement.hpp),
// then coarse-time navigation (receiver/snapshot_navigation.hpp), run by pipelines/snapshot_file.hpp. Writes
// DIR/snapshot.json and DIR/solution.csv (one row, the receive command's columns).
// Exit: 0 fix; 2 bad input or no satellite detected (nothing written); 3 no fix (snapshot.json says why).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <GeographicLib/Geocentric.hpp>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "format_options.hpp"
#include "interrupt_guard.hpp"
#include "io/units.hpp"
#include "io/why_invalid.hpp"
#include "pipelines/snapshot_file.hpp"
#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::tools {

namespace {

struct SnapshotArgs {
  std::string input, fs, if_hz = "0", nav, time, time_sigma = "10", approx_llh, ms = "100", out;
  std::string prns = "1-32", doppler_max = "5000", pfa = "1e-3", skip = "0", spacing = "0.5";
  FormatArgs format;
  bool iq_swap = false, q_negate = false, quiet = false;
};

// "WEEK:TOW" -> GpsTime (full week, TOW in [0, 604800)).
signals::GpsTime parse_time(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw signals::InputError("command line", "--time: expected WEEK:TOW (e.g. 2190:518403.5), got '" + text + "'");
  const int week = parse_int_option("--time (week)", text.substr(0, colon));
  const double tow = parse_double_option("--time (tow)", text.substr(colon + 1));
  if (week < 0 || !(tow >= 0.0 && tow < 604800.0))
    throw signals::InputError("command line", "--time: week must be >= 0 and TOW in [0, 604800)");
  return signals::GpsTime{week, tow};
}

// "LAT,LON,H" (degrees, degrees, metres) -> ECEF.
Eigen::Vector3d parse_llh(const std::string& text) {
  std::vector<double> v;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    v.push_back(parse_double_option("--approx-llh", text.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 3 || std::fabs(v[0]) > 90.0 || std::fabs(v[1]) > 360.0)
    throw signals::InputError("command line",
                              "--approx-llh: expected LAT,LON,H in degrees and metres, got '" + text + "'");
  double x = 0, y = 0, z = 0;
  GeographicLib::Geocentric::WGS84().Forward(v[0], v[1], v[2], x, y, z);
  return {x, y, z};
}

void run_snapshot(const SnapshotArgs& args) {
  const auto started = std::chrono::steady_clock::now();
  pipelines::SnapshotFileJob job;
  job.input = args.input;
  job.format = parse_format(args.format);
  job.source = parse_sample_source_options(args.format, args.fs, args.if_hz, args.iq_swap, args.q_negate);
  const double skip_s = parse_double_option("--skip", args.skip);
  if (!(skip_s >= 0.0)) throw signals::InputError("command line", "--skip must be >= 0");
  job.source.start_sample = std::llround(skip_s * job.source.fs_hz);
  job.approximate_time = parse_time(args.time);
  job.navigation.time_sigma_s = parse_double_option("--time-sigma-s", args.time_sigma);
  if (!args.approx_llh.empty()) job.approximate_position_e_m = parse_llh(args.approx_llh);
  job.snapshot_ms = parse_double_option("--ms", args.ms);
  if (!(job.snapshot_ms >= 2.0 && job.snapshot_ms <= 10000.0))
    throw signals::InputError("command line", "--ms must be in [2, 10000]");
  job.search.fs_hz = job.source.fs_hz;
  job.search.doppler_max_hz = parse_double_option("--doppler-max", args.doppler_max);
  job.search.pfa = parse_double_option("--pfa", args.pfa);
  job.search.spacing_chips = parse_double_option("--spacing-chips", args.spacing);
  job.prns = parse_prn_list_option("--prn", args.prns);
  std::string why;
  if (!job.search.IsValid(&why)) throw signals::InputError("command line", why);
  if (why = io::why_invalid(job.navigation); !why.empty()) throw signals::InputError("command line", why);
  job.nav = signals::read_rinex_nav(args.nav);
  if (job.nav.ephemerides.empty()) throw signals::InputError(args.nav, "holds no GPS ephemeris");

  const pipelines::SnapshotFileResult result = pipelines::snapshot_file(job);
  if (result.shortened)
    fmt::print(stderr, "ultratrack snapshot: {} holds {:.1f} ms; using all of it instead of {:g} ms\n", args.input,
               result.used_ms, job.snapshot_ms);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  // The search runs in memory: a signal before here ends the program with nothing written; from here it waits
  // until both files are complete (the exit status then says the run was stopped).
  const InterruptGuard writing;
  pipelines::write_snapshot_outputs(args.out, job, result, args.format.format, wall_s);
  const receiver::SnapshotSolution& solution = result.solution;
  if (!solution.valid) throw CommandExit(3, "snapshot: no fix: " + solution.failure);
  if (args.quiet) return;
  fmt::print("{} satellites detected, {} used; ", result.detections.size(), solution.used);
  fmt::print("fix {:.7f} {:.7f} {:.1f} m, time correction {:+.3f} s, quality {} (residual rms {:.1f} m)\n",
             solution.lat_rad * io::kDegPerRad, solution.lon_rad * io::kDegPerRad, solution.height_m,
             solution.time_correction_s, solution.quality, solution.residual_rms_m);
}

}  // namespace

void add_snapshot_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "snapshot", "Position from a short recording (coarse-time navigation: ephemerides + approximate time)");
  auto args = std::make_shared<SnapshotArgs>();
  cmd->add_option("--input", args->input, "IF sample file")->required();
  add_format_options(cmd, args->format);
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--nav", args->nav, "RINEX navigation file (broadcast ephemerides)")->required();
  cmd->add_option("--time", args->time, "approximate GPS time of the snapshot's first sample, WEEK:TOW")->required();
  cmd->add_option("--time-sigma-s", args->time_sigma, "1-sigma of --time, s (solutions beyond 3 sigma are refused)")
      ->capture_default_str();
  cmd->add_option("--approx-llh", args->approx_llh,
                  "approximate position LAT,LON,H (deg, deg, m); without it a Doppler fix and a grid search");
  cmd->add_option("--ms", args->ms, "snapshot length, ms (the file's length when shorter)")->capture_default_str();
  cmd->add_option("--skip", args->skip, "seconds of the file to skip before the snapshot")->capture_default_str();
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15")->capture_default_str();
  cmd->add_option("--doppler-max", args->doppler_max, "Doppler search range +-, Hz")->capture_default_str();
  cmd->add_option("--pfa", args->pfa, "false-alarm probability per PRN")->capture_default_str();
  cmd->add_option("--spacing-chips", args->spacing, "early-late spacing of the fine code phase, chips (0, 1.5]")
      ->capture_default_str();
  cmd->add_flag("--iq-swap", args->iq_swap, "exchange I and Q (complex formats)");
  cmd->add_flag("--q-negate", args->q_negate, "negate Q (complex) / invert the spectrum (real IF)");
  cmd->add_option("--out", args->out, "output folder (snapshot.json, solution.csv)")->required();
  cmd->add_flag("--quiet", args->quiet, "no summary line on stdout");
  cmd->callback([args] { run_snapshot(*args); });
}

}  // namespace ultratrack::tools
