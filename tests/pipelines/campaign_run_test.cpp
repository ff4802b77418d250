// SPDX-License-Identifier: GPL-3.0-or-later
// Campaign runs and their report (pipelines/campaign_run.hpp, campaign_report.hpp) on a tiny simulated campaign
// (2 s static files on the shipped ephemeris): a run writes its folder and marker, a complete run is not redone,
// a failed run is reported with its message, a missing one is named; the reductions against hand-computed tables.
#include "pipelines/campaign_run.hpp"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "config/campaign_toml.hpp"
#include "config/scenario_toml.hpp"
#include "ins/earth_model.hpp"
#include "io/atomic_file.hpp"
#include "pipelines/campaign_metrics.hpp"
#include "pipelines/campaign_report.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"

namespace {

namespace fs = std::filesystem;
using namespace ultratrack;
using pipelines::CampaignRunState;

// Two 2 s files at 45 dB-Hz; the second receive names a coupling that needs an IMU the scenario lacks: it fails.
fs::path tiny_campaign(const fs::path& dir) {
  std::ofstream(dir / "s.toml") << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 2.0\n"
                                   "cn0_dbhz = 45.0\nseed = {seed}\n[time]\ngps_week = "
                                << test::shipped_nav_week << "\ntow_s = " << test::shipped_nav_tow_s
                                << "\n[navigation]\nrinex = \"" << test::shipped_nav_file().string()
                                << "\"\nelevation_mask_deg = 30.0\n";
  std::ofstream(dir / "c.toml")
      << "[[axis]]\nname = \"seed\"\nvalues = [7, 8]\ncoupling = [\"scalar\", \"tight\"]\n"
         "[simulate]\nscenario = \"s.toml\"\n[receive]\nnav = \""
      << test::shipped_nav_file().string()
      << "\"\ncoupling = \"{coupling}\"\n[compute]\nlock_outcomes = { lock_deadline_s = 1.5 }\n"
         "[[report]]\nkind = \"lock_threshold\"\nlevel = \"seed\"\n"
         "[[report]]\nkind = \"stats\"\nvalue = \"satellites_tracked\"\n";
  return dir / "c.toml";
}

TEST(CampaignRun, RunsResumesAndReportsFailures) {
  const fs::path dir = test::scratch_dir();
  const config::CampaignFile campaign = config::read_campaign(tiny_campaign(dir));
  const auto runs = pipelines::expand_campaign(campaign.axes);
  ASSERT_EQ(runs.size(), 2u);
  const fs::path out = dir / "out";

  // Before any run: both missing.
  std::string report = pipelines::campaign_report(out, runs, campaign.reductions);
  EXPECT_NE(report.find("2 runs: 0 complete, 0 failed, 2 missing"), std::string::npos) << report;
  EXPECT_NE(report.find("missing: 0000-0001"), std::string::npos) << report;

  const fs::path run0 = pipelines::campaign_run_dir(out, 0);
  const auto status0 = pipelines::run_campaign_job(config::campaign_job(campaign, runs[0]), run0);
  ASSERT_EQ(status0.state, CampaignRunState::kComplete) << status0.message;
  EXPECT_TRUE(fs::exists(run0 / "rx" / "tracking.csv"));
  EXPECT_TRUE(fs::exists(run0 / "sim" / "truth.csv"));
  EXPECT_FALSE(fs::exists(run0 / "sim" / "antenna0.i8.bin")) << "the sample file is deleted unless kept";
  EXPECT_EQ(test::read_text_file(run0 / "parameters.csv"), "name,value\nseed,7\ncoupling,scalar\n");
  // Every simulated satellite is classified; at 45 dB-Hz each is locked within 1.5 s and kept to the end.
  const auto outcomes = pipelines::read_lock_outcomes_csv(run0 / "lock_outcomes.csv");
  ASSERT_GE(outcomes.size(), 3u);
  for (const auto& o : outcomes) EXPECT_EQ(o.outcome, "kept") << "PRN " << o.prn;
  EXPECT_EQ(status0.scalars.at("satellites_tracked"), std::to_string(outcomes.size()));

  // Resume: a complete run is not redone (a file left in its folder survives).
  { std::ofstream(run0 / "sentinel") << "x"; }
  EXPECT_EQ(pipelines::run_campaign_job(config::campaign_job(campaign, runs[0]), run0).state,
            CampaignRunState::kComplete);
  EXPECT_TRUE(fs::exists(run0 / "sentinel"));

  // A run killed before its marker (folder and outputs there, no complete.csv) is missing, and redone from scratch.
  fs::remove(run0 / "complete.csv");
  EXPECT_EQ(pipelines::campaign_run_status(run0).state, CampaignRunState::kMissing);
  EXPECT_EQ(pipelines::run_campaign_job(config::campaign_job(campaign, runs[0]), run0).state,
            CampaignRunState::kComplete);
  EXPECT_FALSE(fs::exists(run0 / "sentinel"));
  EXPECT_EQ(pipelines::read_lock_outcomes_csv(run0 / "lock_outcomes.csv").size(), outcomes.size());

  // The tight coupling needs an IMU (no [trajectory]): the run fails, recorded with its message.
  const auto status1 =
      pipelines::run_campaign_job(config::campaign_job(campaign, runs[1]), pipelines::campaign_run_dir(out, 1));
  ASSERT_EQ(status1.state, CampaignRunState::kFailed);
  EXPECT_FALSE(status1.message.empty());
  report = pipelines::campaign_report(out, runs, campaign.reductions);
  EXPECT_NE(report.find("2 runs: 1 complete, 1 failed, 0 missing"), std::string::npos) << report;
  EXPECT_NE(report.find("failed: 0001 (seed=8 coupling=tight): " + status1.message), std::string::npos) << report;
  // The lock table of the complete run: every satellite kept, fraction 1.
  const std::string row = fmt::format("     7.0  {:4d}  {:4d}     0             0             0          1.000",
                                      outcomes.size(), outcomes.size());
  EXPECT_NE(report.find(row), std::string::npos) << report;

  // A failed run is redone on resume (its folder is cleared).
  { std::ofstream(pipelines::campaign_run_dir(out, 1) / "sentinel") << "x"; }
  (void)pipelines::run_campaign_job(config::campaign_job(campaign, runs[1]), pipelines::campaign_run_dir(out, 1));
  EXPECT_FALSE(fs::exists(pipelines::campaign_run_dir(out, 1) / "sentinel"));
}

// A campaign over recordings: each [[recording]] is one value of the axis "recording", received with its flags.
TEST(CampaignRun, ReceivesRecordings) {
  const fs::path dir = test::scratch_dir();
  tiny_campaign(dir);  // s.toml
  std::string scenario = test::read_text_file(dir / "s.toml");
  scenario.replace(scenario.find("{seed}"), 6, "9");
  std::ofstream(dir / "rec.toml") << scenario;
  const sim::Scenario parsed = config::read_scenario(dir / "rec.toml");
  const auto simulated = sim::simulate_to_folder(parsed, dir / "rec", config::to_toml(parsed));
  std::ofstream(dir / "r.toml") << "[[recording]]\nname = \"rec9\"\ninput = \"rec/antenna0.i8.bin\"\nformat = \"i8\"\n"
                                   "sample_rate_hz = 2.0e6\n[[recording]]\nname = \"absent\"\ninput = \"nothing.bin\"\n"
                                   "sample_rate_hz = 2.0e6\n[receive]\nnav = \""
                                << test::shipped_nav_file().string()
                                << "\"\n[compute]\nlock_outcomes = { lock_deadline_s = 1.5 }\n";
  const config::CampaignFile campaign = config::read_campaign(dir / "r.toml");
  const auto runs = pipelines::expand_campaign(campaign.axes);
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(*runs[0].find("input"), (dir / "rec" / "antenna0.i8.bin").string());
  const fs::path out = dir / "out";
  const auto status =
      pipelines::run_campaign_job(config::campaign_job(campaign, runs[0]), pipelines::campaign_run_dir(out, 0));
  ASSERT_EQ(status.state, CampaignRunState::kComplete) << status.message;
  EXPECT_TRUE(fs::exists(dir / "rec" / "antenna0.i8.bin")) << "a recording is never deleted";
  // Without the simulation's list every PRN is classified: the simulated ones kept, the others not acquired.
  int kept = 0, not_acquired = 0;
  for (const auto& o : pipelines::read_lock_outcomes_csv(pipelines::campaign_run_dir(out, 0) / "lock_outcomes.csv"))
    if (o.outcome == "kept") {
      ++kept;
    } else if (o.outcome == "not_acquired") {
      ++not_acquired;
    }
  EXPECT_EQ(kept, static_cast<int>(simulated.satellites.size()));
  EXPECT_EQ(kept + not_acquired, 32);
  // A missing recording: the run fails naming the file.
  const auto missing =
      pipelines::run_campaign_job(config::campaign_job(campaign, runs[1]), pipelines::campaign_run_dir(out, 1));
  ASSERT_EQ(missing.state, CampaignRunState::kFailed);
  EXPECT_NE(missing.message.find("nothing.bin"), std::string::npos) << missing.message;
}

// A run folder made by hand: parameters, lock outcomes, the marker.
void fake_run(const fs::path& out, int index, const std::string& level, const std::vector<std::string>& outcomes) {
  const fs::path dir = pipelines::campaign_run_dir(out, index);
  fs::create_directories(dir);
  std::vector<pipelines::LockOutcome> rows;
  int prn = 1;
  for (const std::string& o : outcomes) rows.push_back({prn++, o, "", ""});
  pipelines::write_lock_outcomes_csv(dir / "lock_outcomes.csv", rows);
  io::write_file_atomically(dir / "complete.csv", "name,value\nfixes," + level + "\n");
}

TEST(CampaignReport, LockThresholdTableMatchesHandCounts) {
  const fs::path out = test::scratch_dir();
  const std::vector<pipelines::CampaignRun> runs{
      {0, {{"cn0_dbhz", "26.0"}}}, {1, {{"cn0_dbhz", "30.0"}}}, {2, {{"cn0_dbhz", "30.0"}}}};
  // 26 dB-Hz: 2 kept, 1 lost, 1 never locked, 1 not acquired; 30 dB-Hz: 10 kept over two runs.
  fake_run(out, 0, "1", {"kept", "kept", "lost", "never_locked", "not_acquired"});
  fake_run(out, 1, "3", {"kept", "kept", "kept", "kept", "kept"});
  fake_run(out, 2, "5", {"kept", "kept", "kept", "kept", "kept"});
  pipelines::CampaignReduction threshold;
  threshold.kind = pipelines::CampaignReduction::Kind::kLockThreshold;
  pipelines::CampaignReduction stats;
  stats.value = "fixes";
  const std::string report = pipelines::campaign_report(out, runs, {threshold, stats});
  // Wilson 68 % (z = 1) of 2 of 4: centre 2.5/5 = 0.5, half-width sqrt(0.0625 + 0.015625) / 1.25 = 0.2236;
  // of 2 of 3: centre (2/3 + 1/6) / (4/3) = 0.625, half-width sqrt(2/27 + 1/36) / (4/3) = 0.2394.
  EXPECT_NE(report.find("    26.0     5     2     1             1             1          0.500  [0.276, 0.724]"
                        "           0.667  [0.386, 0.864]"),
            std::string::npos)
      << report;
  // 10 of 10: [10/11, 1].
  EXPECT_NE(report.find("    30.0    10    10     0             0             0          1.000  [0.909, 1.000]"),
            std::string::npos)
      << report;
  // 0.5 at 26, 1.0 at 30: 0.9 is crossed at 26 + 0.4 / 0.5 * 4 = 29.20.
  EXPECT_NE(report.find("of acquired satellites (pull-in included): 29.20 dB-Hz"), std::string::npos) << report;
  // fixes 1, 3, 5: mean 3, sd 2, 95 % interval 3 +- 4.303 * 2 / sqrt(3) = [-1.969, 7.969], median 3.
  EXPECT_NE(report.find("[-1.969, 7.969]"), std::string::npos) << report;
  const auto [lo, hi] = pipelines::wilson_interval(0, 19, 1.0);
  EXPECT_DOUBLE_EQ(lo, 0.0);
  EXPECT_NEAR(hi, 1.0 / 20.0, 1e-15);  // k = 0, z = 1: the upper bound is 1 / (n + 1)
}

// The step protocol's weak part against hand-made files: truth.csv a receiver moving east along a parallel (tow
// 1000 s at t = 0), fixes 5 m off (3, 4, 0) from t = 4 s and 100 m off before, nav.csv rows 2 m high from t = 4.5 s
// and 50 m high before: 3-D RMS and maximum 5 m and 2 m over the rows at and after 4 s only.
TEST(CampaignMetrics, WeakPartPositionsCountOnlyTheRowsAfterTheStep) {
  const fs::path dir = test::scratch_dir();
  const double lat = 0.6, lon0 = 2.4, h = 50.0;
  const auto lon = [&](double t) { return lon0 + 2.0 * t / (6.4e6 * std::cos(lat)); };  // ~2 m/s east
  std::string truth = "t_s,tow_s,ecef_x_m,ecef_y_m,ecef_z_m\n", sol = "tow_s,ecef_x_m,ecef_y_m,ecef_z_m\n";
  std::string nav = "t_s,lat_deg,lon_deg,height_m\n";
  for (int k = 0; k <= 100; ++k) {
    const double t = 0.1 * k;
    const Eigen::Vector3d r = ins::ecef_from_geodetic(lat, lon(t), h);
    truth += fmt::format("{:.1f},{:.1f},{:.6f},{:.6f},{:.6f}\n", t, 1000.0 + t, r.x(), r.y(), r.z());
  }
  for (int k = 1; k <= 9; ++k) {  // fixes at t = 1..9 s, nav rows at t + 0.5
    const double t = k;
    const Eigen::Vector3d off = t >= 4.0 ? Eigen::Vector3d(3.0, 4.0, 0.0) : Eigen::Vector3d(100.0, 0.0, 0.0);
    const Eigen::Vector3d r = ins::ecef_from_geodetic(lat, lon(t), h) + off;
    sol += fmt::format("{:.1f},{:.6f},{:.6f},{:.6f}\n", 1000.0 + t, r.x(), r.y(), r.z());
    nav += fmt::format("{:.1f},{:.12f},{:.12f},{:.4f}\n", t + 0.5, lat * 180.0 / M_PI, lon(t + 0.5) * 180.0 / M_PI,
                       h + (t + 0.5 >= 4.0 ? 2.0 : 50.0));
  }
  io::write_file_atomically(dir / "truth.csv", truth);
  io::write_file_atomically(dir / "solution.csv", sol);
  io::write_file_atomically(dir / "nav.csv", nav);
  const pipelines::WeakPartPositions w =
      pipelines::weak_part_positions(dir / "solution.csv", dir / "nav.csv", dir / "truth.csv", 4.0);
  EXPECT_EQ(w.fixes, 6);  // t = 4..9
  EXPECT_NEAR(w.rms_3d_m, 5.0, 1e-3);
  EXPECT_NEAR(w.max_3d_m, 5.0, 1e-3);
  EXPECT_EQ(w.nav_rows, 6);  // t = 4.5..9.5
  EXPECT_NEAR(w.nav_rms_3d_m, 2.0, 1e-3);
  EXPECT_NEAR(w.nav_max_3d_m, 2.0, 1e-3);
  // Nothing after the end: NaN, no rows; no nav.csv: no rows.
  const pipelines::WeakPartPositions none =
      pipelines::weak_part_positions(dir / "solution.csv", dir / "absent.csv", dir / "truth.csv", 20.0);
  EXPECT_EQ(none.fixes, 0);
  EXPECT_TRUE(std::isnan(none.rms_3d_m));
  EXPECT_EQ(none.nav_rows, 0);
}

}  // namespace
