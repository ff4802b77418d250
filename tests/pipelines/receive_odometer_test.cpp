// SPDX-License-Identifier: GPL-3.0-or-later
// Odometer (VMS) aiding in `receive --coupling loose|tight --odometer` from IF samples end to end through the library
// (issue 19, [KimVMS]): one simulation of a car at 20 m/s (HG1700AE IMU at 100 Hz, a 10 Hz odometer with a +0.3 %
// scale factor, 20 ms delay and a 0.2 / -0.3 deg mounting misalignment, nominal constellation, 2.0 MHz i8 at
// 45 dB-Hz, 80 s) with a 40 deg turn before a 45 s tunnel (every satellite blocked from 30 s to 75 s) that holds
// a 15 deg curve at 1 deg/s (below the odometer gate's 1.5 deg/s). The same receive
// with and without the odometer, in the loose and the tight coupling; the horizontal drift over the blockage against
// the simulator's truth.
// The 60 s figure of docs/validation.md: benchmarks/odometer_tunnel.sh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "config/scenario_toml.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "ins/odometer_csv.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/receive_file.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation_files.hpp"
#include "sim/truth_csv.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

constexpr double kStartTow_s = 518776.0;  // first fix ~8.1 s in (hot start from the scenario's RINEX)
constexpr double kBlockStart_s = 30.0, kBlockEnd_s = 75.0, kSpeed_mps = 20.0;
constexpr double kScaleFactorError = 0.003, kYawMisalignment_deg = -0.3;

struct Sim {
  fs::path dir, sim, nav;
  std::vector<ins::NavState> truth;  // the IMU's (body origin and attitude) at 100 Hz
};

const Sim& simulated() {
  static Sim s =
      [] {
        Sim r;
        r.dir = test::scratch_dir();
        r.sim = r.dir / "sim";
        std::ofstream(r.dir / "route.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                              "12,0,0,0,0\n10,0,4,0,0\n8,0,0,0,0\n15,0,0,0,0\n15,0,1,0,0\n20,0,0,0,0\n";
        std::ofstream(r.dir / "tunnel.toml")
            << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 80.0\ncn0_dbhz = 45.0\nseed = 4\n"
               "[time]\ngps_week = 2190\ntow_s = "
            << kStartTow_s
            << "\n[navigation]\nconstellation = \"nominal\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
               "[trajectory]\nfile = \"route.csv\"\nspeed_mps = "
            << kSpeed_mps << "\nheading_deg = 0.0\nimu_rate_hz = 100.0\nodometer = true\nodometer_scale_factor_error = "
            << kScaleFactorError << "\nodometer_delay_s = 0.02\nodometer_misalignment_pitch_deg = 0.2\n"
            << "odometer_misalignment_yaw_deg = " << kYawMisalignment_deg
            << "\n[output]\ntruth_rate_hz = 100.0\n[imu]\npreset = \"hg1700ae\"\nseed = 7\n"
               "[atmosphere]\nionosphere = true\ntroposphere = true\n"
               "[[blockage]]\nantenna = 0\nstart_s = "
            << kBlockStart_s << "\nduration_s = " << kBlockEnd_s - kBlockStart_s << "\n";
        const auto scenario = config::read_scenario(r.dir / "tunnel.toml");
        sim::simulate_to_folder(scenario, r.sim, "");
        r.nav = r.dir / "nominal.rnx";  // the scenario's own broadcast data: the receiver's hot start
        signals::write_rinex_nav_304(r.nav, sim::to_rinex_nav(sim::load_navigation(scenario)));
        r.truth = sim::read_truth_csv(r.sim / "truth.csv");
        return r;
      }();
  return s;
}

// The receive of the scenario's file into rx in the given coupling (ultra-tight: EKF, I&Q), with the odometer when
// asked.
void receive(const fs::path& rx, bool odometer, pipelines::Coupling coupling) {
  const auto& s = simulated();
  pipelines::ReceiveFileJob job;
  job.input = s.sim / "antenna0.i8.bin";
  job.out = rx;
  job.source.fs_hz = job.options.receiver.fs_hz = 2.0e6;
  job.navigation = signals::read_rinex_nav(s.nav);
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  job.imu = ins::read_imu_csv(s.sim / "imu.csv");
  job.options.coupling = coupling;
  if (odometer) {
    job.options.odometer = ins::read_odometer_csv(s.sim / "odometer.csv").samples;
    job.options.odometer_name = "odometer.csv";
  }
  pipelines::receive_file(std::move(job));
}

// The nav row at (or just before) t: its horizontal and heading errors against the truth (rows and truth both at
// 100 Hz on the same time line) and its horizontal 1-sigma.
struct Horizontal {
  double error_m = 0.0, sigma_m = 0.0, heading_error_rad = 0.0;
};
Horizontal horizontal_at(const std::vector<pipelines::FusedNavRow>& nav, double t) {
  const auto& s = simulated();
  auto it = std::upper_bound(nav.begin(), nav.end(), t + 1e-6,
                             [](double x, const pipelines::FusedNavRow& r) { return x < r.nav.t_s; });
  EXPECT_NE(it, nav.begin());
  const auto& row = *(it - 1);
  auto tr = std::lower_bound(s.truth.begin(), s.truth.end(), row.nav.t_s - 1e-6,
                             [](const ins::NavState& p, double x) { return p.t_s < x; });
  EXPECT_NEAR(tr->t_s, row.nav.t_s, 1e-5);
  const Eigen::Vector3d r = ins::ecef_from_geodetic(row.nav.lat_rad, row.nav.lon_rad, row.nav.height_m);
  const Eigen::Vector3d r_true = ins::ecef_from_geodetic(tr->lat_rad, tr->lon_rad, tr->height_m);
  const Eigen::Vector3d e_n = ins::C_en(row.nav.lat_rad, row.nav.lon_rad).transpose() * (r - r_true);
  return {e_n.head<2>().norm(), row.sigma.position_ned_m.head<2>().norm(),
          ins::attitude_error_n(row.nav.q_nb, tr->q_nb).z()};
}

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 3));
}

// Without the odometer the filter runs the INS alone through the tunnel; with it the VMS speed and the
// non-holonomic constraints hold the velocity. Physics bound with the odometer: dead reckoning from the entry
// with the odometer's simulated errors left uncorrected drifts by at most D (|scale factor error| + |yaw
// mounting error| + |heading error at the entry| + the gyro's heading drift) over the D = 900 m driven in the
// tunnel (HG1700AE gyro bias 1 deg/h: 0.0125 deg in 45 s, taken as 0.05 deg); the filter, which also estimates the
// odometer's errors, must do no worse. The INS alone must drift more: a residual accelerometer bias of 0.1 mg
// alone gives 1 m in 45 s. Neither may take the blockage's first epochs as measurements (the channels' loops run
// on noise until their loss-of-lock test fires; receiver/fade_detector.hpp withholds them): in the first 2 s the
// INS of a converged filter (velocity within a few cm/s) moves less than 0.5 m from where it entered.
void check_tunnel(pipelines::Coupling coupling, const std::string& name) {
  const auto& s = simulated();
  const fs::path rx_without = s.dir / (name + "_without"), rx_with = s.dir / (name + "_with");
  receive(rx_without, false, coupling);
  receive(rx_with, true, coupling);
  const auto without = pipelines::read_fused_nav_csv(rx_without / "nav.csv");
  const auto with = pipelines::read_fused_nav_csv(rx_with / "nav.csv");
  ASSERT_FALSE(without.empty());
  ASSERT_FALSE(with.empty());
  const Horizontal entry_without = horizontal_at(without, kBlockStart_s);
  const Horizontal end_without = horizontal_at(without, kBlockEnd_s);
  const Horizontal entry_with = horizontal_at(with, kBlockStart_s), end_with = horizontal_at(with, kBlockEnd_s);
  constexpr double kRadPerDeg = M_PI / 180.0;
  const double distance_m = kSpeed_mps * (kBlockEnd_s - kBlockStart_s);
  const double bound_m =
      entry_with.error_m + distance_m * (std::abs(kScaleFactorError) + std::abs(kYawMisalignment_deg) * kRadPerDeg +
                                         std::abs(entry_with.heading_error_rad) + 0.05 * kRadPerDeg);
  std::printf(
      "45 s tunnel, %s EKF: horizontal error at the entry %.2f m / %.2f m, at the exit %.2f m without "
      "the odometer (1-sigma %.2f m), %.2f m with it (1-sigma %.2f m, physics bound %.2f m)\n",
      name.c_str(), entry_without.error_m, entry_with.error_m, end_without.error_m, end_without.sigma_m,
      end_with.error_m, end_with.sigma_m, bound_m);
  EXPECT_LT(entry_with.error_m, 3.0);  // both enter on GNSS
  EXPECT_LT(entry_without.error_m, 3.0);
  EXPECT_LT(horizontal_at(without, kBlockStart_s + 2.0).error_m, entry_without.error_m + 0.5);
  EXPECT_LT(horizontal_at(with, kBlockStart_s + 2.0).error_m, entry_with.error_m + 0.5);
  EXPECT_LE(end_with.error_m, bound_m);
  EXPECT_LT(end_with.error_m, end_without.error_m);
  EXPECT_LT(end_with.sigma_m, end_without.sigma_m);  // and the filter knows it
  EXPECT_LE(end_with.error_m, 3.0 * end_with.sigma_m);

  // summary.json: fuse's odometer object inside the fusion object, the windows accepted in the tunnel's straights.
  const std::string summary = test::read_text_file(rx_with / "summary.json");
  ASSERT_NE(summary.find("\"odometer\": {\"file\": \"odometer.csv\", \"mode\": \"gated\""), std::string::npos);
  EXPECT_NE(summary.find("\"coupling\": \"" + name + "\""), std::string::npos);
  const std::string odometer = summary.substr(summary.find("\"odometer\": {"));
  EXPECT_GE(json_number(odometer, "gnss_last_used_s"), kBlockStart_s - 1.0);
  EXPECT_LE(json_number(odometer, "gnss_last_used_s"), kBlockStart_s + 1.0);
  EXPECT_GE(json_number(odometer, "updates_accepted"), 30.0);  // 1 Hz from the start (~10 s) to the end, but
  EXPECT_GE(json_number(odometer, "gated_yaw_rate"), 5.0);     // the 4 deg/s turn (10 s) is gated out
  // the simulated scale factor error recovered within 3 sigma
  EXPECT_NEAR(json_number(odometer, "scale_factor"), kScaleFactorError,
              3.0 * json_number(odometer, "sigma_scale_factor"));
  const std::string plain = test::read_text_file(rx_without / "summary.json");
  EXPECT_EQ(plain.find("\"odometer\""), std::string::npos);
}

}  // namespace

TEST(ReceiveOdometer, LooseCouplingWithTheOdometerBridgesATunnel) {
  check_tunnel(pipelines::Coupling::kLoose, "loose");
}

// The tight filter carries the odometer states after its clock's ([17, 21)).
TEST(ReceiveOdometer, TightCouplingWithTheOdometerBridgesATunnel) {
  check_tunnel(pipelines::Coupling::kTight, "tight");
}

// The ultra-tight driver takes the odometer states over from the tight filter at the hand-over ([17, 21) after
// its clock) and the windows from then on.
TEST(ReceiveOdometer, UltraTightCouplingWithTheOdometerBridgesATunnel) {
  check_tunnel(pipelines::Coupling::kUltraTight, "ultra-tight");
}

// Every coupling with an IMU takes the odometer; with height aiding the tight and ultra-tight ones refuse it (one
// filter carries either the terrain state or the odometer's), naming the key.
TEST(ReceiveOdometer, HeightAidingWithAnOdometerIsRejectedNamingIt) {
  pipelines::ReceiveOptions o;
  o.receiver.fs_hz = 2.0e6;
  o.odometer = {{1.0, 10, 1.0}, {2.0, 10, 1.0}};
  std::string why;
  for (const auto coupling :
       {pipelines::Coupling::kLoose, pipelines::Coupling::kTight, pipelines::Coupling::kUltraTight}) {
    o.coupling = coupling;
    EXPECT_TRUE(o.IsValid(&why)) << why;
  }
  o.navigation.height_aiding.enabled = true;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("height_aiding"), std::string::npos) << why;
}
