// `ultratrack receive --imu imu.csv --coupling loose|tight`: GNSS/INS integration fed by the running receiver.
// ReceiveFusion sits between the ReceiverEngine and the receiver's own outputs (it forwards every call) and feeds
// fusion::GnssInsIntegration: loose: each PVT fix (position and Doppler velocity with the PVT's a-priori
// covariance) -> GnssFix; tight: each observation epoch (raw pseudoranges and Doppler; ephemerides from --nav and
// the decoded ones; the PVT's elevation mask, atmosphere switches and elevation/C/N0 sigma model) -> pseudorange
// and rate updates, also with fewer than four satellites. The INS starts after the alignment (--align static:
// levelling + gyrocompassing over the first seconds; motion: from the fixes' velocities; config: the
// configuration's attitude, position and velocity) and writes DIR/nav.csv in `fuse`'s columns (IMU position).
// Time: the IMU's t_s is seconds of GPS time since an origin (--imu-time-origin): sample0 = the GPS time of the
// input file's first sample (what `simulate` writes), tow = t_s is the GPS time of week, or a number = the GPS
// time of week at t_s = 0. Receiver clock jumps are taken out of the tight filter's pseudoranges and epoch times,
// so its clock states stay continuous. Units SI; angles in degrees only in the configuration and the JSON.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fuse_config.hpp"
#include "fuse_run.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "fusion/ultratight_integration.hpp"
#include "ins/nav_state.hpp"
#include "receiver/receiver_engine.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::tools {

// --coupling of `receive`: scalar (per-channel loops; "none" is accepted too), vector (tools/receive_vector.hpp),
// loose or tight (GNSS/INS integration, this file), ultra-tight (tools/receive_ultratight.hpp: the tight integration
// of this file pulls in, then the ultra-tight loop takes the channels over). A new kind of coupling is one more value here and in
// parse_receive_coupling / to_string.
enum class ReceiveCoupling { Scalar, Vector, Loose, Tight, UltraTight };
ReceiveCoupling parse_receive_coupling(const std::string& text);  // InputError for an unknown value
std::string to_string(ReceiveCoupling coupling);

struct ImuTimeOrigin {
  enum class Kind { Sample0, WeekStart, Tow } kind = Kind::Sample0;
  double tow_s = 0.0;  // Kind::Tow
};

// The command-line text of the fusion options (parsed by parse_receive_fusion).
struct ReceiveFusionArgs {
  std::string imu, coupling = "scalar", filter, align, config, time_origin, ut_measurement;
  bool ut_serial = false;  // --ut-serial
  // --ut-pipelined[=true|false]: names the default (older command lines); =false selects the serial loop.
  bool ut_pipelined = true;
  const CLI::Option* ut_pipelined_option = nullptr;  // set by add_receive_fusion_options: was it given?
};
void add_receive_fusion_options(CLI::App* cmd, ReceiveFusionArgs& args);

struct ReceiveFusionSettings {
  ReceiveCoupling coupling = ReceiveCoupling::Scalar;
  fusion::FilterKind filter = fusion::FilterKind::Ekf;
  AlignMode align = AlignMode::Motion;
  FuseConfig config;  // `fuse`'s configuration keys (--fusion-config)
  std::string imu_file;
  ImuTimeOrigin time_origin;
  fusion::UltraTightForm ut_form = fusion::UltraTightForm::Iq;  // --ut-measurement iq|discriminator
  // Ultra-tight only. Pipelined (the default): the loop runs beside the next block's correlation
  // (receiver::ReceiverEngine::set_vector_loop), its commands one 20 ms vector epoch later, as a real-time
  // receiver runs its navigation filter concurrently with the correlators. --ut-serial: the loop runs on the
  // caller between blocks, its commands at the epoch that produced them (slower with 2 or more threads).
  bool ut_pipelined = true;
};

// Checks and parses the options (InputError naming the option or the configuration file). Nothing for
// --coupling scalar or vector (then no other fusion option may be given).
std::optional<ReceiveFusionSettings> parse_receive_fusion(const ReceiveFusionArgs& args);
// The IMU file: InputError naming it when missing, malformed, non-finite or shorter than two rows.
std::vector<ins::ImuIncrement> read_receive_imu(const ReceiveFusionSettings& settings);

class ReceiveFusion final : public receiver::ReceiverObserver {
 public:
  // Opens DIR/nav.csv (committed by commit()). receiver_options: the PVT's mask, atmosphere and sigma settings
  // and the sample rate; nav_ephemerides: the --nav file's (the decoded ones come from the attached engine).
  ReceiveFusion(const ReceiveFusionSettings& settings, std::vector<ins::ImuIncrement> imu,
                receiver::ReceiverObserver& downstream, const std::filesystem::path& out_dir,
                const receiver::ReceiverOptions& receiver_options, std::vector<signals::Ephemeris> nav_ephemerides);
  ~ReceiveFusion() override;

  // The engine whose decoded ephemerides and Klobuchar parameters the tight filter uses (must outlive this).
  void attach(const receiver::ReceiverEngine& engine);

  void on_tracking(const receiver::TrackingRecord& r) override;
  void on_acquisition(std::int64_t snapshot_first_sample, const std::vector<receiver::AcquisitionResult>& r) override;
  // Throw io::InputError naming the IMU file when an epoch's time lies outside the IMU data.
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
  void commit();  // nav.csv

  // For the ultra-tight loop (tools/receive_ultratight.hpp), which starts from this tight integration: the
  // running integration (nullptr before the start), the IMU rows, the GPS time of IMU t_s = 0 (once known), the
  // latest observation epoch's sample and IMU time. hand_over(): from now on this object only forwards to the
  // receiver's outputs (no more updates, no INS steps); nav.csv rows then come from write_nav.
  const fusion::GnssInsIntegration* integration() const;
  const std::vector<ins::ImuIncrement>& imu() const;
  const ReceiveFusionSettings& settings() const;
  std::optional<signals::GpsTime> imu_time_origin() const;
  std::optional<std::pair<std::int64_t, double>> last_epoch_time() const;
  void hand_over();
  bool handed_over() const;
  void write_nav(const ins::NavState& nav, const Eigen::Vector3d& sigma_pos_ned_m, const Eigen::Vector3d& sigma_vel_n_mps,
                 const Eigen::Vector3d& sigma_att_rad);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ultratrack::tools
