// SPDX-License-Identifier: GPL-3.0-or-later
// Vector tracking without an IMU: an 8-state EKF (ECEF position, velocity, receiver clock bias and drift, in m,
// m/s, m, m/s) with a constant-velocity process model (white acceleration) and a crystal clock model (Allan h0,
// h-2), updated with every channel's code discriminator as a pseudorange error and its carrier Doppler as a
// pseudorange rate, chi-square gated, noise from each channel's C/N0. From the state it predicts each channel's
// replica (code rate incl. code Doppler, code phase at the next epoch start, carrier Doppler) from the
// satellite's broadcast orbit and clock, and commands the channels through receiver::VectorLoop.
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

#include "fusion/ekf.hpp"
#include "fusion/false_lock_monitor.hpp"
#include "fusion/nis_release.hpp"
#include "fusion/tight_measurements.hpp"
#include "fusion/vector_carrier_phase.hpp"
#include "receiver/vector_loop.hpp"

namespace ultratrack::fusion {

namespace vx {  // state indices
inline constexpr int kPos = 0, kVel = 3, kBias = 6, kDrift = 7;
}  // namespace vx
using VectorState = StateVector<8>;

// Closed-form discriminator variances for one coherent integration of T seconds at carrier-to-noise density
// cn0_hz (ratio-Hz). Both are the loop-jitter formulas of Kaplan & Hegarty (Understanding GPS, 2nd ed., ch. 5:
// DLL sigma^2 = Bn d / (2 C/N0) (1 + 2 / ((2 - d) T C/N0)) chips^2 for the noncoherent early-minus-late
// discriminator with E-L spacing d chips; PLL sigma^2 = Bn / (C/N0) (1 + 1 / (2 T C/N0)) rad^2 for the Costas
// arctangent) with one independent discriminator output per T, i.e. Bn = 1 / (2 T).
double code_discriminator_variance_chips2(double cn0_hz, double t_s, double spacing_chips);
double costas_phase_variance_cycles2(double cn0_hz, double t_s);
// Small-error gain of the channels' normalised early-minus-late envelope DLL (receiver::dll_nelp_chips, E-L
// spacing 1 chip) for one coherent integration of T seconds: E[output] = gain x code error near zero. With unit
// noise per I and Q, E and L have amplitude s = sqrt(2 C/N0 T) / 2 at zero error, and to first order
// (ratio of the means) gain = s R'(s) / E[R](s) for the Rician envelope R:
//   gain = 2 nu (I0(nu) + I1(nu)) / ((1 + 2 nu) I0(nu) + 2 nu I1(nu)),  nu = s^2 / 4 = C/N0 T / 8,
// 1 at high C/N0, 0.62 / 0.49 / 0.36 / 0.25 at 24 / 22 / 20 / 18 dB-Hz and 20 ms (Monte Carlo of the
// discriminator: 0.63 / 0.47 / 0.33 / 0.25, VectorTracking.WeakSignalDiscriminatorVariancesAgainstMonteCarlo).
// The noise's own mean in the denominator is what shrinks it: below ~26 dB-Hz the discriminator reports about
// half of the code error, and a filter taking its output at face value corrects half as much as it believes.
double code_discriminator_gain(double cn0_hz, double t_s);

// White-acceleration PSD per ECEF axis and the clock's power-law coefficients (fractional frequency).
struct VectorProcessNoise {
  double accel_psd_m2ps3 = 2.0;  // ~1.4 m/s^2 rms over 1 s: a road or air vehicle's manoeuvres
  // TCXO (Brown & Hwang, Introduction to Random Signals and Applied Kalman Filtering, table 9.2 / Groves 9.4.2):
  // bias PSD c^2 h0 / 2, drift PSD c^2 2 pi^2 h-2.
  double h0 = 2e-19;
  double h_minus2 = 2e-20;
};

// xdot = F x + G w: r' = v, v' = a, b' = d + w_b, d' = w_d (exact discretisation, Ekf's Van Loan).
struct VectorProcessModel {
  static constexpr int kNoiseSize = 5;
  VectorProcessNoise noise;
  VectorState f(const VectorState& x, double dt) const;
  StateMatrix<8> F(const VectorState&) const;
  Eigen::Matrix<double, 8, 5> G(const VectorState&) const;
  Eigen::Matrix<double, 5, 5> Qc() const;
};

// The state propagated by dt seconds (constant velocity and drift).
VectorState propagate(const VectorState& x, double dt);

// One pseudorange (rate = false) or pseudorange-rate (rate = true) measurement of a satellite (observable
// prepared for the measurement's receive time), taken delta_s seconds before the state's time: the state is
// propagated back by delta_s inside h. z in m or m/s, sigma its 1-sigma.
class VectorRangeMeasurement {
 public:
  VectorRangeMeasurement(const SatelliteObservable& sat, double delta_s, bool rate, double z, double sigma);
  Eigen::VectorXd z() const { return Eigen::VectorXd::Constant(1, z_); }
  Eigen::VectorXd h(const VectorState& x) const;
  MeasurementJacobian<8> H(const VectorState& x) const;
  Eigen::MatrixXd R() const { return Eigen::MatrixXd::Constant(1, 1, sigma_ * sigma_); }

 private:
  SatelliteObservable sat_;
  double delta_s_;
  bool rate_;
  double z_, sigma_;
};

// The replica a state implies for a satellite: pseudorange, its rate, and the code rate and carrier Doppler at
// baseband (code rate 1.023 MHz (1 - rate / c), Doppler -rate / lambda_L1).
struct ReplicaPrediction {
  double pseudorange_m = 0.0;
  double pseudorange_rate_mps = 0.0;
  double code_rate_chips_per_s = 0.0;
  double doppler_hz = 0.0;
};
ReplicaPrediction predict_replica(const SatelliteObservable& sat, const VectorState& x);

// How the filter treats the vector channels' carriers: kAidedPll, each channel's Costas PLL closes its carrier,
// aided by the predicted Doppler's changes (carrier_aiding); kFll, the filter closes it (a vector FLL): every
// vector epoch each channel's carrier NCO is commanded to the predicted Doppler at the middle of its next epoch,
// and the channel's frequency discriminator (receiver/vector_frequency_discriminator.hpp) is the pseudorange-rate
// measurement that keeps the prediction honest (filter-driven as kAidedPll's channels: their presence test judges
// lock, and with the bits known (--nav) the discriminator has them wiped, which keeps it unbiased down to ~18
// dB-Hz where the Costas form reads the prediction; 90 % tracking threshold 15.8 dB-Hz on the issue-7 files against
// 25.6 for kAidedPll, docs/validation.md); kPll, a vector PLL (fusion/vector_carrier_phase.hpp): as kFll, plus
// per-channel carrier states in the filter, updated by each channel's Costas discriminator, that add a phase jump
// and a frequency residual to every command, so that the replica stays phase-locked with no loop in the channel
// (the pseudorange-rate rows are then phase-locked delta ranges); a channel whose phase lock fails is commanded as
// in kFll (and re-enters after VectorPllOptions::relock_after_s).
enum class VectorCarrier { kAidedPll, kFll, kPll };
const char* to_string(VectorCarrier carrier);
// "aided-pll", "fll" or "pll" (to_string's names); nothing for another.
std::optional<VectorCarrier> vector_carrier_from_string(std::string_view text);

struct VectorTrackingOptions {
  VectorProcessNoise process;
  GateOptions gate{true, 0.9999};
  double min_cn0_dbhz = 25.0;  // channels below are neither used nor commanded
  double elevation_mask_rad = 5.0 * 3.14159265358979 / 180.0;
  bool ionosphere = true, troposphere = true;        // as the receiver's PVT (the filter's clock absorbs the rest)
  double code_spacing_chips = 1.0;                   // E-L spacing of the channels (2 x early_late_offset_chips)
  bool use_doppler = true;                           // pseudorange-rate rows
  bool carrier_aiding = true;                        // the predicted Doppler's changes aid each vector channel's PLL
  VectorCarrier carrier = VectorCarrier::kAidedPll;  // kFll, kPll: the filter commands the carrier NCOs
  VectorPllOptions pll;                              // kPll's per-channel carrier states
  int join_after_updates = 25;  // accepted pseudorange updates (20 ms each) before a channel is commanded
  int max_rejections = 10;      // consecutive gate rejections that return a channel to scalar
  double max_jump_chips = 0.3;  // a prediction further than this from the replica returns it to scalar
  int min_satellites = 4;       // fewer accepted channels for reset_after_s restarts the filter
  double reset_after_s = 1.0;
  // Coasting: a channel in vector mode whose signal fades (C/N0 below min_cn0_dbhz, or the channel reports
  // coasting) keeps being commanded from the prediction, without measurement updates, for at most max_coast_s
  // and while the predicted pseudorange's 1-sigma (from the covariance) stays below max_coast_sigma_chips; then
  // it is dropped (a coasting channel is then released to re-acquisition). While channels coast, a filter with
  // fewer than min_satellites updates propagates instead of restarting.
  double max_coast_s = 30.0;
  double max_coast_sigma_chips = 0.5;
  // Channels in vector mode are filter-driven (receiver::VectorChannelCommand::filter_driven, as ultra-tight's):
  // the channel's scalar loss test (C/N0 below min_cn0_dbhz or PLI below 0.3 for 0.3 s) gives way to the presence
  // test (1 s windows, 12 dB-Hz), its PLL sums N x 20 ms with the known bits wiped (pure PLL; kFll / kPll: no
  // channel PLL, the known bits wipe the frequency discriminator's epochs instead), its time tag is held, and its
  // epochs reach the filter without the per-epoch fade gate below 30 dB-Hz. (kPll's phase arcs keep their own lock
  // test: a weak filter-driven channel stays usable, and its arc ends when that test fails.) Such a channel's
  // discriminators keep updating the filter below min_cn0_dbhz (down to whatever the presence test keeps), with
  // their variances from the lower of the channel's 0.2 s C/N0 and its weak_cn0_average_s running mean (linear):
  // at 22 dB-Hz the 0.2 s estimates span 16-25 dB-Hz (threshold runs) and the DLL variance grows as 1 / C/N0^2
  // there, so an estimate reading high would give the gate far too small a sigma. Joining (join_after_updates) still
  // needs min_cn0_dbhz. false: vector channels keep the scalar loss test and are used only above min_cn0_dbhz.
  bool filter_driven = true;
  double weak_cn0_average_s = 1.0;
  // False PLL lock of a weak channel (running mean C/N0 below false_lock_below_dbhz): the mean over
  // doppler_bias_average_s of its measured minus predicted Doppler (fusion/false_lock_monitor.hpp, kRunning). Above
  // doppler_bias_hz its Doppler rows are left out; above false_lock_hz (after at least one averaging time) its carrier
  // aiding steps once by that mean, putting the PLL back on the predicted frequency. Locked channels of the threshold
  // runs kept 15 s means within 2 Hz (the PLL's own noise averaged, and the prediction's error); false locks sat at
  // 20-25 Hz. Strong channels are left alone: in a 2 g step turn the prediction, not the PLL, is what lags.
  double false_lock_below_dbhz = 35.0;
  double doppler_bias_average_s = 0.5;
  double doppler_bias_hz = 4.0;
  double false_lock_hz = 7.0;
  // Windowed NIS (fusion/nis_release.hpp) of each channel's rows (one entry per epoch: its pseudorange row and,
  // when used, its rate row). A channel far outside its band is released to its scalar loops and its rows are left
  // out until it loses synchronisation; the channels' pooled windows outside their band re-open the filter's
  // covariance (to at least its initial sigmas). The gate probability is gate.probability's.
  NisReleaseOptions nis;
  double initial_sigma_pos_m = 10.0, initial_sigma_vel_mps = 0.5;
  double initial_sigma_bias_m = 10.0, initial_sigma_drift_mps = 0.5;
};

// One channel's view of a vector epoch, for logs (vector.csv) and tests.
struct VectorChannelLog {
  int prn = 0;
  bool vector = false;                      // commanded in vector mode this epoch
  bool pr_used = false, rate_used = false;  // measurement updates accepted
  double pr_innovation_m = NAN, rate_innovation_mps = NAN;
  double pr_sigma_m = NAN, rate_sigma_mps = NAN;
  double measured_doppler_hz = NAN, predicted_doppler_hz = NAN;
  double replica_code_rate_chips_per_s = NAN, predicted_code_rate_chips_per_s = NAN;
  double code_jump_chips = NAN;
  double cn0_dbhz = NAN;
  bool coasting = false;               // commanded from the prediction alone (faded or coasting)
  double coast_s = 0.0;                // time since it last had a usable measurement while commanded
  double predicted_sigma_chips = NAN;  // 1-sigma of the predicted pseudorange
  // kPll: the channel's carrier phase closed by the filter this epoch (false: not in kPll, or fallen back to the
  // FLL); its discriminator (cycles), gated innovation, state 1-sigma, frequency residual nu (Hz), lock indicator,
  // loop noise bandwidth of the latest gains (Hz), the commanded phase jump (cycles). In every mode, for truth
  // comparisons: the replica's carrier phase (cycles) at the middle of the epoch measured (measurement_sample).
  bool phase_tracking = false;
  double phase_disc_cycles = NAN, phase_innovation_cycles = NAN, phase_sigma_cycles = NAN, phase_nu_hz = NAN;
  double phase_lock = NAN, phase_bn_hz = NAN, phase_jump_cycles = NAN;
  std::int64_t measurement_sample = 0;
  double replica_phase_mid_cycles = NAN;
};
struct VectorEpochLog {
  std::int64_t sample = 0;
  signals::GpsTime receive_time;
  VectorState x = VectorState::Zero();
  Eigen::Matrix<double, 8, 1> sigma = Eigen::Matrix<double, 8, 1>::Zero();
  int used = 0;    // channels with an accepted pseudorange
  int vector = 0;  // channels commanded
  std::vector<VectorChannelLog> channels;
};

class VectorTrackingFilter final : public receiver::VectorLoop {
 public:
  explicit VectorTrackingFilter(const VectorTrackingOptions& options = {});

  void update(const receiver::VectorEpochInput& epoch, std::span<receiver::VectorChannelCommand> commands) override;

  bool initialised() const { return ekf_.has_value(); }
  const VectorTrackingOptions& options() const { return opt_; }
  const VectorState& x() const { return ekf_->x(); }
  const StateMatrix<8>& P() const { return ekf_->P(); }
  int resets() const { return resets_; }
  int initialisations() const { return initialisations_; }
  // Carrier aiding steps given to weak channels found on a false PLL lock (VectorTrackingOptions::false_lock_hz).
  int frequency_resets() const { return frequency_resets_; }
  // kPll: phase arcs started (hand-overs and re-entries) and phase locks lost (fallbacks to the FLL).
  int phase_arcs() const { return phase_arcs_; }
  int phase_losses() const { return phase_losses_; }
  // Releases with time (receiver time, s), PRN (0: the filter re-opened) and reason ("channel_nis", "filter_nis"),
  // counted per reason.
  const ReleaseLog& release_log() const { return release_log_; }
  // Called at the end of every update once the filter runs.
  void set_log(std::function<void(const VectorEpochLog&)> log) { log_ = std::move(log); }

 private:
  struct PrnState {
    int accepted = 0;          // pseudorange updates accepted since it (re)joined
    int rejections = 0;        // consecutive rejections
    double coast_s = 0.0;      // commanded without a usable measurement (faded, coasting) this long
    double cn0_mean_hz = NAN;  // running mean of the channel's C/N0 estimates (ratio-Hz), while synchronised
    // Running mean of measured minus predicted Doppler over doppler_bias_average_s (its epochs: Doppler
    // measurements since the last aiding step).
    FalseLockMonitor doppler_bias{FalseLockMonitor::Averaging::kRunning, 0.5};
    double aid_offset_hz = 0.0;  // steps given to the carrier aiding (false-lock resets)
  };
  // Whether a channel's measurements may update the filter and keep it commanded as tracked (not faded).
  bool usable(const receiver::VectorChannelInput& ch, const PrnState& st) const;
  PrnState fresh_prn_state() const;  // with the false-lock monitor of opt_
  std::optional<SatelliteObservable> observable(const receiver::VectorEpochInput& in, int prn, std::int64_t sample,
                                                double pseudorange_m) const;
  bool initialise(const receiver::VectorEpochInput& in);
  // kPll: one channel's carrier states (discriminator update, lock test, fallback/re-entry) and its carrier
  // command; doppler_at(sample) is the filter's predicted Doppler of the channel at a receiver sample, with error
  // variance prediction_variance_hz2.
  // The windowed NIS tests after an epoch's updates.
  void nis_tests(const receiver::VectorEpochInput& in);
  void command_pll(const receiver::VectorChannelInput& ch, const std::function<double(std::int64_t)>& doppler_at,
                   double prediction_variance_hz2, bool usable_now, double cn0_hz, double step_s, double fs_hz,
                   receiver::VectorChannelCommand& command, VectorChannelLog& log);

  VectorTrackingOptions opt_;
  VectorProcessModel model_;
  std::optional<Ekf<8>> ekf_;
  std::int64_t sample_ = 0;
  double clock_corrections_s_ = 0.0;
  double starved_s_ = 0.0;
  int resets_ = 0, initialisations_ = 0, frequency_resets_ = 0;
  int phase_arcs_ = 0, phase_losses_ = 0;
  std::array<PrnState, 33> prn_{};
  std::array<VectorCarrierPhase, 33> phase_{};  // kPll, per PRN
  std::array<bool, 33> nis_released_{};         // by PRN, until the channel loses synchronisation
  std::array<double, 33> epoch_nis_{};          // this epoch's NIS and dof per PRN (summed over its rows)
  std::array<int, 33> epoch_dof_{};
  NisReleaseMonitor nis_;
  ReleaseLog release_log_;
  VectorEpochLog log_epoch_;
  std::function<void(const VectorEpochLog&)> log_;
};

}  // namespace ultratrack::fusion
