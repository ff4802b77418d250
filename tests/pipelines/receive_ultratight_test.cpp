// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight receive end to end through the library (pipelines::receive_file), short for CI: the simulator writes
// 21 s of a car on a 100 m circle at 30 km/h (45 dB-Hz, 2 MHz, the shipped brdc3540_0000-0200.14n from TOW 518476, 4 s
// into a subframe, when no satellite is within 1 deg of the 10 deg measurement mask; IF samples, imu.csv (HG1700) and
// truth.csv from one trajectory) with every signal absent from 14.0 to 18.0 s (a short tunnel; 4 s: the filter-driven
// channels' presence test declares a loss 1-2 s after it, within 3 s with probability 1 - 0.085^2). The receiver starts
// hot, pulls in scalar, the tight integration aligns in motion, and ~2 s later the ultra-tight loop takes the channels
// over. Checked against the simulator's truth: every channel synchronised at the hand-over is commanded by the
// loop to the end (none released, none re-acquired), coasts through the gap and re-locks within 1 s of the
// signal's return; the fused position (nav.csv) against truth.csv within a bound from the noise; EKF + I&Q and
// UKF + discriminators both with the pipelined loop (`--ut-pipelined`: its commands one 20 ms period later), and both
// again with the serial loop (the default); the same bytes with one thread and two (either loop). The command line's
// flags for these options and its errors: tests/tools/receive_ultratight_cli_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "config/scenario_toml.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "io/input_error.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/receive_file.hpp"
#include "pipelines/solution_compare.hpp"
#include "pipelines/ultratight_loop.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"
#include "support/ultratight_tunnel_scenario.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

using test::kGapEnd_s, test::kGapStart_s, test::kDuration_s, test::kStartTow_s;

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 3));
}

struct Sim {
  fs::path dir, sim, nav;
};

Sim& tunnel() {
  static Sim s = [] {
    Sim r;
    const fs::path brdc = test::shipped_nav_file();
    r.dir = test::scratch_dir();
    r.sim = r.dir / "sim";
    r.nav = brdc;
    test::write_tunnel_scenario(r.dir, brdc);
    ultratrack::sim::simulate_to_folder(config::read_scenario(r.dir / "circle.toml"), r.sim, "");
    return r;
  }();
  return s;
}

// The receive of the tunnel file into rx: hot start (the ephemeris file), in-motion alignment over 1 s windows,
// ultra-tight coupling with the given filter, measurement form and loop, `threads` worker threads (0: all cores).
// perturb_prn: that satellite's broadcast clock (af0) in the receiver's ephemerides is off by perturb_m of range (the
// signal is simulated from the true one): its predicted replica contradicts its correlations.
pipelines::ReceiveFileResult receive(const fs::path& rx, fusion::FilterKind filter, fusion::UltraTightForm form,
                                     bool serial, int threads = 0, int perturb_prn = 0, double perturb_m = 0.0) {
  const auto& s = tunnel();
  pipelines::ReceiveFileJob job;
  job.input = s.sim / "antenna0.i8.bin";
  job.out = rx;
  job.source.fs_hz = job.options.receiver.fs_hz = 2.0e6;
  job.options.receiver.threads = threads;
  job.navigation = signals::read_rinex_nav(s.nav);
  for (auto& e : job.navigation.ephemerides)
    if (e.prn == perturb_prn) e.af0_s += perturb_m / 299792458.0;
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  job.imu = ins::read_imu_csv(s.sim / "imu.csv");
  job.options.coupling = pipelines::Coupling::kUltraTight;
  job.options.filter = filter;
  job.options.ut_form = form;
  job.options.ut_pipelined = !serial;
  job.options.align = pipelines::AlignMode::Motion;
  job.options.navigation.motion_window_s = 1.0;
  return pipelines::receive_file(std::move(job));
}

// Position error of nav.csv against truth.csv (IMU = antenna: no lever arm) from t0 on: 3-D RMS, and the RMS of
// the filter's own 3-D 1-sigma over the same rows.
struct NavError {
  int rows = 0;
  double rms_m = 0.0, sigma_m = 0.0;
};
NavError nav_error(const fs::path& rx, double t0) {
  const auto truth = ultratrack::pipelines::read_simulation_truth_csv(tunnel().sim / "truth.csv");
  const auto nav = pipelines::read_fused_nav_csv(rx / "nav.csv");
  NavError e;
  double s2 = 0.0, g2 = 0.0;
  for (const auto& r : nav) {
    const double tow = kStartTow_s + r.nav.t_s;
    if (r.nav.t_s < t0) continue;
    auto it = std::lower_bound(truth.begin(), truth.end(), tow,
                               [](const ultratrack::pipelines::TruthPoint& p, double t) { return p.tow_s < t; });
    if (it == truth.begin() || it == truth.end()) continue;
    const double w = (tow - (it - 1)->tow_s) / (it->tow_s - (it - 1)->tow_s);
    const Eigen::Vector3d p = (it - 1)->r_e_m + w * (it->r_e_m - (it - 1)->r_e_m);
    s2 += (ins::ecef_from_geodetic(r.nav.lat_rad, r.nav.lon_rad, r.nav.height_m) - p).squaredNorm();
    g2 += r.sigma.position_ned_m.squaredNorm();
    ++e.rows;
  }
  if (e.rows) {
    e.rms_m = std::sqrt(s2 / e.rows);
    e.sigma_m = std::sqrt(g2 / e.rows);
  }
  return e;
}

// 3-D RMS of solution.csv's velocity against the truth from t0 on, outside [skip_from, skip_to) (IMU time).
double fix_velocity_rms(const fs::path& rx, double t0, double skip_from, double skip_to, int& rows) {
  const auto truth = ultratrack::pipelines::read_simulation_truth_csv(tunnel().sim / "truth.csv");
  double s2 = 0.0;
  rows = 0;
  for (const auto& f : pipelines::read_solution_csv(rx / "solution.csv")) {
    const double t = f.tow_s - kStartTow_s;
    if (t < t0 || (t >= skip_from && t < skip_to)) continue;
    auto it = std::lower_bound(truth.begin(), truth.end(), f.tow_s,
                               [](const ultratrack::pipelines::TruthPoint& p, double x) { return p.tow_s < x; });
    if (it == truth.begin() || it == truth.end()) continue;
    const double w = (f.tow_s - (it - 1)->tow_s) / (it->tow_s - (it - 1)->tow_s);
    const Eigen::Vector3d v_ned = (it - 1)->v_ned_mps + w * (it->v_ned_mps - (it - 1)->v_ned_mps);
    s2 += (f.v_enu_mps - Eigen::Vector3d(v_ned.y(), v_ned.x(), -v_ned.z())).squaredNorm();
    ++rows;
  }
  return rows ? std::sqrt(s2 / rows) : NAN;
}

// ultratight.csv: per PRN, (time, ultratight, coasting, updated, accepted, carrier runaway) rows.
struct Row {
  double t;
  bool ultratight, coasting, updated, accepted, runaway;
};
std::map<int, std::vector<Row>> read_log(const fs::path& rx) {
  std::ifstream in(rx / "ultratight.csv");
  std::string line;
  std::getline(in, line);
  const auto header = test::split_csv_line(line);
  const auto col = [&](const std::string& name) { return test::csv_column(header, name); };
  const std::size_t t = col("time_s"), prn = col("prn"), ut = col("ultratight"), co = col("coasting"),
                    acc = col("accepted"), upd = col("updated"), run = col("carrier_runaway");
  std::map<int, std::vector<Row>> out;
  while (std::getline(in, line)) {
    const auto f = test::split_csv_line(line);
    out[std::stoi(f[prn])].push_back(
        {std::stod(f[t]), f[ut] == "1", f[co] == "1", f[upd] == "1", f[acc] == "1", f[run] == "1"});
  }
  return out;
}

// Sample variance of the I&Q form's prompt in-phase innovation (innovation_2) over the updates in [t0, t1).
double prompt_i_innovation_variance(const fs::path& rx, double t0, double t1, int& n) {
  std::ifstream in(rx / "ultratight.csv");
  std::string line;
  std::getline(in, line);
  const auto header = test::split_csv_line(line);
  const auto col = [&](const std::string& name) { return test::csv_column(header, name); };
  const std::size_t t = col("time_s"), upd = col("updated"), ip = col("innovation_2");
  double s = 0.0, s2 = 0.0;
  n = 0;
  while (std::getline(in, line)) {
    const auto f = test::split_csv_line(line);
    const double time = std::stod(f[t]);
    if (f[upd] != "1" || time < t0 || time >= t1) continue;
    const double v = std::stod(f[ip]);
    s += v;
    s2 += v * v;
    ++n;
  }
  return n > 1 ? (s2 - s * s / n) / (n - 1) : NAN;
}

void check_run(fusion::FilterKind filter_kind, fusion::UltraTightForm form_kind, bool serial = false) {
  const std::string filter = filter_kind == fusion::FilterKind::Ekf ? "ekf" : "ukf";
  const std::string form = form_kind == fusion::UltraTightForm::Iq ? "iq" : "discriminator";
  const auto rx = tunnel().dir / ("rx_" + filter + "_" + form + (serial ? "_serial" : ""));
  const pipelines::ReceiveSummary result = receive(rx, filter_kind, form_kind, serial).summary;
  EXPECT_TRUE(result.handed_over);
  EXPECT_TRUE(result.navigation_started);
  EXPECT_GT(result.ultratight_channel_epochs, 0);
  const std::string summary = test::read_text_file(rx / "summary.json");
  ASSERT_NE(summary.find("\"ultratight\": {\"filter\": \"" + filter + "\", \"measurement\": \"" + form +
                         "\", \"handed_over\": true, \"loop\": \"" + (serial ? "serial" : "pipelined") + "\""),
            std::string::npos)
      << summary;
  const double handover_s = json_number(summary, "handover_t_s");
  EXPECT_GT(handover_s, 9.0);
  EXPECT_LT(handover_s, kGapStart_s - 1.0);
  EXPECT_EQ(json_number(summary, "releases"), 0.0);
  // The windowed NIS test (1 s windows, 1e-6, margin 3) releases nothing at 45 dB-Hz and never re-opens the filter:
  // its 1 s sums stay below 1.9 x the dof there (docs/validation.md) against a band of 3 x q(300, 1e-6) = 4.3 x;
  // a consistent filter would pass it with probability 1e-6 per window (~3.5e-3 over this run's ~3500 windows).
  EXPECT_EQ(summary.find("channel_nis"), std::string::npos) << summary;
  EXPECT_EQ(json_number(summary, "filter_reopens"), 0.0);
  // The carrier-runaway check (below 30 dB-Hz only) leaves a 45 dB-Hz run alone; per channel below.
  std::printf("carrier re-centres %g, left out %g\n", json_number(summary, "carrier_recentres"),
              json_number(summary, "runaway_left_out"));
  EXPECT_EQ(json_number(summary, "runaway_releases"), 0.0);

  const auto log = read_log(rx);
  // The channels commanded at the hand-over: at least 6 (the file's sky at the start: 9 healthy satellites above
  // 10 deg, PRNs 2 (8.9 deg) and 11 (6.6 deg) above the 5 deg command mask, PRN 12 at 5.4 deg).
  std::set<int> handed;
  for (const auto& [prn, rows] : log)
    if (!rows.empty() && rows.front().ultratight) handed.insert(prn);
  EXPECT_GE(handed.size(), 6u);
  // Below the PVT's 10 deg mask a channel is commanded but "aided only": its correlations never update the filter
  // (UltraTightOptions::measurement_mask_rad). Elevations from the simulation (at its start; they move < 0.2 deg
  // in the file's 21 s), none within 0.5 deg of the mask.
  std::map<int, double> elevation_deg;
  {
    std::ifstream in(tunnel().sim / "satellites.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      const auto f = test::split_csv_line(line);
      elevation_deg[std::stoi(f.at(0))] = std::stod(f.at(1));
    }
  }
  int aided_only = 0;
  for (int prn : handed) {
    ASSERT_TRUE(elevation_deg.count(prn)) << "PRN " << prn;
    ASSERT_GT(std::abs(elevation_deg[prn] - 10.0), 0.5) << "PRN " << prn;
    aided_only += elevation_deg[prn] < 10.0;
  }
  EXPECT_EQ(json_number(summary, "aided_only_satellite_periods") > 0.0, aided_only > 0);
  for (const auto& [prn, el] : elevation_deg) {  // every satellite above the 5 deg command mask is commanded
    if (el > 5.5) {
      EXPECT_TRUE(handed.count(prn)) << "PRN " << prn << " at " << el << " deg";
    }
  }
  int late_losses = 0;  // channels whose loss the presence test declared a window late (below)
  int undeclared = 0;   // channels whose loss it did not declare within the gap (below)
  for (int prn : handed) {
    const bool measured = elevation_deg[prn] >= 10.0;
    const auto& rows = log.at(prn);
    double relock_s = NAN;
    int before = 0, before_ok = 0, after = 0, after_ok = 0;  // updates (measurements) and accepted ones
    int outside_gap = 0;
    double loss_s = NAN;  // first coasting row after the gap's start
    for (const Row& r : rows) {
      // Commanded by the loop throughout (kept in lock, or coasting on the prediction in the gap).
      EXPECT_TRUE(r.ultratight) << "PRN " << prn << " at " << r.t;
      if (r.updated && r.t < kGapStart_s) ++before, before_ok += r.accepted;
      if (r.updated && r.t > kGapEnd_s + 1.5) ++after, after_ok += r.accepted;
      // Coasting only inside the gap and until the re-lock (the C/N0 estimate needs ~0.2 s to see the fade).
      if (r.coasting && (r.t < kGapStart_s || r.t > kGapEnd_s + 1.0)) ++outside_gap;
      if (r.coasting && r.t >= kGapStart_s && std::isnan(loss_s)) loss_s = r.t - kGapStart_s;
      if (r.t >= kGapEnd_s && !r.coasting && std::isnan(relock_s)) relock_s = r.t - kGapEnd_s;
    }
    EXPECT_EQ(outside_gap, 0) << "PRN " << prn;
    // The presence test (1 s windows of 20 ms epochs, 12 dB-Hz): no window holding 45 dB-Hz epochs fails, so the
    // loss comes at the end of the first window wholly inside the gap, 1-2 s after its start, or a window later
    // when noise passes (probability 0.085 each). But a noise window that reads 15 dB-Hz or more also sets the
    // monitor's level (PresenceMonitorOptions: a step down counts at once), and at ~13 dB-Hz a loss needs 3 or more
    // absent windows, which the 4 s gap may not hold: then the loss comes after the return, i.e. never. That is a
    // fraction of a per cent of channel-gaps, but over 12 channels about one file in ten: the same tunnel file
    // simulated with seeds 1-11 (`receive --coupling ultra-tight --filter ekf`) left one channel's loss undeclared in
    // 1 file of 11 at 8a375b1 (seed 1) and in 1 of 11 with the aided hold (receiver/scalar_tracking.hpp; seed 4, this
    // file), a different draw of the same windows (12 and 13 late losses in all). So at most one channel per file.
    const bool declared = loss_s >= 1.0 && loss_s <= kGapEnd_s - kGapStart_s;
    if (!declared) {
      ++undeclared;
      std::printf("PRN %d: loss not declared within the gap (%.2f s)\n", prn, loss_s);
    } else {
      EXPECT_GE(loss_s, 1.0) << "PRN " << prn;
    }
    // The carrier-runaway check (C/N0 below 30 dB-Hz, 1 s means of the replica's offset from the prediction) never
    // flags a channel while its 45 dB-Hz signal is there. In the gap a channel coasts, and the monitor restarts,
    // before it has a whole 1 s mean of faded epochs (the C/N0 estimate falls below 30 dB-Hz ~0.1 s in; the loss
    // comes 1-2 s in) unless the presence test declares the loss a window late (2-3 s in): then the PLL on noise may
    // be judged a runaway in the gap before it coasts, and stays flagged until it re-locks (seen on the shipped
    // file's sky: PRN 9 lost 2.14 s in, flagged from 2.06 s in to its re-lock).
    const bool late = !declared || loss_s > 2.0;
    late_losses += late;
    for (const Row& r : rows) {
      const bool in_fade = r.t >= kGapStart_s && r.t <= kGapEnd_s + relock_s;
      EXPECT_FALSE(r.runaway && !(late && in_fade)) << "PRN " << prn << " judged a runaway at " << r.t << " s";
    }
    std::printf("PRN %d: loss declared %.2f s into the gap, re-lock %.2f s after the return\n", prn, loss_s, relock_s);
    EXPECT_LE(relock_s, 1.0) << "PRN " << prn;  // issue 7: back in lock within 1 s, no acquisition
    // Measurements pass the gate (p = 0.9999): before the gap nearly all (97-100 % seen); from 1.5 s after the
    // return most (84-100 % seen: in the first second after a re-lock the PLL's residual phase makes the gate
    // refuse a third of them: docs/validation.md).
    if (!measured) {  // aided only: never an update
      EXPECT_EQ(before + after, 0) << "PRN " << prn;
      continue;
    }
    EXPECT_GE(before_ok, 0.9 * before) << "PRN " << prn;
    EXPECT_GE(after_ok, 0.75 * after) << "PRN " << prn;
    EXPECT_GE(before, 100) << "PRN " << prn;
  }
  EXPECT_LE(undeclared, 1);
  EXPECT_GE(json_number(summary, "relocks"), static_cast<double>(handed.size()) - undeclared);
  // No aiding step and no correlation left out unless a late-declared loss let the check act in the gap (at most one
  // re-centring per such channel).
  if (late_losses == 0) {
    EXPECT_EQ(json_number(summary, "carrier_recentres"), 0.0);
    EXPECT_EQ(json_number(summary, "runaway_left_out"), 0.0);
  }
  EXPECT_LE(json_number(summary, "carrier_recentres"), static_cast<double>(late_losses));
  // No re-acquisition: each handed-over satellite acquired once (summary per_satellite).
  for (int prn : handed) {
    const auto at = summary.find("\"prn\": " + std::to_string(prn) + ",");
    ASSERT_NE(at, std::string::npos);
    EXPECT_EQ(json_number(summary.substr(at), "acquisitions"), 1.0) << "PRN " << prn;
  }
  // Position against truth after the hand-over, the gap included. Bound from the noise: the code noise of one
  // 20 ms epoch at 45 dB-Hz is sqrt(d / (2 C/N0 T)) chip = 0.02 chip = 5.8 m per satellite; the filter averages it
  // with the INS over ~1 s (50 epochs x 7 satellites, PDOP ~2: ~0.5 m), leaving the unmodelled residual
  // atmosphere (broadcast Klobuchar and Saastamoinen against the simulated same models: < 0.5 m) and the INS drift
  // in the 4 s gap (HG1700: decimetres at most). 2 m 3-D RMS (issue 3's fix tolerance), and at most 3 times the
  // filter's own stated 1-sigma (consistency).
  if (form == "iq") {
    // The prompt's in-phase innovation against the model's amplitude: unit noise plus the amplitude estimate's
    // own variance (a 0.1 average of |P|^2 at A^2 = 1265: ~0.05) and the filter's share (small). It was 3.3 when
    // the amplitude followed the normalised taps (the channel's noise normalisation moves it +-8 %), 0.81 with the
    // epoch's own prompt in its average (docs/validation.md). Bounds: 0.88-1.3 (~700 updates, sampling sd ~5 %).
    int n = 0;
    const double v = prompt_i_innovation_variance(rx, handover_s + 1.0, kGapStart_s, n);
    std::printf("ultra-tight %s iq: I_P innovation variance %.3f over %d updates\n", filter.c_str(), v, n);
    EXPECT_GE(n, 400);
    EXPECT_GT(v, 0.88);
    EXPECT_LT(v, 1.3);
  }
  const NavError e = nav_error(rx, handover_s + 0.5);
  std::printf("ultra-tight %s %s %s: hand-over %.2f s, %zu channels, nav 3-D RMS %.3f m (stated %.3f m) over %d rows\n",
              filter.c_str(), form.c_str(), serial ? "serial" : "pipelined", handover_s, handed.size(), e.rms_m,
              e.sigma_m, e.rows);
  EXPECT_GE(e.rows, 500);
  EXPECT_LT(e.rms_m, 2.0);
  EXPECT_LT(e.rms_m, 3.0 * e.sigma_m);
  // solution.csv's velocity after the hand-over is the filter's (the channels' Doppler is its own command): the
  // INS-aided velocity at 45 dB-Hz is good to centimetres per second; 0.1 m/s leaves room for the 30 ms
  // extrapolation of the pipelined rows. The gap and the second after it (fixes from re-locking channels) are
  // left out.
  int fix_rows = 0;
  const double v_rms = fix_velocity_rms(rx, handover_s + 0.5, kGapStart_s, kGapEnd_s + 1.0, fix_rows);
  std::printf("ultra-tight %s %s: solution.csv velocity 3-D RMS %.3f m/s over %d fixes\n", filter.c_str(), form.c_str(),
              v_rms, fix_rows);
  EXPECT_GE(fix_rows, 20);
  EXPECT_LT(v_rms, 0.1);
}

}  // namespace

// The pipelined loop (`--ut-pipelined`): job 0 of the next block's correlation, its commands one 20 ms vector epoch
// later. The lock, coasting, re-lock, NIS and accuracy checks hold with that latency.
TEST(ReceiveUltraTight, EkfOnIqKeepsEveryChannelThroughAShortTunnelAndFollowsTruth) {
  check_run(fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq);
}

TEST(ReceiveUltraTight, UkfOnDiscriminatorsKeepsEveryChannelThroughAShortTunnelAndFollowsTruth) {
  check_run(fusion::FilterKind::Ukf, fusion::UltraTightForm::Discriminator);
}

// The serial loop (the default: on the caller between blocks, its commands at once) passes the same checks.
TEST(ReceiveUltraTight, SerialEkfOnIqKeepsEveryChannelThroughAShortTunnelAndFollowsTruth) {
  check_run(fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq, true);
}

TEST(ReceiveUltraTight, SerialUkfOnDiscriminatorsKeepsEveryChannelThroughAShortTunnelAndFollowsTruth) {
  check_run(fusion::FilterKind::Ukf, fusion::UltraTightForm::Discriminator, true);
}

// One satellite's broadcast clock 100 m off in the receiver's ephemerides (0.34 chip: the hand-over still commands
// it, within max_jump_chips): the filter's replica of it is 100 m from its signal, its I&Q updates contradict the
// prediction from its first update on (NIS in the thousands, each counted at the gate's 27.9) and the windowed NIS
// test releases it to scalar tracking with its first full window: 50 x 27.9 = 1393 > 3 q(300, 1e-6) = 1293 (from a
// window of clean updates it would take k = (1293 - 50 x 6) / (27.9 - 6) = 45 updates; any run of 50 updates above
// 1293 / 50 = 26 trips it within one window), 1 s after the hand-over plus the loop's one or two 20 ms periods of
// latency; it is then left out of the filter. The others stay commanded to the end and the filter is never re-opened;
// its position stays on the truth.
TEST(ReceiveUltraTight, AChannelWhoseEphemerisContradictsItsSignalIsReleasedAndTheOthersStay) {
  // The highest satellite (the most weight in the solution; measured, far above the masks).
  int prn = 0;
  double best = -90.0;
  {
    std::ifstream in(tunnel().sim / "satellites.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      const auto f = test::split_csv_line(line);
      if (std::stod(f.at(1)) > best) best = std::stod(f.at(1)), prn = std::stoi(f.at(0));
    }
  }
  ASSERT_GT(best, 30.0);
  const auto rx = tunnel().dir / "rx_contradicted";
  receive(rx, fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq, false, 0, prn, 100.0);
  const std::string summary = test::read_text_file(rx / "summary.json");
  const double handover_s = json_number(summary, "handover_t_s");
  EXPECT_EQ(json_number(summary, "releases"), 1.0) << summary;
  EXPECT_EQ(json_number(summary, "filter_reopens"), 0.0);
  ASSERT_NE(summary.find("\"releases_by_reason\": {\"channel_nis\": 1}"), std::string::npos) << summary;
  const auto at = summary.find("\"release_log\": [{\"t_s\": ");
  ASSERT_NE(at, std::string::npos);
  const double released_s = json_number(summary.substr(at + 16), "t_s");
  EXPECT_EQ(json_number(summary.substr(at + 16), "prn"), static_cast<double>(prn));
  // Receiver time (from sample 0) against the hand-over (IMU time = GPS time - the file's start: the same to
  // within the clock bias, microseconds).
  std::printf("PRN %d (%.1f deg) released %.2f s after the hand-over at %.2f s\n", prn, best, released_s - handover_s,
              handover_s);
  EXPECT_GT(released_s - handover_s, 0.98);        // not before the window is full
  EXPECT_LT(released_s - handover_s, 1.0 + 0.07);  // one window, and the loop's latency
  const auto log = read_log(rx);
  for (const auto& [p, rows] : log) {
    if (rows.empty() || !rows.front().ultratight) continue;
    for (const Row& r : rows) {
      if (p != prn) {
        EXPECT_TRUE(r.ultratight) << "PRN " << p << " at " << r.t;
      }
      if (p == prn && r.t > released_s + 0.05) {
        EXPECT_FALSE(r.ultratight) << "PRN " << p << " commanded again at " << r.t;
        EXPECT_FALSE(r.updated) << "PRN " << p << " updates the filter again at " << r.t;
      }
    }
  }
  const NavError e = nav_error(rx, handover_s + 0.5);
  std::printf("contradicted PRN %d: nav 3-D RMS %.3f m over %d rows\n", prn, e.rms_m, e.rows);
  EXPECT_LT(e.rms_m, 2.0);
}

namespace {

// ultratight.csv and nav.csv of the ultra-tight receive with 1 and with 2 threads: {threads - 1} x {ut, nav}.
std::array<std::array<std::string, 2>, 2> outputs_by_thread_count(const std::string& name, bool serial) {
  std::array<std::array<std::string, 2>, 2> text;
  for (int threads : {1, 2}) {
    const auto rx = tunnel().dir / (name + std::to_string(threads));
    receive(rx, fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq, serial, threads);
    text[threads - 1][0] = test::read_text_file(rx / "ultratight.csv");
    text[threads - 1][1] = test::read_text_file(rx / "nav.csv");
  }
  return text;
}

}  // namespace

// Pipelined: every thread count runs the same jobs on the same inputs (--threads 1 runs the loop's
// job in turn): the same bytes.
TEST(ReceiveUltraTight, OneThreadAndTwoGiveTheSameBytes) {
  const auto text = outputs_by_thread_count("rx_threads", false);
  EXPECT_GT(text[0][0].size(), 10000u);
  EXPECT_TRUE(text[0][0] == text[1][0]) << "ultratight.csv differs";
  EXPECT_TRUE(text[0][1] == text[1][1]) << "nav.csv differs";
}

// Serial: the loop runs on the engine's caller thread after the channels' parallel work: the same bytes for one
// thread and two. The latency is real: its commands, and so its log, differ from the pipelined loop's.
TEST(ReceiveUltraTight, SerialOneThreadAndTwoGiveTheSameBytesAndDifferFromPipelined) {
  const auto text = outputs_by_thread_count("rx_serial_threads", true);
  EXPECT_GT(text[0][0].size(), 10000u);
  EXPECT_TRUE(text[0][0] == text[1][0]) << "ultratight.csv differs";
  EXPECT_TRUE(text[0][1] == text[1][1]) << "nav.csv differs";
  const auto rx = tunnel().dir / "rx_pipelined_two_threads";
  receive(rx, fusion::FilterKind::Ekf, fusion::UltraTightForm::Iq, false, 2);
  EXPECT_FALSE(test::read_text_file(rx / "ultratight.csv") == text[0][0]);
}
