// SPDX-License-Identifier: GPL-3.0-or-later
// GNSS/INS from IF samples (loose and tight coupling) end to end through the library: one simulation (a land vehicle on
// a circle of radius 100 m at 30 km/h, HG1700AE IMU at 100 Hz, nominal constellation, 2.0 MHz i8, a few seconds) writes
// the IF samples, imu.csv and truth.csv from ONE trajectory; the receiver starts hot from a RINEX file of the
// scenario's own ephemerides (no ../shared needed). Checked against the simulator's truth: the fused position (nav.csv,
// IMU = antenna here: no lever arm) against the PVT fixes (solution.csv) at the same epochs; tight coupling with only
// three satellites (no PVT fix at all) stays on the truth. Bad IMU input on the command line:
// tests/tools/receive_fusion_cli_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "config/fuse_config_toml.hpp"
#include "config/receive_config_toml.hpp"
#include "config/scenario_toml.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "io/input_error.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/receive_file.hpp"
#include "pipelines/solution_compare.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario_models.hpp"
#include "sim/simulation_files.hpp"
#include "support/fusion_circle_scenario.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

constexpr double kStartTow_s = test::kFusionStartTow_s, kDuration_s = test::kFusionDuration_s;
constexpr double kC = 299792458.0;

struct Sim {
  fs::path dir, sim, nav;
  std::vector<ultratrack::pipelines::TruthPoint> truth;
  std::vector<int> prns_by_elevation;  // highest first
};

Sim& simulated() {
  static Sim s = [] {
    Sim r;
    r.dir = test::scratch_dir();
    r.sim = r.dir / "sim";
    test::write_fusion_circle_scenario(r.dir);
    ultratrack::sim::simulate_to_folder(config::read_scenario(r.dir / "circle.toml"), r.sim, "");
    // The scenario's own broadcast data as a RINEX file: the receiver's hot start.
    const sim::NavigationSource nav = sim::load_navigation(config::read_scenario(r.dir / "circle.toml"));
    signals::RinexNavData data;
    data.ephemerides = nav.ephemerides;
    data.klobuchar = nav.klobuchar;
    data.utc = nav.utc;
    r.nav = r.dir / "nominal.rnx";
    signals::write_rinex_nav_304(r.nav, data);
    r.truth = ultratrack::pipelines::read_simulation_truth_csv(r.sim / "truth.csv");
    std::ifstream sats(r.sim / "satellites.csv");
    std::string line;
    std::getline(sats, line);
    std::vector<std::pair<double, int>> el;
    while (std::getline(sats, line)) {
      std::stringstream ss(line);
      std::string prn, elev;
      std::getline(ss, prn, ',');
      std::getline(ss, elev, ',');
      el.emplace_back(std::stod(elev), std::stoi(prn));
    }
    std::sort(el.rbegin(), el.rend());
    for (const auto& [e, p] : el) r.prns_by_elevation.push_back(p);
    return r;
  }();
  return s;
}

// Truth ECEF position at a true GPS time of week (linear between the 10 Hz rows; the 100 m circle at 8.3 m/s
// bends by 0.35 mm over 0.1 s).
Eigen::Vector3d truth_at(const std::vector<ultratrack::pipelines::TruthPoint>& truth, double tow_s) {
  auto it = std::lower_bound(truth.begin(), truth.end(), tow_s,
                             [](const ultratrack::pipelines::TruthPoint& p, double t) { return p.tow_s < t; });
  if (it == truth.begin()) return it->r_e_m;
  if (it == truth.end()) return truth.back().r_e_m;
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double w = (tow_s - a.tow_s) / (b.tow_s - a.tow_s);
  return a.r_e_m + w * (b.r_e_m - a.r_e_m);
}

Eigen::Vector3d nav_at(const std::vector<pipelines::FusedNavRow>& nav, double t_s) {
  auto it = std::lower_bound(nav.begin(), nav.end(), t_s,
                             [](const pipelines::FusedNavRow& r, double t) { return r.nav.t_s < t; });
  auto pos = [](const pipelines::FusedNavRow& r) {
    return ins::ecef_from_geodetic(r.nav.lat_rad, r.nav.lon_rad, r.nav.height_m);
  };
  if (it == nav.begin()) return pos(*it);
  if (it == nav.end()) return pos(nav.back());
  const double w = (t_s - (it - 1)->nav.t_s) / (it->nav.t_s - (it - 1)->nav.t_s);
  return pos(*(it - 1)) + w * (pos(*it) - pos(*(it - 1)));
}

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 3));
}

struct Rms {
  int epochs = 0;
  double fused_m = 0.0, gnss_m = 0.0;
  // sqrt(mean over epochs k of the mean squared fix error of the fixes up to k, the start's included): what a
  // filter that averages the fixes so far could reach at worst (|mean e_i|^2 <= mean |e_i|^2).
  double running_mean_bound_m = 0.0;
};

// Fused (nav.csv) and PVT (solution.csv) 3-D position errors at the fixes made after the fused start.
Rms compare(const fs::path& rx) {
  const auto& s = simulated();
  const auto nav = pipelines::read_fused_nav_csv(rx / "nav.csv");
  const auto fixes = ultratrack::pipelines::read_solution_csv(rx / "solution.csv");
  Rms r;
  double f2 = 0.0, g2 = 0.0, since_start = 0.0, bound2 = 0.0;
  int n_since_start = 0;
  for (const auto& f : fixes) {
    const double tow = f.tow_s - f.clock_bias_m / kC;  // true GPS time of the fix
    const double t = tow - kStartTow_s;                // IMU time (sample 0 = the scenario start)
    if (nav.empty() || t < nav.front().nav.t_s - 1e-6 || t > nav.back().nav.t_s) continue;
    const Eigen::Vector3d truth = truth_at(s.truth, tow);
    since_start += (f.r_e_m - truth).squaredNorm();
    ++n_since_start;
    if (t <= nav.front().nav.t_s + 1e-6) continue;  // the start's own fix
    f2 += (nav_at(nav, t) - truth).squaredNorm();
    g2 += (f.r_e_m - truth).squaredNorm();
    bound2 += since_start / n_since_start;
    ++r.epochs;
  }
  if (r.epochs) {
    r.fused_m = std::sqrt(f2 / r.epochs);
    r.gnss_m = std::sqrt(g2 / r.epochs);
    r.running_mean_bound_m = std::sqrt(bound2 / r.epochs);
  }
  return r;
}

struct Receive {
  pipelines::Coupling coupling = pipelines::Coupling::kTight;
  fusion::FilterKind filter = fusion::FilterKind::Ekf;
  pipelines::AlignMode align = pipelines::AlignMode::Motion;
  std::optional<fs::path> fusion_config;   // [initial], [alignment], ...; without it in-motion windows of 1 s
  std::optional<fs::path> receive_config;  // [receiver], ...
  std::vector<int> prns;                   // searched (all when empty)
};

// The hot-started receive of the scenario's file with its IMU data into rx, through the library.
pipelines::ReceiveSummary receive(const fs::path& rx, const Receive& o) {
  const auto& s = simulated();
  pipelines::ReceiveFileJob job;
  job.input = s.sim / "antenna0.i8.bin";
  job.out = rx;
  job.source.fs_hz = job.options.receiver.fs_hz = 2.0e6;
  if (o.receive_config) config::apply_receive_config(*o.receive_config, job.options.receiver);
  if (!o.prns.empty()) job.options.receiver.prns = o.prns;
  job.navigation = signals::read_rinex_nav(s.nav);
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  job.imu = ins::read_imu_csv(s.sim / "imu.csv");
  job.options.coupling = o.coupling;
  job.options.filter = o.filter;
  job.options.align = o.align;
  if (o.fusion_config)
    job.options.navigation = config::read_fuse_config(*o.fusion_config);
  else
    job.options.navigation.motion_window_s = 1.0;
  return pipelines::receive_file(std::move(job)).summary;
}

}  // namespace

// Loose: each PVT fix (with its own a-priori covariance) updates the filter. The fixes are carrier-smoothed
// pseudorange solutions whose errors vary slowly (metres at first, settling as the Hatch filters converge), so
// over the 7 s after the alignment the filter, which treats them as white and in effect averages them, cannot
// beat them; its honest bound is the running-mean bound of the fixes themselves (Rms above). A time-tag error
// of 0.1 s (0.8 m along the track) or a wrong measurement covariance breaks it. (60 s figures: validation.md.)
TEST(ReceiveFusion, LooseCouplingFromIfSamplesFollowsThePvtFixes) {
  const auto rx = simulated().dir / "rx_loose";
  Receive loose;
  loose.coupling = pipelines::Coupling::kLoose;
  receive(rx, loose);
  const Rms r = compare(rx);
  const std::string summary = test::read_text_file(rx / "summary.json");
  std::printf("loose EKF: %d epochs, fused 3-D RMS %.3f m, PVT %.3f m, running-mean bound %.3f m\n", r.epochs,
              r.fused_m, r.gnss_m, r.running_mean_bound_m);
  EXPECT_NE(summary.find("\"fusion\": {\"coupling\": \"loose\""), std::string::npos);
  EXPECT_GE(r.epochs, 50);  // 16 s file, first fix ~8.1 s, alignment after 1 s of motion
  EXPECT_LE(r.fused_m, r.running_mean_bound_m);
  // one update per fix; the last fix may lie a hair beyond the IMU's last row and stay queued
  EXPECT_GE(json_number(summary, "updates_accepted"), r.epochs - 1);
  EXPECT_EQ(json_number(summary, "updates_rejected"), 0.0);
}

// Tight: raw pseudoranges and Doppler per satellite (noise nearly white: the DLL's), each gated on its own. The
// fused position must beat the PVT fixes at the same epochs, with the EKF and with the UKF.
TEST(ReceiveFusion, TightCouplingFromIfSamplesBeatsThePvtFixes) {
  for (const std::string filter : {"ekf", "ukf"}) {
    const auto rx = simulated().dir / ("rx_tight_" + filter);
    Receive tight;
    tight.filter = filter == "ekf" ? fusion::FilterKind::Ekf : fusion::FilterKind::Ukf;
    receive(rx, tight);
    const Rms r = compare(rx);
    const std::string summary = test::read_text_file(rx / "summary.json");
    std::printf("tight %s: %d epochs, fused 3-D RMS %.3f m, PVT %.3f m\n", filter.c_str(), r.epochs, r.fused_m,
                r.gnss_m);
    EXPECT_NE(summary.find("\"filter\": \"" + filter + "\""), std::string::npos);
    EXPECT_GE(r.epochs, 50);
    EXPECT_LT(r.fused_m, r.gnss_m) << filter;
    EXPECT_EQ(json_number(summary, "epochs_fewer_than_4_satellites"), 0.0);
    // six satellites a fix, pseudorange and rate each: one update per satellite and epoch
    EXPECT_GE(json_number(summary, "updates_accepted"), 5.0 * r.epochs);
  }
}

// A receiver clock jump while the tight filter runs: the receiver's clock starts ~7.6 ms off (initial travel time
// 75 ms instead of ~67 ms) and is corrected by a jump at the first fix (threshold 10 us), after the INS has started
// from the configuration at t = 0 and taken the first epoch. The jump must be taken out of the pseudoranges and
// epoch times (without that, 2280 km steps: the gate rejects nearly every later update).
TEST(ReceiveFusion, TightCouplingCarriesItsClockThroughAReceiverClockJump) {
  const auto& s = simulated();
  const auto rx_config = s.dir / "jump.toml";
  std::ofstream(rx_config) << "[receiver]\nclock_jump_threshold_s = 1e-5\ninitial_travel_time_s = 0.075\n";
  const auto config = s.dir / "start.toml";
  std::ofstream(config) << "[initial]\nattitude_deg = [0, 0, 0]\nposition_deg_m = [35.274016, 137.013759, 100.0]\n"
                           "velocity_ned_mps = [8.333333333, 0, 0]\nsigma_position_m = [3, 3, 3]\n";
  const auto rx = s.dir / "rx_jump";
  Receive jump;
  jump.align = pipelines::AlignMode::Config;
  jump.fusion_config = config;
  jump.receive_config = rx_config;
  receive(rx, jump);
  const std::string summary = test::read_text_file(rx / "summary.json");
  EXPECT_EQ(json_number(summary, "clock_jumps"), 1.0);
  EXPECT_EQ(json_number(summary, "clock_jumps_removed"), 1.0);
  EXPECT_EQ(json_number(summary, "epochs_before_start"), 0.0);  // the filter ran before and after the jump
  EXPECT_EQ(json_number(summary, "updates_rejected"), 0.0);
  const Rms r = compare(rx);
  std::printf("tight EKF through a clock jump: %d epochs, fused 3-D RMS %.3f m, PVT %.3f m\n", r.epochs, r.fused_m,
              r.gnss_m);
  EXPECT_LT(r.fused_m, r.gnss_m);
}

// Tight with three satellites (--prn): the PVT never fixes, the INS starts from the configuration (the
// trajectory's start, 20 m east of the truth on purpose, sigma 20 m) and runs alone until the first epoch; the
// three pseudoranges and rates must then pull the horizontal error to the noise (what stays unobservable with
// three satellites is one position/clock combination, here mostly vertical: its sigma grows, as it must).
TEST(ReceiveFusion, TightCouplingWithThreeSatellitesStaysBoundedWhereThePvtCannotFix) {
  const auto& s = simulated();
  ASSERT_GE(s.prns_by_elevation.size(), 3u);
  const auto config = s.dir / "three.toml";
  std::ofstream(config) << "[initial]\nattitude_deg = [0, 0, 0]\n"
                           "position_deg_m = [35.274016, 137.01397883, 100.0]\n"  // 20.0 m east of the start
                           "velocity_ned_mps = [8.333333333, 0, 0]\nsigma_position_m = [20, 20, 20]\n";
  const auto rx = s.dir / "rx_three";
  Receive three;
  three.align = pipelines::AlignMode::Config;
  three.fusion_config = config;
  three.prns = {s.prns_by_elevation[0], s.prns_by_elevation[1], s.prns_by_elevation[2]};
  receive(rx, three);
  const std::string summary = test::read_text_file(rx / "summary.json");
  EXPECT_EQ(json_number(summary, "fixes"), 0.0);
  const std::string solution = test::read_text_file(rx / "solution.csv");
  EXPECT_EQ(std::count(solution.begin(), solution.end(), '\n'), 1) << "solution.csv: header only";
  EXPECT_GE(json_number(summary, "epochs_fewer_than_4_satellites"), 50.0);
  const auto nav = pipelines::read_fused_nav_csv(rx / "nav.csv");
  ASSERT_FALSE(nav.empty());
  EXPECT_NEAR(nav.back().nav.t_s, kDuration_s, 0.02);
  double worst_late_m = 0.0;
  int outside_3sigma = 0, rows = 0;
  for (const auto& row : nav) {
    if (row.nav.t_s < kDuration_s - 5.0) continue;  // the last 5 s: 3 s and more after the first epoch
    const Eigen::Vector3d r = ins::ecef_from_geodetic(row.nav.lat_rad, row.nav.lon_rad, row.nav.height_m);
    const Eigen::Vector3d e_n =
        ins::C_en(row.nav.lat_rad, row.nav.lon_rad).transpose() * (r - truth_at(s.truth, kStartTow_s + row.nav.t_s));
    worst_late_m = std::max(worst_late_m, e_n.head<2>().norm());
    outside_3sigma += (e_n.cwiseAbs().array() > 3.0 * row.sigma.position_ned_m.array()).any();
    ++rows;
  }
  const double sigma_h_end = nav.back().sigma.position_ned_m.head<2>().norm();
  std::printf(
      "tight, 3 satellites: horizontal error over the last 5 s at most %.2f m (start 20 m), final "
      "horizontal 1-sigma %.2f m, vertical %.2f m\n",
      worst_late_m, sigma_h_end, nav.back().sigma.position_ned_m.z());
  EXPECT_LT(worst_late_m, 5.0);  // the 20 m start error removed to the pseudorange noise level
  EXPECT_LT(sigma_h_end, 10.0);  // and the filter knows it: bounded, not growing like a free INS
  EXPECT_EQ(outside_3sigma, 0) << "of " << rows << " rows";
}
