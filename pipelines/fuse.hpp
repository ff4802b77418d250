// SPDX-License-Identifier: GPL-3.0-or-later
// The work of `ultratrack fuse`, callable in process (tests, figures): external GNSS fixes and IMU increments
// through fusion::GnssInsIntegration (loose, EKF or UKF) after a coarse alignment (static: levelling +
// gyrocompassing over the first seconds; motion: heading from the GNSS track, tilt from the accelerometers;
// config: the configuration's attitude), with optional GNSS outages, and the statistics the summary reports
// (update counts, convergence, RMS against a truth trajectory and of the GNSS fixes themselves).
// Optional GPS attitude ([OhAttINS], a multi-antenna receiver's attitude.csv): fixed rows are attitude updates at
// their own times (GPS time -> IMU time by [attitude] gps_time_at_imu_zero), unfixed rows are skipped and the
// filter falls back to position/velocity; `attitude` alignment takes the first fixed attitude (a MEMS IMU cannot
// gyrocompass, [KimAlign]). Attitudes inside --outage spans are dropped with the fixes.
// Optional odometer ([KimVMS], fusion/vms_measurement.hpp): the odometer rows summed into windows of
// 1 / [odometer] update_rate_hz, each a VMS/NHC update at its end, gated by heading rate and speed; with
// gnss_until_s the fixes after that time are dropped (GNSS for the alignment and until then, odometer only after);
// without fixes the start is the configuration's (--align config with [initial] position_deg_m).
// Units SI inside; times on the IMU file's time line.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <utility>
#include <vector>

#include "fusion/fix_error_whiteness.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "ins/attitude.hpp"
#include "ins/nav_state.hpp"
#include "ins/odometer.hpp"
#include "ins/standstill_gyro_bias.hpp"
#include "ins/truth_interpolator.hpp"
#include "pipelines/fuse_config.hpp"
#include "pipelines/fuse_inputs.hpp"
#include "pipelines/nav_sigma.hpp"
#include "pipelines/navigation_initialisation.hpp"

namespace ultratrack::pipelines {

// The data hold no window the chosen alignment can use (the platform never reaches the in-motion alignment's speed,
// no fixed GPS attitude, ...): not bad input but a run without a solution, with what to change in the message.
struct AlignmentUnavailable : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct FuseSettings {
  fusion::FilterKind filter = fusion::FilterKind::Ekf;
  AlignMode align = AlignMode::Motion;
  FuseConfig config;
  std::vector<std::pair<double, double>> outages;  // [start, start + duration): GNSS fixes dropped
  // GPS attitude (empty: none). attitude_file names it in messages and the summary.
  std::vector<GpsAttitudeRow> attitude;
  std::string attitude_file;
  // Odometer rows (empty: no odometer aiding) and the file's name for messages and the summary.
  std::vector<ins::OdometerSample> odometer;
  std::string odometer_file;
  std::optional<double> gnss_until_s;  // fixes after this time are dropped
};

// Odometer aiding's account ([KimVMS]'s metric: error / distance travelled since GNSS was last used, in %).
struct OdometerUse {
  long long windows = 0;              // odometer windows handed to the filter
  fusion::OdometerEstimate estimate;  // at the end
  double gnss_last_used_s = 0.0;      // the last fix handed to the filter (else the navigation start)
  // Against truth, from gnss_last_used_s to the end (nothing without truth or without distance travelled):
  std::optional<double> distance_travelled_m, horizontal_error_max_m, horizontal_error_end_m, altitude_error_max_m;
};

// What happened to the attitude rows (all zero without --attitude).
struct AttitudeUse {
  long long rows = 0, fixed_rows = 0;
  long long unfixed_skipped = 0;  // fixed = 0: fallback to position/velocity
  long long before_start = 0;     // at or before the navigation start (the alignment's row among them)
  long long after_end = 0;        // after the last IMU row
  long long in_outage = 0;
  long long used = 0;  // handed to the filter
};

struct ErrorRms {
  int rows = 0;
  double horizontal_m = 0.0, vertical_m = 0.0, position_3d_m = 0.0, velocity_mps = 0.0, attitude_deg = 0.0,
         heading_deg = 0.0;
  double within_3sigma = 0.0;  // fraction of rows with every position axis inside 3 sigma
};

struct OutageResult {
  double start_s = 0.0, end_s = 0.0;
  double horizontal_error_m = 0.0;  // at the end of the outage (truth needed)
  double sigma_horizontal_m = 0.0;  // the filter's horizontal 1-sigma there
};

struct FuseResult {
  double start_s = 0.0, end_s = 0.0;  // navigation span
  ins::EulerAngles initial_attitude;
  std::string alignment_note;
  // Motion alignment: the gyro biases a standstill at the start measured (used when set), and the span of the
  // position differences the heading came from (position-only fixes; 0: the fixes' velocities).
  std::optional<ins::StandstillGyroBias> standstill;
  double motion_span_s = 0.0;
  // The fixes' errors as the filter took them: measured (fusion/fix_error_whiteness.hpp, [gnss]
  // error_correlation_time_s "auto") or configured; Gauss-Markov states, an inflated variance, or white.
  std::optional<fusion::FixErrorWhiteness> fix_whiteness;
  fusion::FixErrorOptions fix_error;   // enabled: carried as states
  double fix_error_inflation_s = 0.0;  // > 0: the variance inflated for this correlation time
  // The velocities' error model (measured with the positions'), and the 1-sigma each velocity fix was used at [m/s].
  std::optional<fusion::VelocityWhiteness> velocity_whiteness;
  double velocity_sigma_mps = 0.0;
  fusion::IntegrationCounters counters;
  std::vector<fusion::RecoveryEvent> recovery_events;  // lock-out recoveries (fusion/lockout_recovery.hpp)
  long long fixes_used = 0, fixes_before_start = 0, fixes_in_outage = 0;
  std::optional<double> converged_at_s;  // heading 1-sigma below the threshold from here to the end
  NavSigma final_sigma;
  ins::NavState final_nav;
  // The IMU bias estimates at the end and their 1-sigma (body axes, m/s^2 and rad/s).
  Eigen::Vector3d accel_bias_b = Eigen::Vector3d::Zero(), gyro_bias_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma_accel_bias_b = Eigen::Vector3d::Zero(), sigma_gyro_bias_b = Eigen::Vector3d::Zero();
  std::optional<ErrorRms> rms_all, rms_converged;  // against truth
  std::optional<ErrorRms> gnss_rms;                // the fixes themselves against truth (antenna)
  std::vector<OutageResult> outages;
  AttitudeUse attitude;
  long long fixes_after_gnss_until = 0;
  std::optional<OdometerUse> odometer;  // with odometer rows
  bool interrupted = false;             // a stop request ended the run before the last IMU row
};

// The odometer rows as speed windows of about window_s (whole rows; each window ends at a row's time): what fuse
// and receive (pipelines/gnss_ins_coupler.hpp) hand to GnssInsIntegration::add_odometer.
std::vector<fusion::OdometerSpeed> odometer_windows(const std::vector<ins::OdometerSample>& rows, double window_s);

// Every solution row (after each IMU interval) goes to on_row. truth: a trajectory on the IMU time line for the
// RMS statistics (empty: none). A stop request ends the run after the current IMU interval (the result then covers
// the rows so far). Throws io::InputError for inputs that do not fit together (no overlap in time, unknown preset,
// ...) and AlignmentUnavailable when the data hold no window the chosen alignment can use.
FuseResult fuse(const std::vector<ins::ImuIncrement>& imu, const std::vector<GnssFixRow>& gnss,
                const std::vector<ins::TruthSample>& truth, const FuseSettings& settings,
                const std::function<void(const ins::NavState&, const NavSigma&)>& on_row = {},
                const std::function<void(double fraction)>& on_progress = {}, std::stop_token stop = {});

}  // namespace ultratrack::pipelines
