// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver's files in one output folder, fed as a ReceiverObserver: solution.csv, solution.nmea,
// solution.kml (solution_writer.hpp), observations.rnx (RINEX 3.04 obs), tracking.csv (one row per channel
// every tracking_record_interval_s), and at finish() navigation.rnx (RINEX 3.04 nav from the decoded
// ephemerides) and summary.json (receiver_summary.hpp). Every file is an AtomicFile: none appears under
// its final name unless finish() completes, so a failed run leaves no partial outputs.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

#include "io/atomic_file.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/receiver_summary.hpp"
#include "receiver/rinex_obs_writer.hpp"
#include "receiver/solution_writer.hpp"

namespace ultratrack::receiver {

class ReceiverOutputs final : public ReceiverObserver {
 public:
  // Creates the folder when missing; throws signals::InputError when it cannot be written.
  ReceiverOutputs(const std::filesystem::path& dir, double fs_hz, double observation_interval_s);

  void on_tracking(const TrackingRecord& r) override;
  void on_observations(const ObservationEpoch& epoch) override;
  void on_fix(const PvtSolution& fix, const ObservationEpoch& epoch) override;

  // Writes navigation.rnx and summary.json and commits every file.
  void finish(const ReceiverEngine& engine, const RunDescription& run);
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  double fs_hz_;
  SolutionCsvWriter solution_;
  std::optional<NmeaWriter> nmea_;  // made at the first fix, when the leap-second count is known
  KmlWriter kml_;
  RinexObsWriter obs_;
  io::AtomicFile tracking_;
  Eigen::Vector3d sum_r_e_m_ = Eigen::Vector3d::Zero();
  int fixes_ = 0;
};

}  // namespace ultratrack::receiver
