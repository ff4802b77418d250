// `ultratrack receive --imu F --coupling ultra-tight --filter ekf|ukf [--ut-measurement iq|discriminator]`: the
// closed-loop ultra-tight driver (fusion/ultratight_integration.hpp) attached to the receiver engine through the
// vector-loop seam (receiver/vector_loop.hpp). Channels acquire and pull in as scalar while the tight integration
// of tools/receive_fusion.hpp aligns and runs; then the driver starts from the tight filter's state and, every
// 20 ms, (1) runs the INS to the vector epoch, (2) updates from each synchronised channel's latest correlation
// epoch (E/P/L I&Q normalised to unit noise, data bit removed by the prompt's sign, the replica that actually ran
// given explicitly), (3) predicts every satellite's replica and commands each channel's code (rate and phase jump)
// and carrier aiding (predicted Doppler; the channel's Costas PLL stays closed, so carrier phase stays continuous).
// A channel that loses lock coasts on the prediction and re-locks without acquisition. A weak channel whose PLL
// runs away from the predicted Doppler (CarrierRunawayMonitor) is left out of the filter, stepped back onto the
// prediction and its carrier phase flagged as slipped; one that keeps running away is released. Logs: ultratight.csv
// (per vector epoch and channel, keyed like tracking.csv by sample/time/prn) and nav.csv rows after the hand-over.
// Time: the driver's t_s is IMU time (GPS time minus the IMU time origin); its clock bias is against the receiver
// clock with the engine's clock jumps since the hand-over taken out. Units: s, m, m/s, Hz, chips.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "fusion/ultratight_integration.hpp"
#include "io/atomic_file.hpp"
#include "receive_fusion.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/vector_loop.hpp"

namespace ultratrack::tools {

struct ReceiveUltraTightOptions {
  double period_s = 0.020;          // vector epoch = the driver's period = the channels' 20 ms coherent epochs
  double handover_after_s = 2.0;    // the tight integration runs this long (IMU time) before the hand-over
  double max_jump_chips = 0.5;      // a channel joins / stays only while prediction and replica agree this well
  double max_coast_s = 30.0;        // a coasting channel is released (scalar, then lost) after this
  // Satellites above this elevation are commanded by the loop (INS-predicted replicas); only those above the
  // PVT's mask update the filter (fusion::UltraTightOptions::measurement_mask_rad). Between the two masks a
  // channel is "aided only": its replica follows the prediction, its correlations are not used.
  double command_mask_deg = 5.0;
  // Carrier runaway (a weak channel's aided PLL off its signal: CarrierRunawayMonitor). Below runaway_below_dbhz
  // (the channel's C/N0 estimate) the 1 s mean of replica carrier minus the filter's predicted Doppler is checked;
  // above runaway_hz the channel's correlations are left out of the filter until a later 1 s mean is within it,
  // its aiding steps once by minus that mean (its PLL back onto the prediction), and its carrier phase is reported
  // with loss of lock. Why 5 Hz: 1 s means of the 16-18 dB-Hz threshold runs' channels that never ran away
  // (13,702 channel-seconds, 27 runs, straight and circle): median 0.26 Hz, 99.9 % 3.41 Hz, largest 4.73 Hz;
  // the 11 runaway channels reached 12-137 Hz (docs/validation.md). Strong channels are left alone: there the PLL
  // follows the signal and the prediction, not the PLL, is what lags (10 g turn).
  double runaway_below_dbhz = 30.0;
  double runaway_average_s = 1.0;
  double runaway_hz = 5.0;
  // A channel still beyond runaway_hz in the 1 s after each of this many re-centrings in a row is not locked (its
  // PLL cannot hold the signal): the loop releases it (scalar, then lost) instead of keeping it "bit-synced".
  int runaway_max_recentres = 3;
};

// One channel's carrier against the filter's prediction: block means over average_s of (replica carrier - predicted
// Doppler), Hz. add() returns true when a block completes; mean_hz() is then its mean, recent_hz() the mean of the
// last kRecent epochs (where the PLL is now: a runaway PLL drifts by up to 10-25 Hz/s, so the 1 s mean lags the
// carrier by several Hz, and a step by it left cn0_18_file_0's PRN 18 running away for 58 s; on a locked channel
// at 18 dB-Hz one epoch's offset has a 0.46 Hz standard deviation: 9 channels, 26,456 epochs). reset() starts a new block
// (after a step of the aiding, a re-lock, or a strong epoch), skipping the next `settle` epochs (a pipelined
// command reaches the channel one period late).
class CarrierRunawayMonitor {
 public:
  bool add(double offset_hz, double period_s, double average_s) {
    if (!std::isfinite(offset_hz)) return false;
    if (settle_ > 0) {
      --settle_;
      return false;
    }
    sum_ += offset_hz;
    ++n_;
    recent_[next_++ % kRecent] = offset_hz;
    if (static_cast<double>(n_) * period_s < average_s - 1e-9) return false;
    mean_hz_ = sum_ / n_;
    sum_ = 0.0;
    n_ = 0;
    return true;
  }
  void reset(int settle = 0) {
    sum_ = 0.0;
    n_ = 0;
    next_ = 0;
    settle_ = settle;
  }
  double mean_hz() const { return mean_hz_; }
  double recent_hz() const {
    const int n = std::min(next_, kRecent);
    double s = 0.0;
    for (int k = 0; k < n; ++k) s += recent_[k];
    return n > 0 ? s / n : mean_hz_;
  }

 private:
  static constexpr int kRecent = 5;
  double sum_ = 0.0, mean_hz_ = 0.0;
  std::array<double, kRecent> recent_{};
  int n_ = 0, settle_ = 0, next_ = 0;
};

// The I&Q model's signal power of one channel from the prompt taps: running means of I_P^2 + Q_P^2 on the raw
// scale (taps / iq_scale, so the per-epoch noise normalisation does not move it), E[I_P^2 + Q_P^2] = A^2 + 2 in
// unit-noise taps. Two means: ~0.2 s (weight 0.1) follows a C/N0 step, ~1 s (weight 0.02) is the one used while
// the two agree; the slow one restarts from the fast one when they differ by more than 3 of the fast one's
// sigmas, sqrt((4 + 4 A^2) 0.1 / 1.9). Why 1 s: at 16 dB-Hz (A^2 = 1.59) the 0.2 s mean's A^2 has a standard
// deviation of 0.74 (46 %), and a C/N0 gate on it selects the epochs that read high (docs/validation.md).
struct PromptPowerAverage {
  double fast = NAN, slow = NAN;  // raw scale
  // p2_raw: this epoch's I_P^2 + Q_P^2 on the raw scale; scale2 = iq_scale^2. Returns A^2 on this epoch's unit-noise
  // scale from the epochs before this one (this epoch's own noise would otherwise enter its prediction), then
  // takes this epoch in. The first epoch uses itself.
  double update(double p2_raw, double scale2) {
    const double f = std::isfinite(fast) ? fast : p2_raw;
    double s = std::isfinite(slow) ? slow : f;
    const double fast_sigma = std::sqrt((4.0 + 4.0 * std::max(0.0, f * scale2 - 2.0)) * 0.1 / 1.9);
    if (std::abs(s - f) * scale2 > 3.0 * fast_sigma) s = f;
    fast = f + 0.1 * (p2_raw - f);
    slow = s + 0.02 * (p2_raw - s);
    return s * scale2 - 2.0;
  }
};

class ReceiveUltraTight final : public receiver::VectorLoop {
 public:
  // fusion: the tight pull-in (settings().coupling UltraTight); opens DIR/ultratight.csv (committed by finish).
  ReceiveUltraTight(ReceiveFusion& fusion, const receiver::ReceiverOptions& options, const std::filesystem::path& dir,
                    ReceiveUltraTightOptions ut = {});
  void attach(receiver::ReceiverEngine& engine);
  void update(const receiver::VectorEpochInput& epoch, std::span<receiver::VectorChannelCommand> commands) override;
  // Runs the INS to end_sample (the receiver's next unprocessed sample) and commits the log.
  void finish(std::int64_t end_sample);

  bool handed_over() const { return driver_.has_value(); }
  const fusion::UltraTightIntegration* driver() const { return driver_ ? &*driver_ : nullptr; }
  std::string summary_json() const;  // the "ultratight" member of summary.json
  std::string report() const;        // one line for stdout

 private:
  struct ChannelState {
    bool commanded = false;  // in vector mode under this loop (as of the last command)
    double coast_s = 0.0;
    bool ever = false;
    bool was_coasting = false;
    PromptPowerAverage prompt_power;  // the I&Q model's amplitude
    double aid_hz = NAN;  // the carrier aiding sent (changes by the INS propagation only)
    // The command sent last (vector): a pipelined loop's is still pending when the next inputs are taken.
    double sent_code_rate_chips_per_s = 0.0, sent_jump_chips = 0.0;
    // Carrier runaway (ReceiveUltraTightOptions::runaway_hz): the monitor, whether the channel is judged off its
    // signal now (left out of the filter, its phase flagged), and the aiding step still to send (Hz).
    CarrierRunawayMonitor runaway;
    bool runaway_off = false;
    double pending_step_hz = 0.0;
    int runaway_repeats = 0;     // re-centrings in a row each followed by a 1 s mean still beyond runaway_hz
    bool runaway_given_up = false;  // released for that; commanded again only after a new synchronisation
    double last_offset_hz = NAN;  // the latest epoch's replica minus predicted Doppler (ultratight.csv)
  };
  void start(const receiver::VectorEpochInput& epoch, double t_k);
  double imu_time(const receiver::VectorEpochInput& epoch, std::int64_t sample) const;
  void feed_imu_to(double t);
  void emit_nav();
  std::vector<fusion::ChannelCorrelation> correlations(const receiver::VectorEpochInput& epoch, double t_k);
  std::map<int, double> propagated_doppler_change();
  double predicted_doppler_at(int prn, double t_s) const;
  bool runaway_check(const receiver::VectorChannelInput& in, double t_mid_s);
  void command(const receiver::VectorEpochInput& epoch, double t_k, std::span<receiver::VectorChannelCommand> out,
               const std::map<int, double>& aid_change);

  ReceiveFusion& fusion_;
  receiver::ReceiverOptions options_;
  ReceiveUltraTightOptions ut_;
  io::AtomicFile log_;
  std::optional<fusion::UltraTightIntegration> driver_;
  std::vector<signals::Ephemeris> ephemerides_;  // the driver's: one per PRN at the hand-over, then every later one
  std::size_t ephemerides_seen_ = 0;             // VectorEpochInput::ephemerides entries already considered
  signals::GpsTime origin_;
  double corrections_at_start_s_ = 0.0;  // the engine's clock corrections at the hand-over
  double t_ins_ = 0.0;                   // the driver's INS time (IMU rows split at vector epochs)
  std::size_t next_imu_ = 0;
  bool period_open_ = false;
  std::map<int, fusion::ReplicaCommand> period_replicas_;  // the open period's replicas by PRN
  std::map<int, fusion::ReplicaCommand> previous_replicas_;  // the period's before it (predicted Doppler's slope)
  std::map<int, ChannelState> channels_;
  std::optional<double> first_integration_t_s_;
  std::optional<std::int64_t> last_sample_;
  double last_t_s_ = 0.0;
  // Counts.
  double handover_t_s_ = 0.0;
  std::int64_t handover_sample_ = 0;
  long long vector_epochs_ = 0, channel_epochs_ = 0, coasting_channel_epochs_ = 0, releases_ = 0, relocks_ = 0;
  long long measurements_ = 0, known_bits_ = 0, not_wiped_ = 0;
  long long runaway_recentres_ = 0, runaway_left_out_ = 0, runaway_releases_ = 0;
};

}  // namespace ultratrack::tools
