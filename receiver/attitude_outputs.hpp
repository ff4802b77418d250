// SPDX-License-Identifier: GPL-3.0-or-later
// The files of `ultratrack attitude`, fed as a ReceiverObserver: the position solution in DIR/position/ (the
// scalar receiver's ReceiverOutputs, as `receive` writes it), and in DIR: attitude.csv (one row per epoch with
// antenna phases: gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,
// fixed,ratio; angles nan while no validated fix), antenna_phases.csv (every antenna's phase per satellite and
// epoch with its flags) and summary.json (fix rate, time to first attitude, realtime factor, slips flagged).
// The time columns are the receiver's clock at the epoch (within the clock-jump threshold, 1 ms, of GPS time).
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/atomic_file.hpp"
#include "receiver/attitude_solver.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/receiver_outputs.hpp"

namespace ultratrack::receiver {

struct AttitudeStats {
  int epochs = 0;           // epochs with antenna phases
  int attitude_epochs = 0;  // with a valid attitude
  int fixed_epochs = 0;
  int new_fixes = 0;
  std::optional<std::int64_t> first_attitude_sample;
  std::optional<std::int64_t> first_epoch_sample;
  double sum_sats = 0.0;
  std::array<int, receiver::kMaxAntennas> slips{};     // slip flags raised, per antenna
  std::array<int, receiver::kMaxAntennas> unusable{};  // satellite-epochs without a usable phase
};

class AttitudeOutputs final : public receiver::ReceiverObserver {
 public:
  // Creates DIR and DIR/position; throws InputError when they cannot be written.
  AttitudeOutputs(const std::filesystem::path& dir, double fs_hz, double observation_interval_s,
                  receiver::AttitudeSolverOptions solver, std::vector<double> line_bias_cycles);

  void on_tracking(const receiver::TrackingRecord& r) override { position_.on_tracking(r); }
  void on_observations(const receiver::ObservationEpoch& e) override { position_.on_observations(e); }
  void on_fix(const receiver::PvtSolution& f, const receiver::ObservationEpoch& e) override { position_.on_fix(f, e); }
  void on_antenna_phases(const receiver::AntennaPhaseEpoch& epoch) override;

  // Commits every file; run describes the master input.
  void finish(const receiver::ReceiverEngine& engine, const receiver::RunDescription& run,
              const std::vector<std::string>& inputs);
  const AttitudeStats& stats() const { return stats_; }

 private:
  std::filesystem::path dir_;
  double fs_hz_;
  receiver::ReceiverOutputs position_;
  receiver::AttitudeSolver solver_;
  std::vector<double> line_bias_cycles_;
  io::AtomicFile attitude_, phases_;
  receiver::AntennaPhaseEpoch corrected_;  // reused
  AttitudeStats stats_;
};

}  // namespace ultratrack::receiver
