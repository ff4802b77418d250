// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack gnsssim`: external GNSS fixes (gnss.csv for `ultratrack fuse`) sampled from a truth/nav CSV at
// any rate and start time (e.g. 5 Hz at t = 0.137 + 0.2 k), with seeded Gauss-Markov position errors and white
// velocity errors.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "commands.hpp"
#include "interrupt_guard.hpp"
#include "io/input_error.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "sim/truth_csv.hpp"

namespace ultratrack::tools {
namespace {

struct GnssSimOptions {
  std::string truth_file, out_file;
  double rate_hz = 1.0, first_s = 0.0, correlation_s = 0.0, velocity_sigma_mps = 0.05, velocity_correlation_s = 0.0;
  std::vector<double> sigma_m{1.5, 1.5, 3.0};
  std::vector<double> lever_arm_m{0.0, 0.0, 0.0};
  std::vector<double> white_sigma_m, stated_sigma_m;
  bool no_velocity = false;
  std::uint64_t seed = 1;
};

void run_gnsssim(const GnssSimOptions& o) {
  const auto nav = sim::read_truth_csv(o.truth_file);
  if (nav.size() < 2) throw io::InputError(o.truth_file, "needs at least two rows");
  if (!(o.velocity_sigma_mps > 0.0)) throw io::InputError("command line", "--velocity-sigma must be positive");
  if (o.correlation_s < 0.0) throw io::InputError("command line", "--correlation must not be negative");
  if (o.velocity_correlation_s < 0.0)
    throw io::InputError("command line", "--velocity-correlation must not be negative");
  pipelines::GnssFixSimulationOptions s;
  s.rate_hz = o.rate_hz;
  s.first_time_s = o.first_s;
  s.sigma_ned_m = {o.sigma_m[0], o.sigma_m[1], o.sigma_m[2]};
  s.correlation_time_s = o.correlation_s;
  if (!o.white_sigma_m.empty()) s.white_sigma_ned_m = {o.white_sigma_m[0], o.white_sigma_m[1], o.white_sigma_m[2]};
  if (!o.stated_sigma_m.empty())
    s.stated_sigma_ned_m = Eigen::Vector3d(o.stated_sigma_m[0], o.stated_sigma_m[1], o.stated_sigma_m[2]);
  s.with_velocity = !o.no_velocity;
  s.sigma_velocity_mps = o.velocity_sigma_mps;
  s.velocity_correlation_time_s = o.velocity_correlation_s;
  s.lever_arm_b = {o.lever_arm_m[0], o.lever_arm_m[1], o.lever_arm_m[2]};
  s.seed = o.seed;
  const ins::TruthInterpolator truth(pipelines::truth_samples_from_nav(nav));
  const auto fixes = pipelines::simulate_gnss_fixes(truth, s);
  if (fixes.empty()) throw io::InputError(o.truth_file, "no fix time falls inside the truth span");
  const InterruptGuard writing;  // a signal during the write waits for the whole file (no .partial left)
  pipelines::write_gnss_csv(o.out_file, fixes);
  fmt::print("gnsssim: {} fixes at {} Hz from {:.3f} s to {:.3f} s; wrote {}\n", fixes.size(), o.rate_hz,
             fixes.front().t_s, fixes.back().t_s, o.out_file);
}

}  // namespace

void add_gnsssim_command(CLI::App& app) {
  auto o = std::make_shared<GnssSimOptions>();
  auto* cmd = app.add_subcommand("gnsssim", "GNSS fixes (gnss.csv for fuse) from a truth/nav CSV");
  cmd->add_option("--truth", o->truth_file, "truth.csv of imusim/simulate, or a nav CSV")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--rate", o->rate_hz, "fixes per second (default 1)");
  cmd->add_option("--first", o->first_s, "time of the first fix (default 0)");
  cmd->add_option("--sigma", o->sigma_m, "N E D position 1-sigma in m (default 1.5 1.5 3)")->expected(3);
  cmd->add_option("--correlation", o->correlation_s, "position error correlation time in s (default 0: white)");
  cmd->add_option("--white-sigma", o->white_sigma_m, "N E D white position 1-sigma in m on top (default none)")
      ->expected(3);
  cmd->add_option("--stated-sigma", o->stated_sigma_m,
                  "N E D sigma written in the file (default the true total: a receiver that misstates its accuracy)")
      ->expected(3);
  cmd->add_option("--velocity-sigma", o->velocity_sigma_mps, "velocity 1-sigma in m/s (default 0.05)");
  cmd->add_option("--velocity-correlation", o->velocity_correlation_s,
                  "velocity error correlation time in s (default 0: white; a receiver that smooths its velocities)");
  cmd->add_flag("--no-velocity", o->no_velocity, "leave the velocity columns empty");
  cmd->add_option("--lever-arm", o->lever_arm_m, "antenna in body axes from the IMU, m (x y z)")->expected(3);
  cmd->add_option("--seed", o->seed, "random seed (default 1)");
  cmd->add_option("--out", o->out_file, "output gnss.csv")->required();
  cmd->callback([o] { run_gnsssim(*o); });
}

}  // namespace ultratrack::tools
