// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack align`: the stationary fine alignment of [KimAlign] from an IMU CSV and a multi-antenna receiver's
// attitude.csv (pipelines/alignment_run.hpp): writes DIR/alignment.json (attitude, 1-sigma, biases, the array's
// mounting estimate, observability rank, warnings) and DIR/alignment.csv (one row per filter epoch). --imu-pps maps
// IMU stamps of a free-running local clock to GPS time through a PPS record ([OhAttINS], pipelines/pps_time_sync.hpp).
// The result starts `fuse` (and `receive --imu`) with --align file:DIR/alignment.json.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "commands.hpp"
#include "config/fuse_config_toml.hpp"
#include "ins/imu_csv.hpp"
#include "interrupt_guard.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "pipelines/alignment_run.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "pipelines/pps_time_sync.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;

struct AlignCommandOptions {
  std::string imu_file, attitude_file, config_file, out_dir, pps_file, filter = "ekf";
  std::vector<double> attitude_origin, position, reference;
  double duration_s = 100.0, interval_s = 1.0;
  bool quiet = false;
};

void run_align_command(const AlignCommandOptions& o) {
  pipelines::AlignSettings s;
  s.filter = parse_filter_option(o.filter);
  if (!(o.duration_s >= 0.0)) throw io::InputError("command line", "--duration must be >= 0 (0: all the data)");
  if (!(o.interval_s > 0.0)) throw io::InputError("command line", "--filter-interval must be positive");
  s.duration_s = o.duration_s;
  s.filter_interval_s = o.interval_s;
  s.imu_file = o.imu_file;
  s.attitude_file = o.attitude_file;
  if (!o.config_file.empty()) s.config = config::read_fuse_config(o.config_file);
  if (!o.position.empty()) {
    if (!(std::abs(o.position[0]) <= 90.0 && std::abs(o.position[1]) <= 360.0) || !std::isfinite(o.position[2]))
      throw io::InputError("command line", "--position takes LAT_DEG LON_DEG HEIGHT_M");
    s.config.position_deg_m = Eigen::Vector3d(o.position[0], o.position[1], o.position[2]);
  }
  if (!o.attitude_origin.empty())
    s.config.attitude_gps_time_at_imu_zero = parse_gps_time_option("--attitude-origin", o.attitude_origin);
  if (!o.reference.empty()) {
    const double d = io::kRadPerDeg;
    const auto& v = o.reference;
    if (!(std::abs(v[0]) <= 180.0 && std::abs(v[1]) < 90.0 && std::abs(v[2]) <= 360.0 && v[3] > 0.0 && v[4] > 0.0 &&
          v[5] > 0.0 && std::isfinite(v[3] + v[4] + v[5])))
      throw io::InputError("command line",
                           "--reference-attitude takes ROLL PITCH YAW and their positive 1-sigmas, deg");
    s.reference_attitude = ins::EulerAngles{v[0] * d, v[1] * d, v[2] * d};
    s.reference_sigma_rad = Eigen::Vector3d(v[3], v[4], v[5]) * d;
  }

  const auto attitude = pipelines::read_attitude_csv(o.attitude_file);
  auto imu = ins::read_imu_csv(o.imu_file, {s.config.imu_max_gap_s});
  if (!o.pps_file.empty()) {
    auto mapped =
        pipelines::imu_on_gps_time_by_pps(imu, o.imu_file, o.pps_file, s.config.attitude_gps_time_at_imu_zero);
    // Without an origin the IMU time line starts at the first PPS edge.
    s.config.attitude_gps_time_at_imu_zero = mapped.origin;
    imu = std::move(mapped.imu);
    s.time_note = mapped.note;
    if (!o.quiet) fmt::print("align: {}\n", s.time_note);
  } else {
    s.time_note = "IMU t_s on the attitude time line by the GPS time origin";
  }
  if (!o.quiet)
    fmt::print("align: {} IMU rows ({:.3f}-{:.3f} s), {} attitude rows, {} filter, {} s\n", imu.size(), imu.front().t_s,
               imu.back().t_s, attitude.size(), o.filter, o.duration_s);

  const pipelines::AlignRunResult r = pipelines::run_alignment(imu, attitude, s);
  // The filter runs in memory: a signal before here ends the program with nothing written; from here it waits
  // until both files are complete (the exit status then says the run was stopped).
  const InterruptGuard writing;
  fs::create_directories(o.out_dir);
  io::write_file_atomically(fs::path(o.out_dir) / "alignment.csv", pipelines::alignment_csv(r));
  io::write_file_atomically(fs::path(o.out_dir) / "alignment.json", pipelines::alignment_json(r, s));

  const auto& a = r.alignment;
  const ins::EulerAngles e = ins::euler_from_quaternion(a.nav.q_nb);
  const double d = io::kRadPerDeg;
  fmt::print(
      "align: {:.1f}-{:.1f} s: roll {:.4f} pitch {:.4f} yaw {:.4f} deg, 1-sigma {:.4f} / {:.4f} / {:.4f} deg; "
      "{} attitude updates ({} rejected), observability rank {}\n",
      a.start_s, a.end_s, e.roll_rad / d, e.pitch_rad / d, e.yaw_rad / d, a.sigma_euler_rad.x() / d,
      a.sigma_euler_rad.y() / d, a.sigma_euler_rad.z() / d, a.attitude_updates, a.attitude_rejected,
      r.observability.rank);
  fmt::print(
      "align: array mounting (GPS mean against {}) roll {:.3f} pitch {:.3f} yaw {:.3f} "
      "deg, 1-sigma {:.3f} / {:.3f} / {:.3f} deg\n",
      s.reference_attitude ? "the reference attitude" : "the IMU's levelling/gyrocompassing",
      r.mounting.angles.roll_rad / d, r.mounting.angles.pitch_rad / d, r.mounting.angles.yaw_rad / d,
      r.mounting.sigma_rad.x() / d, r.mounting.sigma_rad.y() / d, r.mounting.sigma_rad.z() / d);
  for (const auto& w : r.warnings) fmt::print("align: warning: {}\n", w);
  fmt::print("align: wrote {}/alignment.json and alignment.csv\n", o.out_dir);
}

}  // namespace

void add_align_command(CLI::App& app) {
  auto o = std::make_shared<AlignCommandOptions>();
  auto* cmd = app.add_subcommand("align", "Stationary fine alignment from an IMU and GPS attitude ([KimAlign])");
  cmd->add_option("--imu", o->imu_file, "IMU CSV of the vehicle at rest")->required()->check(CLI::ExistingFile);
  cmd->add_option("--attitude", o->attitude_file, "attitude.csv of `ultratrack attitude` (fixed rows used)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--attitude-origin", o->attitude_origin,
                  "WEEK TOW: GPS time of IMU t = 0 (else [attitude] gps_time_at_imu_zero, or the first PPS edge)")
      ->expected(2);
  cmd->add_option("--imu-pps", o->pps_file,
                  "PPS CSV (local_s,gps_week,gps_tow_s): IMU stamps are a local clock, mapped to GPS time")
      ->check(CLI::ExistingFile);
  cmd->add_option("--position", o->position, "LAT_DEG LON_DEG HEIGHT_M (else [initial] position_deg_m)")->expected(3);
  cmd->add_option(
         "--reference-attitude", o->reference,
         "R P Y SR SP SY (deg): the body's attitude from a reference and its 1-sigma, for the mounting estimate "
         "(else the IMU's own levelling and gyrocompassing)")
      ->expected(6);
  cmd->add_option("--duration", o->duration_s,
                  "seconds of alignment from the first GPS attitude (default 100; 0: all)");
  cmd->add_option("--filter-interval", o->interval_s, "seconds between filter updates (default 1)");
  cmd->add_option("--config", o->config_file, "TOML with `fuse`'s keys ([imu] [initial] [attitude] [filter])")
      ->check(CLI::ExistingFile);
  cmd->add_option("--filter", o->filter, "ekf or ukf (default ekf)");
  cmd->add_flag("--quiet", o->quiet, "no progress lines");
  cmd->add_option("--out", o->out_dir, "output folder")->required();
  cmd->callback([o] { run_align_command(*o); });
}

}  // namespace ultratrack::tools
