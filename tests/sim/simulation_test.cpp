// sim::simulate into memory: what a sink receives is what the files of `ultratrack simulate` hold (f32 samples bit
// for bit), static truth is the scenario's position, an inertial run hands one IMU row per interval, a stop
// request ends the run, and Scenario::IsValid names the key of what is wrong.
#include "sim/simulation.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
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
