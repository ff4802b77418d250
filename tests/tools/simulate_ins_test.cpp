// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate` with [trajectory] and [imu]: one trajectory drives the IMU data, the truth and the
// IF synthesiser's antennas. Checked against an independent run of the trajectory generator with the
// antenna positions built by hand (GeographicLib position, NED->ECEF rotation, C_nb from the truth
// quaternion or the scenario's Euler angles), the carrier-phase difference of two antennas against the
// baseline on the line of sight, and the written imu.csv integrated by the strapdown mechanisation.
#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "config/scenario_toml.hpp"
#include "ins/imu_csv.hpp"
#include "ins/strapdown.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"
#include "signals/gps_constants.hpp"
#include "signals/input_error.hpp"
#include "signals/satellite_state.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario_models.hpp"
#include "simulation_run.hpp"
#include "support/test_data.hpp"

namespace ultratrack::tools {
using namespace ultratrack::config;
namespace {

using namespace ultratrack::sim;

constexpr double kLat = 35.274016, kLon = 137.013759, kH = 100.0;

std::vector<std::string> read_lines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

// Numeric rows of a CSV file (header skipped).
std::vector<std::vector<double>> read_rows(const std::filesystem::path& p) {
  const auto lines = read_lines(p);
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::string l = lines[i];
    std::replace(l.begin(), l.end(), ',', ' ');
    std::istringstream ss(l);
    std::vector<double> row;
    for (double v; ss >> v;) row.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

Eigen::Vector3d ecef(double lat_rad, double lon_rad, double h) {
  Eigen::Vector3d r;
  GeographicLib::Geocentric::WGS84().Forward(lat_rad / io::kRadPerDeg, lon_rad / io::kRadPerDeg, h, r.x(), r.y(),
                                             r.z());
  return r;
}

// NED -> ECEF rotation, written out from the definition of the NED axes.
Eigen::Matrix3d C_en(double lat, double lon) {
  const Eigen::Vector3d north(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
  const Eigen::Vector3d east(-std::sin(lon), std::cos(lon), 0.0);
  const Eigen::Vector3d down(-std::cos(lat) * std::cos(lon), -std::cos(lat) * std::sin(lon), -std::sin(lat));
  Eigen::Matrix3d C;
  C.col(0) = north;
  C.col(1) = east;
  C.col(2) = down;
  return C;
}

// C_nb = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d C_nb_from_euler(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d antenna_by_hand(const ins::TruthSample& t, const Eigen::Vector3d& lever_b) {
  return ecef(t.lat_rad, t.lon_rad, t.height_m) + C_en(t.lat_rad, t.lon_rad) * t.q_nb.toRotationMatrix() * lever_b;
}

std::string scenario_head(const std::string& signal, const std::string& receiver_extra = "") {
  return signal + R"(
[time]
gps_week = 2190
tow_s = 518400.0
[navigation]
constellation = "nominal"
[atmosphere]
ionosphere = false
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
)" + receiver_extra;
}

const char* const kSignal = R"(
[signal]
sample_rate_hz = 2.6e6
format = "i8"
duration_s = 1.0
seed = 3
)";

TEST(SimulateIns, CircleScenarioTruthImuAndAntennaGeometryAgree) {
  const auto dir = test::scratch_dir();
  const std::string text = scenario_head(kSignal) + R"(
[trajectory]
profile = "circle"
duration_s = 1.5
imu_rate_hz = 100.0
[imu]
preset = "hg1700ae"
seed = 11
[[antenna]]
lever_arm_body_m = [0.5, 0.2, -1.0]
[[antenna]]
lever_arm_body_m = [-2.0, 1.0, -0.8]
)";
  { std::ofstream(dir / "circle.toml") << text; }
  const Scenario s = read_scenario(dir / "circle.toml");
  ASSERT_TRUE(s.trajectory_enabled());
  ASSERT_TRUE(s.signal);
  const auto out = dir / "out";
  const auto result = run_simulation(s, out);
  for (const char* f : {"antenna0.i8.bin", "antenna1.i8.bin", "imu.csv", "truth.csv", "antenna_truth.csv",
                        "satellites.csv", "scenario.toml", "summary.json"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  EXPECT_EQ(result.imu_rows, 150u);
  EXPECT_EQ(read_rows(out / "imu.csv").size(), 150u);
  EXPECT_EQ(to_toml(read_scenario(out / "scenario.toml")), to_toml(s));

  // The same trajectory, run independently.
  const auto ref =
      ins::simulate(ins::profile_spec("circle", 1.5, kLat * io::kRadPerDeg, kLon * io::kRadPerDeg, kH), 100.0).truth;
  ASSERT_EQ(ref.size(), 151u);
  const std::vector<Eigen::Vector3d> levers = {{0.5, 0.2, -1.0}, {-2.0, 1.0, -0.8}};

  // truth.csv: the IMU's position, NED velocity and attitude at the 10 Hz rows (receiver time = GPS time
  // since the start: no clock drift).
  const auto lines = read_lines(out / "truth.csv");
  EXPECT_EQ(lines.at(0),
            "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
            "clock_bias_m,clock_drift_mps,roll_deg,pitch_deg,yaw_deg");
  const auto truth = read_rows(out / "truth.csv");
  ASSERT_EQ(truth.size(), 10u);
  double worst_pos = 0.0, worst_att = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const auto& row = truth[k];
    ASSERT_EQ(row.size(), 17u);
    EXPECT_NEAR(row[0], 0.1 * static_cast<double>(k), 1e-9);
    const ins::TruthSample& r = ref[10 * k];
    const Eigen::Vector3d p(row[3], row[4], row[5]);
    worst_pos = std::max(worst_pos, (p - ecef(r.lat_rad, r.lon_rad, r.height_m)).norm());
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(row[9 + i], r.v_n[i], 2e-5);
    const Eigen::Matrix3d C = r.q_nb.toRotationMatrix();
    const double roll = std::atan2(C(2, 1), C(2, 2)), pitch = -std::asin(C(2, 0)), yaw = std::atan2(C(1, 0), C(0, 0));
    worst_att = std::max({worst_att, std::abs(row[14] - roll / io::kRadPerDeg),
                          std::abs(row[15] - pitch / io::kRadPerDeg), std::abs(row[16] - yaw / io::kRadPerDeg)});
  }
  std::printf("truth.csv vs independent trajectory: position %.2e m, attitude %.2e deg\n", worst_pos, worst_att);
  EXPECT_LT(worst_pos, 1e-3);
  EXPECT_LT(worst_att, 1e-6);
  EXPECT_GT(std::abs(truth.back()[14]), 10.0);  // the coordinated turn banks the body (the attitude matters)

  // antenna_truth.csv: every antenna at IMU position + C_en C_nb lever arm.
  const auto ant = read_rows(out / "antenna_truth.csv");
  ASSERT_EQ(ant.size(), 20u);
  for (const auto& row : ant) {
    const auto k = static_cast<std::size_t>(std::llround(row[0] * 10.0));
    const Eigen::Vector3d expected = antenna_by_hand(ref[10 * k], levers[static_cast<std::size_t>(row[1])]);
    EXPECT_LT((Eigen::Vector3d(row[2], row[3], row[4]) - expected).norm(), 1e-3) << "t " << row[0];
  }

  // The synthesiser as the run wires it: its geometric range for the master antenna is from IMU position +
  // C_nb lever arm, at IMU sample times.
  const NavigationSource nav = load_navigation(s);
  auto interp = std::make_shared<ins::TruthInterpolator>(ref);
  signals::IfSynthesiser synth(synthesiser_options(s, nav), nav.ephemerides, make_motion(s, interp));
  const auto views = synth.visible_satellites(0);
  ASSERT_GE(views.size(), 4u);
  for (std::int64_t n : {std::int64_t{0}, std::int64_t{1'300'000}, std::int64_t{2'600'000}}) {
    const auto k = static_cast<std::size_t>(n / 26'000);  // IMU sample at n / fs
    for (int a = 0; a < 2; ++a) {
      const Eigen::Vector3d r_ant = antenna_by_hand(ref[k], levers[static_cast<std::size_t>(a)]);
      EXPECT_LT((synth.motion().antenna_state(a, static_cast<double>(n) / 2.6e6).r_e_m - r_ant).norm(), 1e-3);
      for (const auto& v : views) {
        const auto tm = synth.timing(v.prn, a, n);
        const auto& eph = *std::find_if(nav.ephemerides.begin(), nav.ephemerides.end(),
                                        [&](const signals::Ephemeris& e) { return e.prn == v.prn; });
        const double flight = tm.geometric_range_m / signals::kSpeedOfLight_mps;
        const auto st =
            signals::satellite_state(eph, signals::add_seconds({2190, 518400.0}, tm.receive_time_s - flight));
        const double range = (signals::rotate_to_receive_frame(st.r_e_m, flight) - r_ant).norm();
        EXPECT_NEAR(tm.geometric_range_m, range, 1e-3) << "PRN " << v.prn << " antenna " << a << " sample " << n;
      }
    }
  }

  // satellites.csv (from the run): the code phase at sample 0 is that of a synthesiser whose antenna sits
  // still at the hand-built master position (code phase at one instant depends on position only).
  const auto sats = read_rows(out / "satellites.csv");
  ASSERT_EQ(sats.size(), views.size());
  signals::IfSynthesiser still(
      synthesiser_options(s, nav), nav.ephemerides,
      std::make_shared<signals::StaticMotion>(std::vector<Eigen::Vector3d>{antenna_by_hand(ref[0], levers[0])}));
  for (const auto& row : sats) {
    const double expected = still.timing(static_cast<int>(row[0]), 0, 0).code_phase_chips;
    double d = row[5] - expected;
    d -= 1023.0 * std::round(d / 1023.0);
    EXPECT_NEAR(d, 0.0, 1e-5) << "PRN " << row[0];  // 1e-5 chip = 3 mm
  }
}

TEST(SimulateIns, StaticTwoAntennaAttitudeCarrierPhaseDifferenceIsBaselineOnLineOfSight) {
  const auto dir = test::scratch_dir();
  const std::string text = scenario_head(R"(
[signal]
sample_rate_hz = 2.6e6
format = "i8"
duration_s = 0.1
)",
                                         "attitude_deg = [12.0, -7.0, 63.0]\n") +
                           R"(
[trajectory]
profile = "static"
duration_s = 0.5
[[antenna]]
lever_arm_body_m = [0.0, 0.0, 0.0]
[[antenna]]
lever_arm_body_m = [1.5, 0.4, -0.3]
)";
  { std::ofstream(dir / "static.toml") << text; }
  const Scenario s = read_scenario(dir / "static.toml");
  const auto out = dir / "out";
  run_simulation(s, out);

  const Eigen::Matrix3d C_nb = C_nb_from_euler(12.0 * io::kRadPerDeg, -7.0 * io::kRadPerDeg, 63.0 * io::kRadPerDeg);
  const Eigen::Vector3d r0 = ecef(kLat * io::kRadPerDeg, kLon * io::kRadPerDeg, kH);
  const Eigen::Vector3d baseline_e =
      C_en(kLat * io::kRadPerDeg, kLon * io::kRadPerDeg) * C_nb * Eigen::Vector3d(1.5, 0.4, -0.3);

  // truth.csv carries the parked attitude; imu.csv's specific force levels to it.
  const auto truth = read_rows(out / "truth.csv");
  ASSERT_FALSE(truth.empty());
  EXPECT_NEAR(truth[0][14], 12.0, 1e-6);
  EXPECT_NEAR(truth[0][15], -7.0, 1e-6);
  EXPECT_NEAR(truth[0][16], 63.0, 1e-6);
  EXPECT_LT((Eigen::Vector3d(truth[0][3], truth[0][4], truth[0][5]) - r0).norm(), 1e-3);
  const auto imu = ins::read_imu_csv(out / "imu.csv");
  const Eigen::Vector3d f = imu.front().dv_b / 0.01;
  EXPECT_NEAR(std::atan2(-f.y(), -f.z()) / io::kRadPerDeg, 12.0, 1e-3);
  EXPECT_NEAR(std::atan2(f.x(), std::hypot(f.y(), f.z())) / io::kRadPerDeg, -7.0, 1e-3);

  // The synthesiser wired as in the run: carrier phase difference at sample 0 = baseline . LOS / lambda.
  const NavigationSource nav = load_navigation(s);
  const auto ref = ins::simulate(trajectory_spec(s), s.imu_rate_hz).truth;
  signals::IfSynthesiser synth(synthesiser_options(s, nav), nav.ephemerides,
                               make_motion(s, std::make_shared<ins::TruthInterpolator>(ref)));
  const auto views = synth.visible_satellites(0);
  ASSERT_GE(views.size(), 4u);
  double worst = 0.0;
  for (const auto& v : views) {
    const auto t0 = synth.timing(v.prn, 0, 0), t1 = synth.timing(v.prn, 1, 0);
    const auto& eph = *std::find_if(nav.ephemerides.begin(), nav.ephemerides.end(),
                                    [&](const signals::Ephemeris& e) { return e.prn == v.prn; });
    const double flight = t0.geometric_range_m / signals::kSpeedOfLight_mps;
    const auto st = signals::satellite_state(eph, signals::add_seconds({2190, 518400.0}, -flight));
    const Eigen::Vector3d u = (signals::rotate_to_receive_frame(st.r_e_m, flight) - r0).normalized();
    const double expected = u.dot(baseline_e) / signals::kL1Wavelength_m;
    worst = std::max(worst, std::abs(t1.carrier_phase_cycles - t0.carrier_phase_cycles - expected));
    EXPECT_NEAR(t1.carrier_phase_cycles - t0.carrier_phase_cycles, expected, 1e-3) << "PRN " << v.prn;
  }
  std::printf("static two-antenna: worst carrier-phase difference error %.2e cycles\n", worst);
}

TEST(SimulateIns, ImuOnlyScenarioIntegratesBackToTruth) {
  const auto dir = test::scratch_dir();
  const std::string text = scenario_head("") + R"(
[trajectory]
profile = "circle"
duration_s = 60.0
imu_rate_hz = 100.0
[imu]
preset = "ideal"
)";
  { std::ofstream(dir / "imu_only.toml") << text; }
  const Scenario s = read_scenario(dir / "imu_only.toml");
  EXPECT_FALSE(s.signal);
  const auto out = dir / "out";
  const auto result = run_simulation(s, out);
  EXPECT_EQ(result.imu_rows, 6000u);
  EXPECT_FALSE(std::filesystem::exists(out / "antenna0.i8.bin"));
  EXPECT_FALSE(std::filesystem::exists(out / "satellites.csv"));
  EXPECT_EQ(to_toml(read_scenario(out / "scenario.toml")), to_toml(s));
  std::ifstream summary(out / "summary.json");
  const std::string json((std::istreambuf_iterator<char>(summary)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"signal\": false"), std::string::npos) << json;

  const auto truth = read_rows(out / "truth.csv");
  ASSERT_EQ(truth.size(), 601u);
  const auto imu = ins::read_imu_csv(out / "imu.csv");
  ASSERT_EQ(imu.size(), 6000u);
  auto state_of = [](const std::vector<double>& row) {
    ins::NavState n;
    n.t_s = row[0];
    n.lat_rad = row[6] * io::kRadPerDeg;
    n.lon_rad = row[7] * io::kRadPerDeg;
    n.height_m = row[8];
    n.v_n = {row[9], row[10], row[11]};
    n.q_nb = Eigen::Quaterniond(
        C_nb_from_euler(row[14] * io::kRadPerDeg, row[15] * io::kRadPerDeg, row[16] * io::kRadPerDeg));
    return n;
  };
  ins::Strapdown ins(state_of(truth[0]));
  double worst = 0.0, worst_att = 0.0;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    ins.step(imu[i]);
    if ((i + 1) % 10 != 0) continue;
    const auto& row = truth[(i + 1) / 10];
    ASSERT_NEAR(ins.state().t_s, row[0], 1e-9);
    const auto& st = ins.state();
    worst =
        std::max(worst, (ecef(st.lat_rad, st.lon_rad, st.height_m) - Eigen::Vector3d(row[3], row[4], row[5])).norm());
    worst_att =
        std::max(worst_att, Eigen::AngleAxisd(st.q_nb.conjugate() * state_of(row).q_nb).angle() / io::kRadPerDeg);
  }
  std::printf("imu.csv (ideal) mechanised over 60 s of circle: position error %.3e m, attitude %.2e deg\n", worst,
              worst_att);
  EXPECT_LT(worst, 1.0);
  EXPECT_LT(worst_att, 1e-4);
}

// A mis-synchronised IMU ([imu] time_offset_s): its stamps read true time + the offset, the truth does not move.
TEST(SimulateIns, ImuTimeOffsetShiftsOnlyTheImuStamps) {
  const auto dir = test::scratch_dir();
  const std::string text = scenario_head("") + R"(
[trajectory]
profile = "circle"
duration_s = 2.0
imu_rate_hz = 100.0
[imu]
preset = "ideal"
time_offset_s = 0.003
)";
  { std::ofstream(dir / "offset.toml") << text; }
  const Scenario s = read_scenario(dir / "offset.toml");
  EXPECT_DOUBLE_EQ(s.imu_time_offset_s, 0.003);
  const auto out = dir / "out";
  run_simulation(s, out);
  EXPECT_EQ(to_toml(read_scenario(out / "scenario.toml")), to_toml(s));
  const auto imu = ins::read_imu_csv(out / "imu.csv");
  ASSERT_EQ(imu.size(), 200u);
  for (std::size_t k = 0; k < imu.size(); ++k) EXPECT_NEAR(imu[k].t_s, 0.01 * static_cast<double>(k + 1) + 0.003, 1e-9);
  const auto truth = read_rows(out / "truth.csv");
  EXPECT_NEAR(truth[1][0], 0.1, 1e-9);
}

TEST(SimulateIns, LandProfileWritesTheOdometer) {
  const auto dir = test::scratch_dir();
  const std::string text = scenario_head("") + R"(
[trajectory]
profile = "land"
duration_s = 40.0
odometer = true
)";
  { std::ofstream(dir / "land.toml") << text; }
  run_simulation(read_scenario(dir / "land.toml"), dir / "out");
  const auto odo = read_rows(dir / "out" / "odometer.csv");
  ASSERT_EQ(odo.size(), 400u);  // 10 Hz
  double distance = 0.0;
  for (const auto& r : odo) distance += r[2];
  // The odometer's distance is the path length of the truth (pulses of 2 cm, no scale-factor error).
  const auto truth = read_rows(dir / "out" / "truth.csv");
  double path = 0.0;
  for (std::size_t i = 1; i < truth.size(); ++i)
    path += (Eigen::Vector3d(truth[i][3], truth[i][4], truth[i][5]) -
             Eigen::Vector3d(truth[i - 1][3], truth[i - 1][4], truth[i - 1][5]))
                .norm();
  EXPECT_GT(path, 10.0);
  EXPECT_NEAR(distance, path, 0.02 * path + 0.04);  // chords of 0.1 s vs arc; pulses of 2 cm
}

// A segment file (relative to the scenario) with its start speed and heading; the echo names it absolutely.
TEST(SimulateIns, SegmentFileTrajectoryStartsAsGiven) {
  const auto dir = test::scratch_dir();
  std::ofstream(dir / "seg.csv")
      << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n5,1,0,0,0\n5,0,3,0,0\n";
  const std::string text = scenario_head("") + R"(
[trajectory]
file = "seg.csv"
speed_mps = 10.0
heading_deg = 30.0
imu_rate_hz = 200.0
)";
  { std::ofstream(dir / "seg.toml") << text; }
  const Scenario s = read_scenario(dir / "seg.toml");
  const auto result = run_simulation(s, dir / "out");
  EXPECT_EQ(result.imu_rows, 2000u);  // 10 s at 200 Hz
  const auto truth = read_rows(dir / "out" / "truth.csv");
  ASSERT_EQ(truth.size(), 101u);
  EXPECT_NEAR(truth[0][9], 10.0 * std::cos(30.0 * io::kRadPerDeg), 1e-5);
  EXPECT_NEAR(truth[0][10], 10.0 * std::sin(30.0 * io::kRadPerDeg), 1e-5);
  EXPECT_NEAR(truth[0][16], 30.0, 1e-6);
  // 1 m/s^2 for 5 s, blended in over the first 1 s (quintic: half of the ramp's acceleration is lost)
  EXPECT_NEAR(std::hypot(truth[50][9], truth[50][10]), 10.0 + 4.5, 1e-4);
  const std::string echo = to_toml(read_scenario(dir / "out" / "scenario.toml"));
  EXPECT_EQ(echo, to_toml(s));
  EXPECT_NE(echo.find((dir / "seg.csv").lexically_normal().string()), std::string::npos) << echo;
}

std::string error_of(const std::string& text, bool run = false) {
  const auto dir = test::scratch_dir();
  const auto path = dir / "bad.toml";
  { std::ofstream(path) << text; }
  try {
    const Scenario s = read_scenario(path);
    if (run) run_simulation(s, dir / "out");
  } catch (const signals::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.toml"), std::string::npos) << what;
    return what;
  }
  ADD_FAILURE() << "no InputError for\n" << text;
  return "";
}

TEST(SimulateIns, BadKeysAreInputErrorsNamingTheScenario) {
  EXPECT_NE(
      error_of(scenario_head("") + "[trajectory]\nprofile = \"loop\"\nduration_s = 1.0\n").find("trajectory.profile"),
      std::string::npos);
  EXPECT_NE(error_of(scenario_head("") +
                     "[trajectory]\nprofile = \"static\"\nduration_s = 1.0\n[imu]\npreset = \"tactical\"\n")
                .find("imu.preset"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head(kSignal) + "[trajectory]\nprofile = \"circle\"\nduration_s = 0.5\n", true)
                .find("trajectory lasts 0.5 s"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head("") + "[trajectory]\nprofile = \"circle\"\n").find("duration_s"), std::string::npos);
  EXPECT_NE(error_of(scenario_head("") + "[trajectory]\nprofile = \"circle\"\nduration_s = 1.0\nspeed = 3\n")
                .find("unknown key"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head("") + "[[antenna]]\nlever_arm_body_m = [0, 0, 0]\n").find("[[antenna]]"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head("", "attitude_deg = [0, 0, 10]\n") +
                     "[trajectory]\nprofile = \"circle\"\nduration_s = 1.0\n")
                .find("attitude_deg"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head("") +
                     "[trajectory]\nprofile = \"static\"\nduration_s = 1.0\n[[antenna]]\nlever = [0, 0, 0]\n")
                .find("antenna.lever"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head("") + "[trajectory]\nfile = \"seg.csv\"\nduration_s = 3.0\n").find("own duration"),
            std::string::npos);
  EXPECT_NE(error_of(scenario_head(kSignal) + "[trajectory]\nfile = \"absent.csv\"\n", true).find("absent.csv"),
            std::string::npos);
}

}  // namespace
}  // namespace ultratrack::tools
