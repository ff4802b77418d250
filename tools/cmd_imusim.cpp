// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack imusim`: a trajectory (named profile or segment file) to DIR/imu.csv (with an IMU error preset),
// DIR/truth.csv (nav columns at the IMU rate), optionally DIR/odometer.csv, and DIR/summary.json.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>

#include "commands.hpp"
#include "ins/imu_csv.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/ins_error.hpp"
#include "ins/nav_csv.hpp"
#include "ins/odometer.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "interrupt_guard.hpp"
#include "io/atomic_file.hpp"
#include "io/units.hpp"
#include "sim/imu_simulation.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;
using ins::InputError;

struct ImuSimOptions {
  std::string profile;
  std::string segments_file;
  double duration_s = 0.0;
  double rate_hz = 100.0;
  std::string preset = "ideal";
  std::uint64_t seed = 1;
  double lat_deg = 36.37, lon_deg = 127.36, height_m = 100.0;
  double speed_mps = 0.0, heading_deg = 0.0;
  bool odometer = false;
  double odometer_sf = 0.0;
  std::string out_dir;
};

void run_imusim(const ImuSimOptions& o) {
  if (o.profile.empty() == o.segments_file.empty())
    throw InputError("command line", "give exactly one of --profile NAME and --segments FILE");
  if (!(o.rate_hz >= 50.0 && o.rate_hz <= 1000.0)) throw InputError("command line", "--rate must be within 50-1000 Hz");
  if (std::fabs(o.lat_deg) >= 89.0) throw InputError("command line", "--lat-deg must be within +-89 deg");
  ins::TrajectorySpec spec;
  if (!o.profile.empty()) {
    if (!(o.duration_s > 0.0)) throw InputError("command line", "--duration must be positive");
    spec =
        ins::profile_spec(o.profile, o.duration_s, o.lat_deg * io::kRadPerDeg, o.lon_deg * io::kRadPerDeg, o.height_m);
  } else {
    ins::TrajectorySpec start;
    start.lat0_rad = o.lat_deg * io::kRadPerDeg;
    start.lon0_rad = o.lon_deg * io::kRadPerDeg;
    start.height0_m = o.height_m;
    start.speed0_mps = o.speed_mps;
    start.heading0_rad = o.heading_deg * io::kRadPerDeg;
    spec = ins::read_segments_csv(o.segments_file, start);
    if (o.duration_s > 0.0) throw InputError("command line", "--duration is the segment file's own with --segments");
  }
  const ins::ImuErrorSpec error_spec = ins::imu_preset(o.preset);

  InterruptGuard interrupt;  // Ctrl-C ends the run; imu.csv and truth.csv hold the trajectory so far
  fs::create_directories(o.out_dir);
  ins::NavCsvWriter truth_out(fs::path(o.out_dir) / "truth.csv");
  ins::ImuCsvWriter imu_out(fs::path(o.out_dir) / "imu.csv");
  std::vector<ins::TruthSample> truth_for_odometer;
  sim::ImuSimulationCallbacks callbacks;
  callbacks.on_imu = [&](const ins::ImuIncrement& inc) { imu_out.write(inc); };
  callbacks.on_truth = [&](const ins::TruthSample& t) {
    truth_out.write(t.nav());
    if (o.odometer) truth_for_odometer.push_back(t);
  };
  callbacks.on_progress = [](int percent) { fmt::print(stderr, "imusim: IMU {}%\n", percent); };
  const sim::ImuSimulationResult r =
      sim::simulate_imu(spec, o.rate_hz, error_spec, o.seed, callbacks, interrupt.token());
  imu_out.commit();
  truth_out.commit();
  if (o.odometer) {
    ins::OdometerOptions odometer;
    odometer.scale_factor_error = o.odometer_sf;
    sim::write_odometer_csv(fs::path(o.out_dir) / "odometer.csv", ins::simulate_odometer(truth_for_odometer, odometer));
  }
  const std::size_t rows = r.imu_rows;
  std::string json = "{\n";
  json += fmt::format("  \"trajectory\": \"{}\",\n  \"duration_s\": {},\n  \"imu_rate_hz\": {},\n  \"imu_rows\": {},\n",
                      o.profile.empty() ? o.segments_file : o.profile, spec.duration_s(), o.rate_hz, rows);
  json +=
      fmt::format("  \"preset\": \"{}\",\n  \"seed\": {},\n  \"interrupted\": {},\n", o.preset, o.seed, r.interrupted);
  json += sim::turn_on_bias_json(r.turn_on);
  json += fmt::format("  \"distance_m\": {:.3f}\n}}\n", r.distance_m);
  io::AtomicFile summary(fs::path(o.out_dir) / "summary.json");
  summary.write(json);
  summary.commit();
  fmt::print("imusim: {} IMU rows at {} Hz ({} s, preset {}, seed {}{}); wrote {}/imu.csv, truth.csv{}\n", rows,
             o.rate_hz, spec.duration_s(), o.preset, o.seed, r.interrupted ? ", interrupted" : "", o.out_dir,
             o.odometer ? ", odometer.csv" : "");
}

}  // namespace

void add_imusim_command(CLI::App& app) {
  auto o = std::make_shared<ImuSimOptions>();
  auto* cmd =
      app.add_subcommand("imusim", "Simulate a trajectory: truth.csv and imu.csv (exact increments + error preset)");
  cmd->add_option("--profile", o->profile, "static, straight, circle, s, spiral or land");
  cmd->add_option("--segments", o->segments_file,
                  "segment CSV: duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg")
      ->check(CLI::ExistingFile);
  cmd->add_option("--duration", o->duration_s, "seconds (profiles)");
  cmd->add_option("--rate", o->rate_hz, "IMU rate in Hz (50-1000, default 100)");
  cmd->add_option(
      "--preset", o->preset,
      "IMU errors: ideal, hg1700ae, dmu6x, navigation, mems, adis16405, adis16465, bmi088, stim300 (default ideal)");
  cmd->add_option("--seed", o->seed, "random seed of the IMU errors (default 1)");
  cmd->add_option("--lat-deg", o->lat_deg, "start latitude (default 36.37)");
  cmd->add_option("--lon-deg", o->lon_deg, "start longitude (default 127.36)");
  cmd->add_option("--height-m", o->height_m, "start ellipsoidal height (default 100)");
  cmd->add_option("--speed-mps", o->speed_mps, "start speed (segments only)");
  cmd->add_option("--heading-deg", o->heading_deg, "start heading (segments only)");
  cmd->add_flag("--odometer", o->odometer, "also write odometer.csv (10 Hz pulses, 2 cm per pulse)");
  cmd->add_option("--odometer-sf", o->odometer_sf, "odometer scale-factor error (ratio, default 0)");
  cmd->add_option("--out", o->out_dir, "output folder")->required();
  cmd->callback([o] { run_imusim(*o); });
}

}  // namespace ultratrack::tools
