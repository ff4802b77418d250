// SPDX-License-Identifier: GPL-3.0-or-later
// pipelines::Receiver in process: `simulate` writes 16 s of a static receiver at 45 dB-Hz (12 satellites, the
// shipped brdc3540 file, 2 MHz i8); the receiver starts hot. With vector coupling every filter epoch reaches the
// sink, 20 ms apart, and the summary's counts are those of the sink's epochs; the observer sees the fixes the
// summary counts; no navigation or ultra-tight epoch is sent. A stop requested before the run processes nothing
// and says so.
// ReceiveOptions::IsValid names what does not fit together.
#include "pipelines/receiver_pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <stop_token>
#include <string>
#include <vector>

#include "config/scenario_toml.hpp"
#include "sim/simulation_files.hpp"
#include "support/test_data.hpp"
#include "support/vector_carrier_scenarios.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

struct RecordingSink final : pipelines::ReceiveSink {
  std::vector<std::int64_t> vector_samples;
  long long vector_epochs = 0, vector_channel_epochs = 0, coasting = 0, navigation = 0, ultratight = 0;
  void on_navigation(const ins::NavState&, const pipelines::NavSigma&) override { ++navigation; }
  void on_vector_epoch(const fusion::VectorEpochLog& e) override {
    vector_samples.push_back(e.sample);
    vector_epochs += e.vector > 0;
    vector_channel_epochs += e.vector;
    for (const auto& c : e.channels) coasting += c.vector && c.coasting;
  }
  void on_ultratight_epoch(const pipelines::UltraTightEpochLog&) override { ++ultratight; }
};

struct CountingObserver final : receiver::ReceiverObserver {
  int fixes = 0, epochs = 0;
  void on_observations(const receiver::ObservationEpoch&) override { ++epochs; }
  void on_fix(const receiver::PvtSolution&, const receiver::ObservationEpoch&) override { ++fixes; }
};

constexpr double kFs = 2.0e6;

pipelines::ReceiveOptions options(pipelines::Coupling coupling) {
  pipelines::ReceiveOptions o;
  o.coupling = coupling;
  o.receiver.fs_hz = kFs;
  o.receiver.pvt.troposphere = false;
  o.receiver.reference_week = ultratrack::test::shipped_nav_week;
  o.receiver.reference_week_is_signal_week = true;
  return o;
}

}  // namespace

TEST(ReceiverPipeline, VectorEpochsReachTheSinkAndTheSummaryCountsThem) {
  const std::filesystem::path brdc = ultratrack::test::shipped_nav_file();
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "static.toml") << ultratrack::test::vector_carrier_scenario(brdc, 100.0, 16.0, "");
  const auto sim = dir / "sim";
  sim::simulate_to_folder(config::read_scenario(dir / "static.toml"), sim, "");
  const signals::RinexNavData nav = signals::read_rinex_nav(brdc);
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = kFs;

  RecordingSink sink;
  CountingObserver observer;
  pipelines::Receiver rx(options(pipelines::Coupling::kVector), {}, nav, observer, sink);
  receiver::SampleSource source(sim / "antenna0.i8.bin", signals::SampleFormat::i8, source_options);
  int blocks = 0;
  rx.run(source, source.total_samples(), std::stop_token{}, [&](const receiver::ReceiverEngine&) { ++blocks; });
  const pipelines::ReceiveSummary s = rx.finish();
  fs::remove(sim / "antenna0.i8.bin");

  EXPECT_EQ(blocks, 320);  // 16 s in 50 ms blocks
  EXPECT_NEAR(s.processed_s, 16.0, 1e-9);
  EXPECT_FALSE(s.interrupted);
  EXPECT_TRUE(s.satellites_found);
  EXPECT_GE(s.satellites_tracked, 8);
  EXPECT_GT(s.fixes, 0);
  EXPECT_EQ(s.fixes, observer.fixes);
  EXPECT_GT(s.ttff_s, 0.0);
  EXPECT_NEAR(s.mean_lat_deg, 35.274016, 1e-4);
  EXPECT_NEAR(s.mean_lon_deg, 137.013759, 1e-4);
  EXPECT_NEAR(s.mean_height_m, 100.0, 10.0);

  ASSERT_GT(sink.vector_epochs, 0);
  for (std::size_t k = 1; k < sink.vector_samples.size(); ++k)
    ASSERT_EQ(sink.vector_samples[k] - sink.vector_samples[k - 1], std::llround(0.02 * kFs)) << "epoch " << k;
  EXPECT_EQ(s.vector_epochs, sink.vector_epochs);
  EXPECT_EQ(s.vector_channel_epochs, sink.vector_channel_epochs);
  EXPECT_EQ(s.coasting_channel_epochs, sink.coasting);
  EXPECT_GE(s.vector_filter_starts, 1);
  EXPECT_EQ(sink.navigation, 0);
  EXPECT_EQ(sink.ultratight, 0);
  EXPECT_FALSE(s.navigation_started);
  EXPECT_NE(s.summary_json.find("\"vector\": {\"carrier\": \"aided-pll\""), std::string::npos);
  ASSERT_EQ(s.report.size(), 1u);
  EXPECT_NE(s.report[0].find("vector tracking"), std::string::npos);
}

TEST(ReceiverPipeline, AStopRequestedBeforeTheRunProcessesNothing) {
  const auto dir = ultratrack::test::scratch_dir();
  { std::ofstream(dir / "zeros.i8.bin", std::ios::binary) << std::string(400000, '\0'); }  // 0.1 s at 2 MHz
  RecordingSink sink;
  CountingObserver observer;
  pipelines::Receiver rx(options(pipelines::Coupling::kScalar), {}, {}, observer, sink);
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = kFs;
  receiver::SampleSource source(dir / "zeros.i8.bin", signals::SampleFormat::i8, source_options);
  std::stop_source stop;
  stop.request_stop();
  rx.run(source, source.total_samples(), stop.get_token());
  const pipelines::ReceiveSummary s = rx.finish();
  EXPECT_TRUE(s.interrupted);
  EXPECT_EQ(s.processed_s, 0.0);
  EXPECT_FALSE(s.satellites_found);
  EXPECT_TRUE(s.summary_json.empty());
  EXPECT_TRUE(s.report.empty());
  EXPECT_EQ(sink.vector_samples.size() + sink.navigation + sink.ultratight, 0u);
}

TEST(ReceiveOptions, IsValidNamesWhatDoesNotFitTogether) {
  std::string why;
  EXPECT_TRUE(options(pipelines::Coupling::kScalar).IsValid(&why));
  EXPECT_TRUE(options(pipelines::Coupling::kLoose).IsValid(nullptr));

  auto carrier = options(pipelines::Coupling::kScalar);
  carrier.vector_carrier = fusion::VectorCarrier::kPll;
  EXPECT_FALSE(carrier.IsValid(&why));
  EXPECT_NE(why.find("--coupling vector"), std::string::npos) << why;
  carrier.coupling = pipelines::Coupling::kVector;
  EXPECT_TRUE(carrier.IsValid(&why));

  auto config = options(pipelines::Coupling::kTight);
  config.align = pipelines::AlignMode::Config;
  EXPECT_FALSE(config.IsValid(&why));
  EXPECT_NE(why.find("attitude_deg"), std::string::npos) << why;
  config.navigation.attitude_deg = Eigen::Vector3d::Zero();
  EXPECT_TRUE(config.IsValid(&why));

  auto preset = options(pipelines::Coupling::kUltraTight);
  preset.navigation.imu_preset = "nonesuch";
  EXPECT_FALSE(preset.IsValid(&why));
  EXPECT_NE(why.find("nonesuch"), std::string::npos) << why;

  auto origin = options(pipelines::Coupling::kLoose);
  origin.imu_time_origin = {pipelines::ImuTimeOrigin::Kind::Tow, 604800.0};
  EXPECT_FALSE(origin.IsValid(&why));

  auto receiver = options(pipelines::Coupling::kScalar);
  receiver.receiver.channels = 0;
  EXPECT_FALSE(receiver.IsValid(&why));
  EXPECT_FALSE(why.empty());

  CountingObserver observer;
  RecordingSink sink;
  EXPECT_THROW(pipelines::Receiver(receiver, {}, {}, observer, sink), std::invalid_argument);
}

TEST(Coupling, NamesRoundTrip) {
  for (const auto c : {pipelines::Coupling::kScalar, pipelines::Coupling::kVector, pipelines::Coupling::kLoose,
                       pipelines::Coupling::kTight, pipelines::Coupling::kUltraTight})
    EXPECT_EQ(pipelines::coupling_from_string(pipelines::to_string(c)), c);
  EXPECT_EQ(pipelines::coupling_from_string("none"), pipelines::Coupling::kScalar);
  EXPECT_FALSE(pipelines::coupling_from_string("ultratight"));
}
