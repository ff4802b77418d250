// SPDX-License-Identifier: GPL-3.0-or-later
// sim::simulate into memory: what a sink receives is what the files of `ultratrack simulate` hold (f32 samples bit
// for bit), static truth is the scenario's position, an inertial run hands one IMU row per interval, a stop
// request ends the run, and Scenario::IsValid names the key of what is wrong.
#include "sim/simulation.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"

namespace ultratrack::sim {
namespace {

struct MemorySink final : SimulationSink {
  SimulationShape shape;
  std::vector<std::vector<std::complex<float>>> streams;
  std::vector<TruthRow> truth_rows;
  std::vector<AntennaTruthRow> antenna_rows;
  std::size_t imu_rows = 0;
  std::vector<signals::SatelliteView> in_view;
  bool finished = false;

  void begin(const SimulationShape& s) override {
    shape = s;
    streams.resize(static_cast<std::size_t>(s.antennas));
  }
  void imu(const ins::ImuIncrement&) override { ++imu_rows; }
  void satellites(std::span<const signals::SatelliteView> v) override { in_view.assign(v.begin(), v.end()); }
  void truth(const TruthRow& row) override { truth_rows.push_back(row); }
  void antenna_truth(const AntennaTruthRow& row) override { antenna_rows.push_back(row); }
  void samples(int a, std::span<const std::complex<float>> b) override {
    auto& stream = streams[static_cast<std::size_t>(a)];
    stream.insert(stream.end(), b.begin(), b.end());
  }
  void finish(const SimulationResult&) override { finished = true; }
};

Scenario short_static(signals::SampleFormat format) {
  Scenario s;
  s.sample_rate_hz = 2.0e6;
  s.duration_s = 0.05;
  s.format = format;
  s.truth_rate_hz = 100.0;
  s.antenna_offsets_enu_m = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  return s;
}

TEST(Simulate, MemorySinkGetsWhatTheFilesHold) {
  const Scenario s = short_static(signals::SampleFormat::f32);
  MemorySink memory;
  const SimulationResult r = simulate(s, memory);
  EXPECT_TRUE(memory.finished);
  ASSERT_EQ(memory.shape.antennas, 2);
  EXPECT_EQ(r.samples, 100000);
  EXPECT_EQ(memory.streams[0].size(), 100000u);
  EXPECT_EQ(memory.streams[1].size(), 100000u);
  EXPECT_EQ(memory.truth_rows.size(), 5u);  // 0, 10, 20, 30, 40 ms
  EXPECT_FALSE(memory.in_view.empty());
  EXPECT_EQ(memory.in_view.size(), r.satellites.size());

  const auto dir = test::scratch_dir();
  const SimulationResult files = simulate_to_folder(s, dir, "# echo\n");
  ASSERT_EQ(files.sample_files.size(), 2u);
  for (int a = 0; a < 2; ++a) {
    std::ifstream in(files.sample_files[static_cast<std::size_t>(a)], std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(bytes.size(), memory.streams[static_cast<std::size_t>(a)].size() * sizeof(std::complex<float>));
    EXPECT_EQ(std::memcmp(bytes.data(), memory.streams[static_cast<std::size_t>(a)].data(), bytes.size()), 0) << a;
  }
  std::ifstream echo(dir / "scenario.toml");
  std::string line;
  std::getline(echo, line);
  EXPECT_EQ(line, "# echo");
}

TEST(Simulate, StaticTruthIsTheScenarioPosition) {
  const Scenario s = short_static(signals::SampleFormat::i8);
  MemorySink memory;
  simulate(s, memory);
  double x = 0, y = 0, z = 0;
  GeographicLib::Geocentric::WGS84().Forward(s.llh_deg_m[0], s.llh_deg_m[1], s.llh_deg_m[2], x, y, z);
  ASSERT_FALSE(memory.truth_rows.empty());
  for (const auto& row : memory.truth_rows) {
    EXPECT_NEAR((row.r_e_m - Eigen::Vector3d(x, y, z)).norm(), 0.0, 1e-6);
    EXPECT_NEAR(row.v_e_mps.norm(), 0.0, 1e-9);
    EXPECT_FALSE(row.q_nb.has_value());
  }
  EXPECT_EQ(memory.truth_rows[1].gps.week, s.gps_week);
  EXPECT_NEAR(memory.truth_rows[1].gps.tow_s - s.tow_s, 0.01, 1e-9);  // no clock offset: receiver time = GPS time
}

TEST(Simulate, InertialRunHandsOneImuRowPerInterval) {
  Scenario s;
  s.signal = false;
  s.trajectory_profile = "circle";
  s.trajectory_duration_s = 2.0;
  s.imu_rate_hz = 100.0;
  MemorySink memory;
  const SimulationResult r = simulate(s, memory);
  EXPECT_TRUE(memory.shape.inertial);
  EXPECT_EQ(memory.shape.antennas, 0);
  EXPECT_EQ(memory.imu_rows, 200u);
  EXPECT_EQ(r.imu_rows, 200u);
  ASSERT_EQ(memory.truth_rows.size(), 21u);  // 10 Hz over 2 s, both ends
  EXPECT_TRUE(memory.truth_rows.back().q_nb.has_value());
  EXPECT_NEAR(memory.truth_rows.back().t_s, 2.0, 1e-12);
}

TEST(Simulate, SideslipTurnsTheBodyFromItsTrackByTheGradientTimesLateralAcceleration) {
  Scenario s;
  s.signal = false;
  s.trajectory_profile = "circle";
  s.trajectory_duration_s = 20.0;
  s.imu_rate_hz = 100.0;
  s.sideslip_deg_per_mps2 = 0.5;
  MemorySink memory;
  simulate(s, memory);
  ASSERT_GT(memory.truth_rows.size(), 150u);
  // In the steady turn: the track's rate from the velocity's direction, and the body's lateral velocity.
  const GeographicLib::Geocentric& earth = GeographicLib::Geocentric::WGS84();
  auto body_velocity = [&](const TruthRow& row, Eigen::Vector3d* v_n) {
    double lat = 0, lon = 0, h = 0;
    earth.Reverse(row.r_e_m.x(), row.r_e_m.y(), row.r_e_m.z(), lat, lon, h);
    const double sl = std::sin(lat * M_PI / 180), cl = std::cos(lat * M_PI / 180);
    const double so = std::sin(lon * M_PI / 180), co = std::cos(lon * M_PI / 180);
    Eigen::Matrix3d C_ne;
    C_ne << -sl * co, -sl * so, cl, -so, co, 0.0, -cl * co, -cl * so, -sl;
    *v_n = C_ne * row.v_e_mps;
    return Eigen::Vector3d(row.q_nb->conjugate() * *v_n);
  };
  for (std::size_t i : {100u, 150u}) {
    Eigen::Vector3d v0, v1;
    body_velocity(memory.truth_rows[i - 1], &v0);
    const Eigen::Vector3d v_b = body_velocity(memory.truth_rows[i + 1], &v1);
    const double dt = memory.truth_rows[i + 1].t_s - memory.truth_rows[i - 1].t_s;
    const double track_rate = std::remainder(std::atan2(v1.y(), v1.x()) - std::atan2(v0.y(), v0.x()), 2 * M_PI) / dt;
    const double speed = v_b.head<2>().norm();
    const double beta = 0.5 * M_PI / 180 * speed * track_rate;  // rad: the gradient times the lateral acceleration
    ASSERT_GT(std::abs(beta), 0.01);
    EXPECT_NEAR(v_b.y() / speed, -std::sin(beta), 2e-3 * std::abs(beta)) << "row " << i;
  }
}

TEST(Simulate, StopRequestEndsTheRun) {
  Scenario s = short_static(signals::SampleFormat::i8);
  s.duration_s = 10.0;
  std::stop_source stop;
  stop.request_stop();
  MemorySink memory;
  const SimulationResult r = simulate(s, memory, stop.get_token());
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.samples, 0);
  EXPECT_TRUE(memory.finished);
}

TEST(Scenario, IsValidNamesTheKey) {
  std::string why;
  EXPECT_TRUE(Scenario{}.IsValid(&why)) << why;
  Scenario real = short_static(signals::SampleFormat::r8);
  EXPECT_FALSE(real.IsValid(&why));
  EXPECT_NE(why.find("signal.if_hz"), std::string::npos) << why;
  Scenario slip = short_static(signals::SampleFormat::i8);
  slip.cycle_slips.push_back({});
  slip.cycle_slips.back().antenna = 2;
  EXPECT_FALSE(slip.IsValid(&why));
  EXPECT_NE(why.find("antenna 2 does not exist (2 antennas)"), std::string::npos) << why;
  Scenario rate;
  rate.truth_rate_hz = 0.0;
  EXPECT_FALSE(rate.IsValid(&why));
  EXPECT_NE(why.find("output.truth_rate_hz"), std::string::npos) << why;
  Scenario polar;
  polar.trajectory_profile = "static";
  polar.trajectory_duration_s = 1.0;
  polar.llh_deg_m[0] = 89.5;
  EXPECT_FALSE(polar.IsValid(&why));
  EXPECT_NE(why.find("receiver.llh_deg_m"), std::string::npos) << why;
  EXPECT_FALSE(polar.IsValid(nullptr));
}

}  // namespace
}  // namespace ultratrack::sim
