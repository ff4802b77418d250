// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack ins`: free inertial navigation from an IMU CSV file, started from a given state (first row of a
// truth/nav CSV) or from a coarse alignment over the first seconds of stationary data. Writes DIR/nav.csv
// and DIR/summary.json; when the --init file is a whole truth trajectory, the summary compares against it.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "ins/attitude.hpp"
#include "ins/coarse_alignment.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "ins/ins_error.hpp"
#include "ins/nav_csv.hpp"
#include "ins/strapdown.hpp"
#include "interrupt_guard.hpp"
#include "io/atomic_file.hpp"
#include "io/units.hpp"
#include "sim/truth_csv.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;
using ins::InputError;

struct InsOptions {
  std::string imu_file;
  std::string init_file;
  double align_s = 0.0;
  std::vector<double> position;  // lat_deg, lon_deg, height_m (with --align and no --init)
  std::string out_dir;
  bool aid_height = false;
  int decimate = 1;
};

// Largest errors of the navigation against truth rows at the same times.
struct TruthComparison {
  int matched = 0;
  double max_horizontal_m = 0.0, max_vertical_m = 0.0, max_velocity_mps = 0.0, max_attitude_deg = 0.0;
  double final_horizontal_m = 0.0, final_vertical_m = 0.0, final_attitude_deg = 0.0;
};

void compare(const ins::NavState& nav, const ins::NavState& truth, TruthComparison& c) {
  const Eigen::Vector3d d_e = ins::ecef_from_geodetic(nav.lat_rad, nav.lon_rad, nav.height_m) -
                              ins::ecef_from_geodetic(truth.lat_rad, truth.lon_rad, truth.height_m);
  const Eigen::Vector3d d_n = ins::C_en(truth.lat_rad, truth.lon_rad).transpose() * d_e;
  c.final_horizontal_m = d_n.head<2>().norm();
  c.final_vertical_m = std::fabs(d_n.z());
  c.final_attitude_deg = ins::attitude_error_n(nav.q_nb, truth.q_nb).norm() / io::kRadPerDeg;
  c.max_horizontal_m = std::max(c.max_horizontal_m, c.final_horizontal_m);
  c.max_vertical_m = std::max(c.max_vertical_m, c.final_vertical_m);
  c.max_attitude_deg = std::max(c.max_attitude_deg, c.final_attitude_deg);
  c.max_velocity_mps = std::max(c.max_velocity_mps, (nav.v_n - truth.v_n).norm());
  ++c.matched;
}

std::string state_json(const ins::NavState& s) {
  const ins::EulerAngles e = ins::euler_from_quaternion(s.q_nb);
  return fmt::format(
      "{{\"t_s\": {}, \"lat_deg\": {:.10f}, \"lon_deg\": {:.10f}, \"height_m\": {:.4f}, \"vel_n_mps\": {:.6f}, "
      "\"vel_e_mps\": {:.6f}, \"vel_d_mps\": {:.6f}, \"roll_deg\": {:.6f}, \"pitch_deg\": {:.6f}, \"yaw_deg\": "
      "{:.6f}}}",
      s.t_s, s.lat_rad / io::kRadPerDeg, s.lon_rad / io::kRadPerDeg, s.height_m, s.v_n.x(), s.v_n.y(), s.v_n.z(),
      e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg, e.yaw_rad / io::kRadPerDeg);
}

void run_ins(const InsOptions& o) {
  if (o.init_file.empty() && o.align_s <= 0.0)
    throw InputError("command line", "give --init FILE (initial state) or --align SECONDS (coarse alignment)");
  if (o.align_s < 0.0) throw InputError("command line", "--align must be positive");
  if (o.decimate < 1) throw InputError("command line", "--decimate must be at least 1");
  const std::vector<ins::ImuIncrement> imu = ins::read_imu_csv(o.imu_file);
  std::vector<ins::NavState> truth;
  if (!o.init_file.empty()) truth = sim::read_truth_csv(o.init_file);

  ins::NavState init;
  std::size_t first = 0;  // first IMU row to navigate with
  std::optional<ins::AlignmentResult> alignment;
  if (!truth.empty()) {
    init = truth.front();
  } else {
    if (o.position.size() != 3)
      throw InputError("command line", "--align without --init needs --position LAT_DEG LON_DEG HEIGHT_M");
    init.lat_rad = o.position[0] * io::kRadPerDeg;
    init.lon_rad = o.position[1] * io::kRadPerDeg;
    init.height_m = o.position[2];
    // the first row's interval is taken to be as long as the second's
    init.t_s = imu.size() > 1 ? imu[0].t_s - (imu[1].t_s - imu[0].t_s) : imu[0].t_s - 0.01;
  }
  while (first < imu.size() && imu[first].t_s <= init.t_s) ++first;
  if (first == imu.size())
    throw InputError(o.imu_file, "no IMU rows after the initial time " + fmt::format("{}", init.t_s));

  if (o.align_s > 0.0) {
    std::size_t end = first;
    while (end < imu.size() && imu[end].t_s <= init.t_s + o.align_s + 1e-9) ++end;
    if (end - first < 2)
      throw InputError(o.imu_file, fmt::format("fewer than 2 IMU rows in the {} s alignment span", o.align_s));
    alignment = ins::coarse_align(std::span(imu).subspan(first, end - first), init.t_s, init.lat_rad);
    init.q_nb = alignment->q_nb;
    init.v_n.setZero();
    init.t_s = imu[end - 1].t_s;
    first = end;
  }

  InterruptGuard interrupt;  // Ctrl-C ends the run; nav.csv and summary.json cover it so far (no .partial left)
  fs::create_directories(o.out_dir);
  ins::Strapdown nav(init);
  if (o.aid_height) nav.set_height_aiding(init.height_m);
  ins::NavCsvWriter writer(fs::path(o.out_dir) / "nav.csv");
  writer.write(nav.state());
  TruthComparison cmp;
  std::size_t ti = 0;
  auto match_truth = [&] {
    const double t = nav.state().t_s;
    while (ti < truth.size() && truth[ti].t_s < t - 1e-6) ++ti;
    if (ti < truth.size() && std::fabs(truth[ti].t_s - t) <= 1e-6) compare(nav.state(), truth[ti], cmp);
  };
  if (truth.size() > 1) match_truth();
  const double nominal_dt = imu.size() > first + 1 ? imu[first + 1].t_s - imu[first].t_s : 0.0;
  const auto t_start = std::chrono::steady_clock::now();
  std::size_t steps = 0;
  for (std::size_t k = first; k < imu.size() && !interrupt.interrupted(); ++k) {
    const double dt = imu[k].t_s - nav.state().t_s;
    if (nominal_dt > 0.0 && dt > 3.0 * nominal_dt) nav.reset_history();  // data gap: no coning history across it
    nav.step(imu[k]);
    ++steps;
    if ((k - first + 1) % static_cast<std::size_t>(o.decimate) == 0 || k + 1 == imu.size()) writer.write(nav.state());
    if (truth.size() > 1) match_truth();
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  writer.commit();

  std::string json = "{\n";
  json +=
      fmt::format("  \"imu_file\": \"{}\",\n  \"imu_rows\": {},\n  \"steps\": {},\n", o.imu_file, imu.size(), steps);
  json += fmt::format("  \"mode\": \"{}\",\n  \"height_aiding\": {},\n", alignment ? "align" : "init", o.aid_height);
  if (alignment) {
    json += fmt::format(
        "  \"alignment\": {{\"duration_s\": {}, \"roll_deg\": {:.6f}, \"pitch_deg\": {:.6f}, \"yaw_deg\": {:.6f}}},\n",
        alignment->duration_s, alignment->euler.roll_rad / io::kRadPerDeg, alignment->euler.pitch_rad / io::kRadPerDeg,
        alignment->euler.yaw_rad / io::kRadPerDeg);
  }
  json += "  \"initial\": " + state_json(init) + ",\n";
  json += "  \"final\": " + state_json(nav.state()) + ",\n";
  if (cmp.matched > 0) {
    json += fmt::format(
        "  \"truth_comparison\": {{\"rows_matched\": {}, \"max_horizontal_error_m\": {:.6g}, \"max_vertical_error_m\": "
        "{:.6g}, "
        "\"max_velocity_error_mps\": {:.6g}, \"max_attitude_error_deg\": {:.6g}, \"final_horizontal_error_m\": {:.6g}, "
        "\"final_vertical_error_m\": {:.6g}, \"final_attitude_error_deg\": {:.6g}}},\n",
        cmp.matched, cmp.max_horizontal_m, cmp.max_vertical_m, cmp.max_velocity_mps, cmp.max_attitude_deg,
        cmp.final_horizontal_m, cmp.final_vertical_m, cmp.final_attitude_deg);
  }
  if (interrupt.interrupted()) json += "  \"interrupted\": true,\n";
  json += fmt::format("  \"steps_per_second\": {:.0f}\n}}\n", wall_s > 0 ? steps / wall_s : 0.0);
  io::AtomicFile summary(fs::path(o.out_dir) / "summary.json");
  summary.write(json);
  summary.commit();

  const ins::EulerAngles e = ins::euler_from_quaternion(nav.state().q_nb);
  fmt::print("ins: {} steps from t = {:.3f} s to {:.3f} s ({})\n", steps, init.t_s, nav.state().t_s,
             alignment
                 ? fmt::format("aligned over {:.1f} s: roll {:.4f} pitch {:.4f} yaw {:.4f} deg", alignment->duration_s,
                               alignment->euler.roll_rad / io::kRadPerDeg, alignment->euler.pitch_rad / io::kRadPerDeg,
                               alignment->euler.yaw_rad / io::kRadPerDeg)
                 : "initial state from " + o.init_file);
  fmt::print("ins: final lat {:.8f} lon {:.8f} deg, h {:.2f} m, attitude {:.4f} {:.4f} {:.4f} deg\n",
             nav.state().lat_rad / io::kRadPerDeg, nav.state().lon_rad / io::kRadPerDeg, nav.state().height_m,
             e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg, e.yaw_rad / io::kRadPerDeg);
  if (cmp.matched > 0)
    fmt::print("ins: against truth ({} rows): max horizontal {:.3f} m, vertical {:.3f} m, attitude {:.2e} deg\n",
               cmp.matched, cmp.max_horizontal_m, cmp.max_vertical_m, cmp.max_attitude_deg);
  fmt::print("ins: wrote {}/nav.csv and summary.json\n", o.out_dir);
}

}  // namespace

void add_ins_command(CLI::App& app) {
  auto opts = std::make_shared<InsOptions>();
  auto* cmd = app.add_subcommand("ins", "Free inertial navigation from IMU increments (strapdown, WGS-84 NED)");
  cmd->add_option("--imu", opts->imu_file, "IMU CSV (t_s,dtheta_x_rad,...,dv_z_mps)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--init", opts->init_file,
                  "truth/nav CSV (or simulate's truth.csv): first row is the initial state; later rows are compared")
      ->check(CLI::ExistingFile);
  cmd->add_option("--align", opts->align_s, "coarse alignment over the first SECONDS of stationary data");
  cmd->add_option("--position", opts->position, "LAT_DEG LON_DEG HEIGHT_M (with --align and no --init)")->expected(3);
  cmd->add_flag("--aid-height", opts->aid_height, "hold the vertical channel at the initial height");
  cmd->add_option("--decimate", opts->decimate, "write every Nth navigation state (default 1)");
  cmd->add_option("--out", opts->out_dir, "output folder")->required();
  cmd->callback([opts] { run_ins(*opts); });
}

}  // namespace ultratrack::tools
