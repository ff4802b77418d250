// SPDX-License-Identifier: GPL-3.0-or-later
// GNSS/INS integration fed by the running receiver (`receive --coupling loose|tight`, and ultra-tight's pull-in).
// GnssInsCoupler sits between the ReceiverEngine and the receiver's own observer (it forwards every call) and feeds
// fusion::GnssInsIntegration: loose: each PVT fix (position and Doppler velocity with the PVT's a-priori
// covariance) -> GnssFix; tight: each observation epoch (raw pseudoranges and Doppler; ephemerides from the
// navigation file and the decoded ones; the PVT's elevation mask, atmosphere switches and elevation/C/N0 sigma
// model) -> pseudorange and rate updates, also with fewer than four satellites. Loose or tight with odometer rows
// (ReceiveOptions::odometer): their speed windows as `fuse --odometer`'s VMS/NHC updates (pipelines/fuse.hpp), which
// bridge signal blockages; summary.json's fusion object then has fuse's "odometer" object. The INS starts after the
// alignment (static: levelling + gyrocompassing over the first seconds; motion: from the fixes' velocities; config: the
// configuration's attitude, position and velocity) and hands each solution (IMU position) to the sink's
// on_navigation. Time: IMU t_s on the time line of pipelines/imu_time_line.hpp; receiver clock jumps are taken out
// of the tight filter's pseudoranges and epoch times, so its clock states stay continuous. Units SI; angles in
// degrees only in the configuration and the JSON.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"
#include "ins/nav_state.hpp"
#include "pipelines/receive_options.hpp"
#include "pipelines/receive_sinks.hpp"
#include "receiver/receiver_engine.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::pipelines {

class GnssInsCoupler final : public receiver::ReceiverObserver {
 public:
  // options.coupling: kLoose, kTight or kUltraTight; imu: at least two rows; downstream: the receiver's observer;
  // sink: the navigation rows; nav_ephemerides: known before the run (the decoded ones come from the attached
  // engine). downstream and sink must outlive this.
  GnssInsCoupler(const ReceiveOptions& options, std::vector<ins::ImuIncrement> imu,
                 receiver::ReceiverObserver& downstream, ReceiveSink& sink,
                 std::vector<signals::Ephemeris> nav_ephemerides);
  ~GnssInsCoupler() override;

  // The engine whose decoded ephemerides and Klobuchar parameters the tight filter uses (must outlive this).
  void attach(const receiver::ReceiverEngine& engine);

  void on_tracking(const receiver::TrackingRecord& r) override;
  void on_acquisition(std::int64_t snapshot_first_sample, const std::vector<receiver::AcquisitionResult>& r) override;
  // Throw io::InputError naming the IMU data when an epoch's time lies outside it.
  void on_observations(const receiver::ObservationEpoch& epoch) override;
  void on_fix(const receiver::PvtSolution& fix, const receiver::ObservationEpoch& epoch) override;
  void on_antenna_phases(const receiver::AntennaPhaseEpoch& e) override;

  // Processes the last epoch and runs the INS to end_sample (the receiver's next unprocessed sample).
  void finish(std::int64_t end_sample);
  // The "fusion" member of summary.json (after finish).
  std::string summary_json() const;
  // One or two lines for stdout.
  std::string report() const;
  bool started() const;
  std::string not_started_reason() const;
  long long nav_rows() const;
  NavSigma final_sigma() const;

  // For the ultra-tight loop (pipelines/ultratight_loop.hpp), which starts from this tight integration: the
  // running integration (nullptr before the start), the IMU rows, the GPS time of IMU t_s = 0 (once known), the
  // latest observation epoch's sample and IMU time. hand_over(): from now on this object only forwards to the
  // receiver's observer (no more updates, no INS steps); navigation rows then come from write_nav.
  const fusion::GnssInsIntegration* integration() const;
  const std::vector<ins::ImuIncrement>& imu() const;
  const ReceiveOptions& options() const;
  std::optional<signals::GpsTime> imu_time_origin() const;
  std::optional<std::pair<std::int64_t, double>> last_epoch_time() const;
  void hand_over();
  bool handed_over() const;
  // Odometer aiding after the hand-over (the ultra-tight driver takes the speeds): the windows not yet handed to the
  // tight integration (each once; empty without --odometer), then, as the driver runs, what it made of them (its
  // odometer counters and estimate, the last time its satellite updates were accepted): summary.json's odometer
  // object covers both filters.
  std::vector<fusion::OdometerSpeed> take_odometer_windows();
  void record_handed_over_odometer(long long windows, const fusion::OdometerCounters& counters,
                                   const fusion::OdometerEstimate& estimate, double gnss_last_used_s);
  void write_nav(const ins::NavState& nav, const Eigen::Vector3d& sigma_pos_ned_m,
                 const Eigen::Vector3d& sigma_vel_n_mps, const Eigen::Vector3d& sigma_att_rad);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ultratrack::pipelines
