// SPDX-License-Identifier: GPL-3.0-or-later
// Simulation harness for the fusion tests: an ins/ trajectory with a corrupted IMU (ins/imu_error_model
// preset), GNSS fixes or pseudoranges/Doppler simulated from the truth with known noise, an integration run
// and its error statistics against the truth. Independent of the filter code under test.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fusion/clock_model.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "ins/truth_interpolator.hpp"
#include "receiver/observables.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::fusion::test {

struct SimConfig {
  std::string profile = "land";
  double duration_s = 300.0;
  double imu_rate_hz = 100.0;
  std::string imu_preset = "hg1700ae";
  std::uint64_t seed = 1;
  Eigen::Vector3d lever_arm_b{1.0, 0.3, -1.2};
  double gnss_period_s = 1.0;
  double gnss_offset_s = 0.37;  // first GNSS time: non-integer, between IMU samples
  Eigen::Vector3d sigma_pos_ned_m{2.0, 2.0, 4.0};
  Eigen::Vector3d sigma_vel_n_mps{0.05, 0.05, 0.1};
  bool velocity = true;
  double fix_error_correlation_s = 0.0;  // loose: fix position errors first-order Gauss-Markov (0: white)
  fusion::FixErrorOptions fix_error;     // loose: the filter's fix-error states (off by default)
  double outage_start_s = 1e9;           // no GNSS in [start, start + length)
  double outage_length_s = 0.0;
  // Initial error 1-sigma (drawn) and what the filter is told.
  Eigen::Vector3d sigma0_pos_m{3.0, 3.0, 5.0};
  Eigen::Vector3d sigma0_vel_mps{0.3, 0.3, 0.3};
  Eigen::Vector3d sigma0_att_rad{1e-3, 1e-3, 1e-2};
  // Faults (loose): a fixed initial error added to the drawn one (position NED m, attitude psi NED rad), and
  // fixes offset by bias_offset_ned_m inside [bias_start_s, bias_start_s + bias_length_s).
  Eigen::Vector3d initial_offset_pos_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_offset_att_rad = Eigen::Vector3d::Zero();
  double bias_start_s = 1e9, bias_length_s = 0.0;
  Eigen::Vector3d bias_offset_ned_m = Eigen::Vector3d::Zero();
  // The filter's lock-out recovery (fusion/lockout_recovery.hpp).
  fusion::LockoutRecoveryOptions recovery;
  // Tight: satellites kept (all above the mask when 0), from reduce_after_s on.
  int max_satellites = 0;
  std::vector<int> keep_prns;  // from reduce_after_s on: only these satellites (instead of the highest)
  double reduce_after_s = 0.0;
  double sigma_range_m = 1.0;
  double sigma_rate_mps = 0.05;
  // Tight: the receiver oscillator (truth clock and filter model alike) and the height aiding options.
  fusion::OscillatorAllan oscillator;  // default: TCXO
  fusion::HeightAidingOptions height_aiding;
};

struct RunResult {
  std::vector<double> t_s;                          // at each GNSS epoch (after its update)
  std::vector<Eigen::Vector3d> pos_err_m;           // INS (IMU point) NED error at those times
  std::vector<double> nees;                         // full error-state NEES at those times
  std::vector<double> nees_nav;                     // position/velocity/attitude (9) NEES
  std::vector<double> gnss_err_h_m, gnss_err_3d_m;  // GNSS-only solution error (fix noise / PVT)
  double outage_drift_h_m = 0.0;                    // horizontal error at the end of the outage
  double outage_sigma_h_m = 0.0;                    // filter's horizontal 1-sigma there
  long long accepted = 0, rejected = 0;
  int state_size = 15;
  std::vector<Eigen::Vector3d> sigma_pos_m;           // filter's NED 1-sigma at the recorded times
  std::vector<std::vector<Eigen::Vector3d>> los_ned;  // tight: unit vectors to the satellites used, per record
  std::vector<std::vector<int>> prns;                 // ... and their PRNs
  long long pvt_fixes_reduced = 0;                    // tight: GNSS-only fixes from reduce_after_s on
  fusion::IntegrationCounters counters;
};

// Loose: GnssFix at t = offset + k period; tight: ObservationEpochs from the nominal constellation.
RunResult run_simulation(const SimConfig& cfg, fusion::Coupling coupling, fusion::FilterKind filter);

void geodetic_from_ecef(const Eigen::Vector3d& r_e, double& lat_rad, double& lon_rad, double& height_m);

// RMS of the 3-D norm of a set of vectors / of a set of scalars, from index `from`.
double rms3(const std::vector<Eigen::Vector3d>& v, std::size_t from);
double rms(const std::vector<double>& v, std::size_t from);

// Pseudorange and Doppler of one satellite simulated from the truth (independent of fusion/): true transmit
// time iterated with the Sagnac range, SV clock, atmosphere, receiver clock; rate by central difference.
struct TruthClock {
  double bias_m = 0.0, drift_mps = 0.0;
};
struct SimulatedEpoch {
  receiver::ObservationEpoch epoch;
  std::vector<Eigen::Vector3d> los_ned;  // receiver -> satellite unit vectors (NED), one per observation
  double t_true_s = 0.0;                 // GPS time of the epoch on the run's time line
};
SimulatedEpoch simulate_epoch(const ins::TruthInterpolator& truth, const Eigen::Vector3d& lever_arm_b,
                              const std::vector<signals::Ephemeris>& ephemerides,
                              const signals::KlobucharParameters& iono, const signals::GpsTime& origin, double t_true_s,
                              const TruthClock& clock, bool troposphere = true);

}  // namespace ultratrack::fusion::test
