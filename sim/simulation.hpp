// SPDX-License-Identifier: GPL-3.0-or-later
// simulate(): runs a scenario and hands what it makes to a sink, in time order, so that a library user can
// simulate into memory and `ultratrack simulate` into files (sim/simulation_files.hpp):
//   begin       first, the run's shape (sample streams, inertial or not)
//   imu         each IMU interval's increments (inertial scenarios, before any sample), odometer samples
//   satellites  in view at the first sample (antenna 0): PRN, elevation, azimuth, C/N0, Doppler as the
//               receiver sees it (clock drift included, IF removed), code phase received at sample 0
//   events      the injected slips/blockages and C/N0 steps as the receiver should detect them
//   truth       rows at receiver times k / truth_rate (sample-exact); with [trajectory] per-antenna rows too
//   samples     blocks of <= 10 ms per antenna, sample-synchronous, in file units (2-bit formats: noise
//               sigma 2, the quantiser threshold at 1 sigma; others: RMS = full scale / 4)
//   finish      once, with the result (also after a stop)
// A stop request ends the run between blocks; the result says `interrupted` and holds what was made.
// Without a signal (inertial scenario without [signal]) truth rows are at GPS time since the start, with the
// deterministic clock model, and there are no samples, satellites or antenna rows.
#pragma once

#include <Eigen/Geometry>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stop_token>
#include <string>
#include <vector>

#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"
#include "ins/odometer.hpp"
#include "signals/gps_time.hpp"
#include "signals/if_synthesiser.hpp"
#include "sim/scenario.hpp"

namespace ultratrack::sim {

struct SimulationShape {
  int antennas = 0;       // sample streams; 0 without a signal
  bool inertial = false;  // IMU rows come; truth rows carry q_nb; antenna rows come with a signal
};

// Receiver truth: antenna 0 (static scenarios) or the IMU (inertial ones) at true GPS time `gps`.
struct TruthRow {
  double t_s = 0.0;  // receiver time: sample index / fs (GPS time since the start without a signal)
  signals::GpsTime gps;
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero(), v_e_mps = Eigen::Vector3d::Zero();  // ECEF
  double clock_bias_m = 0.0;  // c * (receiver clock - GPS time)
  double clock_drift_mps = 0.0;
  std::optional<Eigen::Quaterniond> q_nb;  // body to NED, inertial scenarios
};

struct AntennaTruthRow {
  double t_s = 0.0;
  int antenna = 0;
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero(), v_e_mps = Eigen::Vector3d::Zero();  // ECEF
};

// An injected event: kind "slip" or "blockage"; prn 0 = every satellite; end_s = when the signal is back
// (receiver time since the first sample).
struct AntennaEventRow {
  std::string kind;
  int antenna = 0, prn = 0;
  double start_s = 0.0, end_s = 0.0, cycles = 0.0;
};

// A C/N0 step for one transmitted satellite (below the mask too): the first sample with the new level.
struct Cn0StepRow {
  int antenna = 0, prn = 0;
  double start_s = 0.0;
  std::int64_t first_sample = 0;
  double first_sample_s = 0.0;
  double cn0_dbhz = 0.0;
};

struct SimulationProgress {
  enum class Stage { Imu, Signal } stage = Stage::Signal;
  int percent = 0;                     // multiples of 10
  double done_s = 0.0, total_s = 0.0;  // signal seconds (Signal)
  double wall_s = 0.0;
};

struct SimulationResult {
  std::string navigation;                          // the RINEX file or "nominal" ("" without a signal)
  std::vector<signals::SatelliteView> satellites;  // in view at the first sample
  int antennas = 0;
  std::int64_t samples = 0;  // per antenna
  double signal_s = 0.0;
  double wall_s = 0.0;
  double noise_sigma = 0.0;  // per output component, file units
  bool interrupted = false;
  std::size_t truth_rows = 0;
  // Inertial scenarios.
  std::size_t imu_rows = 0;
  double trajectory_duration_s = 0.0;
  ins::ImuErrors imu_turn_on;  // the unit's drawn turn-on errors
  double distance_m = 0.0;
  std::vector<std::filesystem::path> sample_files;  // simulate_to_folder() only
};

// Receives what simulate() makes; every method has an empty default.
class SimulationSink {
 public:
  virtual ~SimulationSink() = default;
  virtual void begin(const SimulationShape&) {}
  virtual void imu(const ins::ImuIncrement&) {}
  virtual void odometer(std::span<const ins::OdometerSample>) {}
  virtual void satellites(std::span<const signals::SatelliteView>) {}
  virtual void events(std::span<const AntennaEventRow>, std::span<const Cn0StepRow>) {}
  virtual void truth(const TruthRow&) {}
  virtual void antenna_truth(const AntennaTruthRow&) {}
  // The satellites transmitted at a truth row's sample (antenna 0): Doppler and code phase there, the truth a
  // tracking channel is judged against (pipelines/truth_lock_rule.hpp).
  virtual void satellite_truth(std::int64_t sample, double t_s, std::span<const signals::SatelliteView> in_view) {
    (void)sample, (void)t_s, (void)in_view;
  }
  virtual void samples(int antenna, std::span<const std::complex<float>> block) { (void)antenna, (void)block; }
  virtual void progress(const SimulationProgress&) {}
  virtual void finish(const SimulationResult&) {}
};

// Throws io::InputError (invalid scenario: Scenario::IsValid; unreadable RINEX, trajectory or segment file;
// unusable synthesiser options) naming the file.
SimulationResult simulate(const Scenario& scenario, SimulationSink& sink, std::stop_token stop = {});

}  // namespace ultratrack::sim
