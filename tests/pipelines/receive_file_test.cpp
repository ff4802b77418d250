// SPDX-License-Identifier: GPL-3.0-or-later
// The library's receive path end to end, without the command line and without shared data: scenarios on the
// nominal constellation (sim/, read from TOML text by config/) simulated into a scratch folder in process, then
// received through pipelines::receive_file (scalar: the summary against the simulator's truth and against the files
// it wrote) and pipelines::Receiver with a recording sink (ultra-tight: every epoch the summary counts reaches the
// sink; the last fused position against the truth within the filter's own sigma). Bad input is one InputError naming
// the file, before any output is written.
#include "pipelines/receive_file.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "config/scenario_toml.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "pipelines/solution_compare.hpp"
#include "signals/input_error.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

constexpr double kFs = 2.0e6;
constexpr double kTow = 518398.0;  // subframes begin 2 s and 8 s into the signal

struct Simulated {
  sim::Scenario scenario;
  sim::SimulationResult result;
  fs::path dir;
};

Simulated simulate(const std::string& name, const std::string& toml) {
  Simulated s;
  s.dir = test::scratch_dir() / name;
  fs::create_directories(s.dir);
  s.scenario = config::parse_scenario(toml, s.dir / (name + ".toml"));
  s.result = sim::simulate_to_folder(s.scenario, s.dir / "sim", toml);
  return s;
}

pipelines::ReceiveFileJob job_for(const Simulated& s, const fs::path& out) {
  pipelines::ReceiveFileJob job;
  job.input = s.dir / "sim" / "antenna0.i8.bin";
  job.out = out;
  job.source.fs_hz = job.options.receiver.fs_hz = kFs;
  job.options.receiver.pvt.troposphere = s.scenario.troposphere;
  job.navigation = sim::to_rinex_nav(sim::load_navigation(s.scenario));
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  return job;
}

const Simulated& static_run() {
  static const Simulated s = simulate("static",
                                      "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 14.0\n"
                                      "cn0_dbhz = 45.0\nseed = 11\n[time]\ngps_week = 2190\ntow_s = 518398.0\n"
                                      "[navigation]\nconstellation = \"nominal\"\n"
                                      "[receiver]\nllh_deg_m = [48.1, 11.6, 520.0]\n");
  return s;
}

std::size_t data_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::size_t n = 0;
  while (std::getline(in, line)) n += !line.empty();
  return n > 0 ? n - 1 : 0;
}

}  // namespace

TEST(ReceiveFile, ScalarHotStartOnTheNominalConstellation) {
  const Simulated& s = static_run();
  const fs::path out = s.dir / "rx";
  const pipelines::ReceiveFileResult r = pipelines::receive_file(job_for(s, out));
  const pipelines::ReceiveSummary& summary = r.summary;

  EXPECT_NEAR(summary.processed_s, 14.0, 1e-9);
  EXPECT_FALSE(summary.interrupted);
  // Every satellite the simulator put in view (above its 5 deg mask; 12 channels by default) is tracked, and those
  // above the PVT's 10 deg mask are used.
  const int in_view = static_cast<int>(s.result.satellites.size());
  const int above_pvt_mask = static_cast<int>(
      std::count_if(s.result.satellites.begin(), s.result.satellites.end(),
                    [](const signals::SatelliteView& v) { return v.elevation_rad > 10.0 * std::numbers::pi / 180.0; }));
  ASSERT_GE(above_pvt_mask, 5);
  EXPECT_EQ(summary.satellites_tracked, std::min(in_view, 12));
  EXPECT_EQ(summary.satellites_used, above_pvt_mask);
  // The first TOW is known at the end of the subframe that begins 2 s in (hot start: ephemerides known).
  EXPECT_GT(summary.ttff_s, 8.0 - 6.0);
  EXPECT_LT(summary.ttff_s, 8.0 + 1.0);
  EXPECT_GT(summary.fixes, 0);
  // The files the observer wrote hold what the summary counts.
  EXPECT_EQ(data_rows(out / "solution.csv"), static_cast<std::size_t>(summary.fixes));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(fs::exists(out / "observations.rnx"));

  // Against the simulator's truth: at 45 dB-Hz a single fix is good to a few metres (code noise ~0.5 m per
  // pseudorange, PDOP < 3 here, ionosphere simulated and removed with the same Klobuchar set); 10 m is > 3 sigma.
  double e, n, u;
  GeographicLib::LocalCartesian(48.1, 11.6, 520.0)
      .Forward(summary.mean_lat_deg, summary.mean_lon_deg, summary.mean_height_m, e, n, u);
  EXPECT_LT(std::hypot(e, n, u), 10.0) << "mean fix " << e << " " << n << " " << u << " m ENU";
  const auto c = pipelines::compare_solution(pipelines::read_solution_csv(out / "solution.csv"),
                                             pipelines::read_simulation_truth_csv(s.dir / "sim" / "truth.csv"));
  EXPECT_EQ(c.fixes + c.fixes_outside_truth, summary.fixes);
  EXPECT_LE(c.fixes_outside_truth, 1);  // a fix at the last sample, past the last truth row
  EXPECT_LT(c.max_3d_m, 15.0);
}

namespace {

struct RecordingSink final : pipelines::ReceiveSink {
  long long navigation = 0, ultratight_epochs = 0, ultratight_channel_epochs = 0;
  std::vector<std::pair<ins::NavState, pipelines::NavSigma>> rows;
  void on_navigation(const ins::NavState& nav, const pipelines::NavSigma& sigma) override {
    ++navigation;
    rows.emplace_back(nav, sigma);
  }
  void on_ultratight_epoch(const pipelines::UltraTightEpochLog& epoch) override {
    ++ultratight_epochs;
    for (const auto& c : epoch.channels) ultratight_channel_epochs += c.ultratight;
  }
};

}  // namespace

// A car on a 100 m circle at 30 km/h (HG1700AE IMU), 45 dB-Hz: tight pull-in, alignment in motion, hand-over to the
// ultra-tight loop; the sink sees every navigation row and channel-epoch the summary counts.
TEST(ReceiveFile, UltraTightHandsOverAndTheSinkSeesEveryEpoch) {
  const std::string circle =
      "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n16.0,0.0,4.774648,0.0,0.0\n";
  const fs::path dir = test::scratch_dir();
  std::ofstream(dir / "circle.csv") << circle;
  const Simulated s = [&] {
    Simulated r;
    r.dir = dir;
    const std::string toml =
        "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 16.0\ncn0_dbhz = 45.0\nseed = 4\n"
        "[time]\ngps_week = 2190\ntow_s = 518398.0\n[navigation]\nconstellation = \"nominal\"\n"
        "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
        "[trajectory]\nfile = \"circle.csv\"\nspeed_mps = 8.333333333\nheading_deg = 0.0\nimu_rate_hz = 100.0\n"
        "[imu]\npreset = \"hg1700ae\"\nseed = 7\n[atmosphere]\nionosphere = true\ntroposphere = true\n";
    r.scenario = config::parse_scenario(toml, dir / "circle.toml");
    r.result = sim::simulate_to_folder(r.scenario, dir / "sim", toml);
    return r;
  }();

  pipelines::ReceiveFileJob job = job_for(s, dir / "unused");
  job.options.coupling = pipelines::Coupling::kUltraTight;
  job.options.filter = fusion::FilterKind::Ukf;
  job.options.align = pipelines::AlignMode::Motion;
  job.options.navigation.motion_window_s = 1.0;
  std::string why;
  ASSERT_TRUE(job.options.IsValid(&why)) << why;
  RecordingSink sink;
  receiver::ReceiverObserver no_files;
  pipelines::Receiver rx(job.options, ins::read_imu_csv(dir / "sim" / "imu.csv"), job.navigation, no_files, sink);
  receiver::SampleSource source(job.input, job.format, job.source);
  rx.run(source, source.total_samples(), {});
  const pipelines::ReceiveSummary summary = rx.finish();

  ASSERT_TRUE(summary.navigation_started) << summary.navigation_not_started;
  EXPECT_TRUE(summary.handed_over);
  EXPECT_EQ(sink.navigation, summary.navigation_rows);
  EXPECT_EQ(sink.ultratight_channel_epochs, summary.ultratight_channel_epochs);
  EXPECT_GT(sink.ultratight_epochs, 0);
  // Every satellite in view is commanded by the loop for the epochs after the hand-over (at least the last 2 s).
  EXPECT_GE(summary.ultratight_channel_epochs, 100LL * std::min<int>(12, s.result.satellites.size()));

  // The last fused position inside the truth's span against the truth, within 4 of the filter's own 3-D sigmas
  // (P(chi2_3 > 16) < 0.2 %) plus the truth file's interpolation (10 Hz rows on an 8.3 m/s circle: < 1 cm).
  const auto truth = pipelines::read_simulation_truth_csv(dir / "sim" / "truth.csv");
  ASSERT_FALSE(sink.rows.empty());
  auto row = sink.rows.rbegin();
  while (row != sink.rows.rend() && kTow + row->first.t_s > truth.back().tow_s) ++row;
  ASSERT_TRUE(row != sink.rows.rend());
  const ins::NavState& last = row->first;
  const pipelines::NavSigma& last_sigma = row->second;
  const double tow = kTow + last.t_s;
  auto it = std::lower_bound(truth.begin(), truth.end(), tow,
                             [](const pipelines::TruthPoint& p, double t) { return p.tow_s < t; });
  ASSERT_TRUE(it != truth.begin() && it != truth.end())
      << "nav t_s " << last.t_s << ", truth " << truth.front().tow_s << ".." << truth.back().tow_s;
  const double w = (tow - (it - 1)->tow_s) / (it->tow_s - (it - 1)->tow_s);
  const Eigen::Vector3d p_truth = (it - 1)->r_e_m + w * (it->r_e_m - (it - 1)->r_e_m);
  const double error_m = (ins::ecef_from_geodetic(last.lat_rad, last.lon_rad, last.height_m) - p_truth).norm();
  EXPECT_LT(error_m, 4.0 * last_sigma.position_ned_m.norm() + 0.01)
      << "at t_s " << last.t_s << ", sigma " << last_sigma.position_ned_m.transpose();
}

TEST(ReceiveFile, BadInputIsOneInputErrorNamingTheFileAndNothingIsWritten) {
  const fs::path dir = test::scratch_dir();
  const auto expect_error = [&](const pipelines::ReceiveFileJob& job, const std::string& words) {
    try {
      pipelines::receive_file(job);
      ADD_FAILURE() << "no error for " << words;
    } catch (const signals::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(job.out / "solution.csv")) << words;
    EXPECT_FALSE(fs::exists(job.out / "summary.json")) << words;
  };
  pipelines::ReceiveFileJob job;
  job.source.fs_hz = job.options.receiver.fs_hz = kFs;
  job.options.receiver.reference_week = 2190;

  // 1 ms of samples: fewer than one acquisition needs.
  job.input = dir / "short.i8.bin";
  job.out = dir / "short_rx";
  std::ofstream(job.input, std::ios::binary) << std::string(2 * 2000, '\x01');
  expect_error(job, "fewer than");
  expect_error(job, job.input.string());

  // 0.3 s from a dead front end (every sample 0): no satellite in the whole signal. (White noise is not used: the
  // acquisition's false-alarm rate makes a detection in it possible, and then the run is not bad input.)
  job.input = dir / "dead.i8.bin";
  job.out = dir / "dead_rx";
  std::ofstream(job.input, std::ios::binary) << std::string(2 * 600000, '\0');
  expect_error(job, "no GPS L1 C/A satellite found");

  // A missing file, and a sample rate that differs between the source and the receiver.
  job.input = dir / "missing.i8.bin";
  job.out = dir / "missing_rx";
  expect_error(job, "missing.i8.bin");
  job.input = dir / "dead.i8.bin";
  job.out = dir / "fs_rx";
  job.options.receiver.fs_hz = 4.0e6;
  expect_error(job, "differs");
}

// An NT1065 file (its 2-bit coding, most significant pair first) read with the default layout tracks nothing; the
// error names the flags that read it (the diagnosis's acquisition finds the simulated satellites with them), and
// the same file read with them is tracked. (A bit order read backwards alone still tracks at 4 MHz, ~8 dB down.)
TEST(ReceiveFile, AWrongTwoBitLayoutIsDiagnosedWithTheFlagsThatWork) {
  const Simulated s = simulate("nt1065",
                               "[signal]\nsample_rate_hz = 4.0e6\nif_hz = 1.0e6\nformat = \"r2\"\n"
                               "two_bit_coding = \"nt1065\"\ntwo_bit_order = \"msb-first\"\n"
                               "duration_s = 1.0\ncn0_dbhz = 45.0\nseed = 3\n"
                               "[time]\ngps_week = 2190\ntow_s = 518398.0\n"
                               "[navigation]\nconstellation = \"nominal\"\n"
                               "[receiver]\nllh_deg_m = [48.1, 11.6, 520.0]\n");
  pipelines::ReceiveFileJob job;
  job.input = s.dir / "sim" / "antenna0.r2.bin";
  job.format = signals::SampleFormat::r2;
  job.source.fs_hz = job.options.receiver.fs_hz = 4.0e6;
  job.source.if_hz = 1.0e6;
  job.options.receiver.reference_week = 2190;
  job.out = s.dir / "rx_wrong";
  try {
    pipelines::receive_file(job);
    ADD_FAILURE() << "a file read with the wrong 2-bit layout gave no error";
  } catch (const signals::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(job.input.string()), std::string::npos) << what;
    EXPECT_NE(what.find("--2bit-coding nt1065 --2bit-order msb-first"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(job.out / "summary.json"));

  job.source.two_bit = {signals::TwoBitCoding::nt1065, signals::BitOrder::msb_first};
  job.out = s.dir / "rx_right";
  const pipelines::ReceiveSummary right = pipelines::receive_file(job).summary;
  EXPECT_EQ(right.satellites_tracked, std::min<int>(12, s.result.satellites.size()));
}
