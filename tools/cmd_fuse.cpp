// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack fuse`: loosely coupled GNSS/INS from an IMU CSV and a GNSS fix CSV (EKF or UKF, closed loop),
// after a static, in-motion or configured alignment. Writes DIR/nav.csv (nav columns + 1-sigma) and
// DIR/summary.json (update counts, convergence, RMS against --truth); progress and a summary on stdout.
// --attitude adds a multi-antenna receiver's GPS attitude (attitude.csv) as a measurement ([OhAttINS]);
// --odometer an odometer's pulses (odometer.csv) as VMS/non-holonomic updates ([KimVMS]), with or without --gnss.
// --imu-pps puts IMU stamps of a free-running local clock on GPS time through a PPS record ([OhAttINS],
// pipelines/pps_time_sync.hpp) before anything uses them: t_s = GPS time - the --attitude-origin (or the first edge).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "config/fuse_config_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/odometer_csv.hpp"
#include "interrupt_guard.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "pipelines/alignment_run.hpp"
#include "pipelines/fuse.hpp"
#include "pipelines/fuse_summary.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "pipelines/pps_time_sync.hpp"
#include "sim/truth_csv.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;
using pipelines::AlignMode;

struct FuseCommandOptions {
  std::string imu_file, gnss_file, truth_file, config_file, out_dir, attitude_file, odometer_file, pps_file;
  std::optional<double> gnss_until_s;
  std::vector<double> attitude_origin;  // WEEK TOW
  std::string coupling = "loose", filter = "ekf", align = "motion";
  std::vector<double> outage;  // START DURATION pairs
  int decimate = 1;
  bool quiet = false;
};

void run_fuse_command(const FuseCommandOptions& o) {
  if (o.coupling != "loose")
    throw io::InputError("command line", "--coupling " + o.coupling +
                                             ": fuse takes external position/velocity fixes, only 'loose' applies "
                                             "(tight coupling runs from observables: ultratrack receive --imu)");
  pipelines::FuseSettings s;
  s.filter = parse_filter_option(o.filter);
  if (o.align == "static") {
    s.align = AlignMode::Static;
  } else if (o.align == "motion") {
    s.align = AlignMode::Motion;
  } else if (o.align == "config") {
    s.align = AlignMode::Config;
  } else if (o.align == "attitude") {
    s.align = AlignMode::Attitude;
  } else if (o.align.starts_with("file:")) {  // `ultratrack align`'s result, applied after --config below
    s.align = AlignMode::Config;
  } else {
    throw io::InputError(
        "command line",
        "--align must be static, motion, config, attitude or file:ALIGNMENT.json, got '" + o.align + "'");
  }
  if (o.decimate < 1) throw io::InputError("command line", "--decimate must be at least 1");
  if (o.outage.size() % 2 != 0) throw io::InputError("command line", "--outage takes START DURATION pairs");
  for (std::size_t i = 0; i < o.outage.size(); i += 2) {
    if (!(o.outage[i + 1] > 0.0)) throw io::InputError("command line", "--outage duration must be positive");
    s.outages.emplace_back(o.outage[i], o.outage[i + 1]);
  }
  if (!o.config_file.empty()) s.config = config::read_fuse_config(o.config_file);
  if (o.align.starts_with("file:")) pipelines::apply_alignment_file(s.config, o.align.substr(5));
  if (!o.attitude_origin.empty())
    s.config.attitude_gps_time_at_imu_zero = parse_gps_time_option("--attitude-origin", o.attitude_origin);
  if (!o.attitude_file.empty()) {
    s.attitude = pipelines::read_attitude_csv(o.attitude_file);
    s.attitude_file = o.attitude_file;
  }

  if (o.gnss_file.empty() && o.odometer_file.empty())
    throw io::InputError("command line", "fuse needs --gnss, --odometer or both");
  if (!o.odometer_file.empty()) {
    s.odometer = ins::read_odometer_csv(o.odometer_file, {s.config.odometer_rate_hz}).samples;
    s.odometer_file = o.odometer_file;
  }
  s.gnss_until_s = o.gnss_until_s;
  auto imu = ins::read_imu_csv(o.imu_file, {s.config.imu_max_gap_s});
  if (!o.pps_file.empty()) {
    auto mapped =
        pipelines::imu_on_gps_time_by_pps(imu, o.imu_file, o.pps_file, s.config.attitude_gps_time_at_imu_zero);
    s.config.attitude_gps_time_at_imu_zero = mapped.origin;  // without an origin the time line starts at the first edge
    imu = std::move(mapped.imu);
    if (!o.quiet) fmt::print("fuse: {}\n", mapped.note);
  }
  const auto gnss = o.gnss_file.empty() ? std::vector<pipelines::GnssFixRow>{} : pipelines::read_gnss_csv(o.gnss_file);
  std::vector<ins::NavState> truth;
  if (!o.truth_file.empty()) truth = sim::read_truth_csv(o.truth_file);
  if (!o.quiet)
    fmt::print("fuse: {} IMU rows ({:.3f}-{:.3f} s), {} GNSS fixes ({:.3f}-{:.3f} s), loose {}, align {}\n", imu.size(),
               imu.front().t_s, imu.back().t_s, gnss.size(), gnss.empty() ? 0.0 : gnss.front().t_s,
               gnss.empty() ? 0.0 : gnss.back().t_s, o.filter, o.align);

  InterruptGuard interrupt;  // Ctrl-C ends the run early; nav.csv and summary.json cover it so far
  fs::create_directories(o.out_dir);
  pipelines::FusedNavCsvWriter nav(fs::path(o.out_dir) / "nav.csv");
  long long rows = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const pipelines::FuseResult r = [&] {
    try {
      return pipelines::fuse(
          imu, gnss, pipelines::truth_samples_from_nav(truth), s,
          [&](const ins::NavState& state, const pipelines::NavSigma& sigma) {
            if (rows++ % o.decimate == 0) nav.write(state, sigma);
          },
          [&](double fraction) {
            if (!o.quiet) fmt::print("fuse: {:3.0f} %\n", 100.0 * fraction);
          },
          interrupt.token());
    } catch (const pipelines::AlignmentUnavailable& e) {
      throw CommandExit(3, std::string("fuse: no solution: ") + e.what());  // nav.csv is not left behind
    }
  }();
  nav.commit();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  io::write_file_atomically(fs::path(o.out_dir) / "summary.json",
                            pipelines::fuse_summary_json(r, s, o.imu_file, o.gnss_file, o.truth_file));

  const auto& e = r.initial_attitude;
  fmt::print("fuse: aligned {}: roll {:.3f} pitch {:.3f} yaw {:.3f} deg\n", r.alignment_note,
             e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg, e.yaw_rad / io::kRadPerDeg);
  if (r.fix_whiteness) fmt::print("fuse: {}\n", r.fix_whiteness->note);
  if (r.velocity_whiteness && r.velocity_whiteness->measured) fmt::print("fuse: {}\n", r.velocity_whiteness->note);
  fmt::print("fuse: {:.1f} s navigated in {:.2f} s; fixes used {}, updates accepted {}, rejected {}{}\n",
             r.end_s - r.start_s, wall_s, r.fixes_used, r.counters.accepted, r.counters.rejected,
             r.fixes_in_outage ? fmt::format(", {} dropped in outages", r.fixes_in_outage) : std::string());
  fmt::print("fuse: {}; final 1-sigma: horizontal {:.2f} m, vertical {:.2f} m, heading {:.3f} deg\n",
             r.converged_at_s ? fmt::format("converged (heading 1-sigma < {} deg) from {:.1f} s",
                                            s.config.convergence_heading_sigma_deg, *r.converged_at_s)
                              : std::string("NOT converged"),
             r.final_sigma.position_ned_m.head<2>().norm(), r.final_sigma.position_ned_m.z(),
             r.final_sigma.attitude_ned_rad.z() / io::kRadPerDeg);
  if (r.rms_all)
    fmt::print(
        "fuse: against truth: position RMS {:.3f} m (horizontal {:.3f}, vertical {:.3f}), velocity {:.4f} m/s, "
        "attitude {:.4f} deg; GNSS fixes alone {:.3f} m\n",
        r.rms_all->position_3d_m, r.rms_all->horizontal_m, r.rms_all->vertical_m, r.rms_all->velocity_mps,
        r.rms_all->attitude_deg, r.gnss_rms ? r.gnss_rms->position_3d_m : 0.0);
  if (!s.attitude.empty())
    fmt::print(
        "fuse: GPS attitude: {} rows, {} fixed, {} unfixed skipped (fallback); updates accepted {}, rejected "
        "{} (gate) + {} (near vertical); {} fixes without attitude\n",
        r.attitude.rows, r.attitude.fixed_rows, r.attitude.unfixed_skipped, r.counters.attitude_accepted,
        r.counters.attitude_rejected, r.counters.attitude_unusable, r.counters.fixes_without_attitude);
  if (const auto& u = r.odometer) {
    const auto& n = r.counters.odometer;
    fmt::print(
        "fuse: odometer: {} windows, updates accepted {}, rejected {} (gate); gated out by heading rate {}, by "
        "speed {}; scale factor {:.5f} +- {:.5f}, misalignment pitch {:.3f} yaw {:.3f} deg, delay {:.3f} s\n",
        u->windows, n.accepted, n.rejected, n.gated_yaw_rate, n.gated_speed, u->estimate.value.scale_factor,
        u->estimate.sigma.scale_factor, u->estimate.value.pitch_rad / io::kRadPerDeg,
        u->estimate.value.yaw_rad / io::kRadPerDeg, u->estimate.value.delay_s);
    if (u->distance_travelled_m)
      fmt::print(
          "fuse: odometer: since GNSS at {:.1f} s: {:.0f} m travelled, horizontal error max {:.2f} m ({:.3f} % "
          "DT), end {:.2f} m, altitude max {:.2f} m ({:.3f} % DT)\n",
          u->gnss_last_used_s, *u->distance_travelled_m, *u->horizontal_error_max_m,
          100.0 * *u->horizontal_error_max_m / *u->distance_travelled_m, *u->horizontal_error_end_m,
          *u->altitude_error_max_m, 100.0 * *u->altitude_error_max_m / *u->distance_travelled_m);
  }
  for (const auto& oo : r.outages)
    fmt::print("fuse: outage {:.1f}-{:.1f} s: horizontal error at its end {:.3f} m (1-sigma {:.3f} m)\n", oo.start_s,
               oo.end_s, oo.horizontal_error_m, oo.sigma_horizontal_m);
  fmt::print("fuse: wrote {}/nav.csv and summary.json{}\n", o.out_dir, interrupt.interrupted() ? " (interrupted)" : "");
}

}  // namespace

void add_fuse_command(CLI::App& app) {
  auto o = std::make_shared<FuseCommandOptions>();
  auto* cmd = app.add_subcommand("fuse", "Loosely coupled GNSS/INS (EKF or UKF) from IMU and GNSS fix CSV files");
  cmd->add_option("--imu", o->imu_file, "IMU CSV (t_s,dtheta_x_rad,...,dv_z_mps)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option(
         "--gnss", o->gnss_file,
         "GNSS CSV (t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m); "
         "needed unless --odometer")
      ->check(CLI::ExistingFile);
  cmd->add_option("--odometer", o->odometer_file,
                  "odometer CSV (t_s,pulses,distance_m): VMS speed and non-holonomic updates, [odometer] keys")
      ->check(CLI::ExistingFile);
  cmd->add_option("--gnss-until", o->gnss_until_s, "T: use GNSS fixes up to T s only (then odometer only)");
  cmd->add_option("--coupling", o->coupling, "loose (external fixes)");
  cmd->add_option("--filter", o->filter, "ekf or ukf (default ekf)");
  cmd->add_option("--config", o->config_file, "TOML: [imu] [initial] [alignment] [gnss] [filter] [output]")
      ->check(CLI::ExistingFile);
  cmd->add_option("--align", o->align,
                  "static, motion (default), config, attitude (first fixed GPS attitude) or file:ALIGNMENT.json "
                  "(`ultratrack align`)");
  cmd->add_option("--attitude", o->attitude_file,
                  "GPS attitude CSV of `ultratrack attitude` (gps_week,tow_s,roll_deg,...,fixed,ratio): attitude "
                  "updates, unfixed rows skipped")
      ->check(CLI::ExistingFile);
  cmd->add_option("--attitude-origin", o->attitude_origin,
                  "WEEK TOW: GPS time of IMU t = 0 (else [attitude] gps_time_at_imu_zero)")
      ->expected(2);
  cmd->add_option("--imu-pps", o->pps_file,
                  "PPS CSV (local_s,gps_week,gps_tow_s): IMU stamps are a local clock, mapped to GPS time since "
                  "--attitude-origin (else the first PPS edge), the time line of the other files")
      ->check(CLI::ExistingFile);
  cmd->add_option("--truth", o->truth_file, "truth/nav CSV on the IMU time line: RMS errors in summary.json")
      ->check(CLI::ExistingFile);
  cmd->add_option("--outage", o->outage, "START DURATION: drop GNSS fixes in [START, START+DURATION) (repeatable)")
      ->expected(2)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--decimate", o->decimate, "write every Nth solution row (default 1)");
  cmd->add_flag("--quiet", o->quiet, "no progress lines");
  cmd->add_option("--out", o->out_dir, "output folder")->required();
  cmd->callback([o] { run_fuse_command(*o); });
}

}  // namespace ultratrack::tools
