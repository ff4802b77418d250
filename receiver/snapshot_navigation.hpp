// SPDX-License-Identifier: GPL-3.0-or-later
// Snapshot (coarse-time) positioning: a position from milliseconds of signal, broadcast ephemerides and an
// approximate time, without a decoded time of week (van Diggelen, "A-GPS", Artech House 2009, ch. 4).
//
// What a snapshot measures per satellite is only the sub-millisecond part of the transmit time: the C/A code
// phase at the snapshot's reference sample, t_tx mod 1 ms = code_phase_chips / 1.023 MHz. Three steps:
//  1. Millisecond integers from an a-priori position x0 and the approximate time t0: a reference satellite k
//     (highest elevation) takes the integer that puts its pseudorange nearest its prediction at (x0, t0); every
//     other satellite the integer that makes its pseudorange minus prediction nearest the reference's (the
//     common part, up to +-0.5 ms, is receiver clock). Right when the prediction errors' differences stay within
//     +-75 km (x0 within ~50 km, t0 within minutes).
//  2. Coarse-time least squares, five unknowns: ECEF position, clock bias b (m) and the time error dt (s) of
//     the transmit times: rho_i = |r_sat_i(t_tx_i + dt) - r| + b - c dt_sv_i + iono + tropo, whose dt column
//     is the satellite's range rate u_i . v_sat_i (the "coarse-time term"); satellites are re-evaluated at the
//     current dt every iteration, so time errors of tens of seconds converge. The true GPS time of the
//     reference sample is then t0 + dt - b / c.
//  3. Fault exclusion and quality: a chi-square test of the weighted residuals (n - 5 degrees of freedom);
//     failing it, the satellite whose removal passes with the lowest cost is excluded (at most two, keeping
//     one degree of freedom). The quality flag says whether the fix passed with redundancy.
// Without an a-priori position: a Doppler-only fix (position and clock drift from the Doppler of a static
// receiver, good to tens or hundreds of km) seeds a grid of a-priori positions (100 km apart, outwards to
// grid_radius_m, nearest first, ending 300 km past the first that passes both residual tests with 2+ degrees of
// freedom); each runs steps 1-3 and the passing solutions are ranked by their pseudorange cost plus
// the cost of their Doppler residuals after a velocity + drift solve (a wrong position leaves Doppler
// residuals of ~1.4e-4 m/s per metre). Units: metres, seconds, Hz; ECEF WGS-84.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::receiver {

struct SnapshotMeasurement {
  int prn = 0;
  double code_phase_chips = 0.0;   // C/A code phase at the reference sample, [0, 1023)
  double code_sigma_chips = 0.05;  // its 1-sigma, > 0
  double doppler_hz = 0.0;         // carrier Doppler, positive when the range shrinks (receiver drift included)
  double doppler_sigma_hz = 10.0;  // its 1-sigma, > 0
  double cn0_dbhz = 45.0;
  signals::Ephemeris ephemeris;  // the set valid at the snapshot's time
};

struct SnapshotOptions {
  double elevation_mask_rad = 5.0 * 3.14159265358979 / 180.0;  // at the solved position
  bool ionosphere = true;  // Klobuchar with `klobuchar` (caller's choice: a nav file's or the default set)
  signals::KlobucharParameters klobuchar;
  bool troposphere = true;
  double model_sigma_m = 2.0;             // atmosphere / orbit / clock error at zenith, grows as 1 / sin(el)
  double time_sigma_s = 10.0;             // a-priori time uncertainty; |time correction| > 3 sigma is a failure
  double false_alarm_probability = 1e-3;  // of the residual test
  int max_exclusions = 2;
  double grid_radius_m = 5.0e6;  // a-priori grid around the Doppler fix (no approximate position)
  double grid_step_m = 1.0e5;
  double max_height_m = 1.0e5;  // |height| beyond this is not a receiver on or above the earth
  int max_iterations = 20;

  // Empty when valid, else the reason.
  // True when the options fit together; otherwise false and *why (when given) says which setting and why.
  bool IsValid(std::string* why) const;
};

struct SnapshotSatellite {
  int prn = 0;
  bool used = false;  // false: excluded by the residual test or below the mask
  double elevation_rad = 0.0, azimuth_rad = 0.0;
  double cn0_dbhz = 0.0;
  double residual_m = 0.0;           // measured minus predicted pseudorange at the solution
  double sigma_m = 0.0;              // its a-priori 1-sigma
  double doppler_residual_hz = 0.0;  // after the velocity + drift solve at the solution
};

struct SnapshotSolution {
  bool valid = false;
  std::string failure;             // why not (when !valid)
  signals::GpsTime time;           // GPS time of the reference sample: t0 + time_correction_s
  double time_correction_s = 0.0;  // true minus approximate time
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  double clock_bias_m = 0.0;  // b: c (receiver time tag - true receive time) modulo the millisecond choice
  Eigen::Vector3d v_e_mps = Eigen::Vector3d::Zero();  // from the Doppler at the solution (7+ satellites: ok)
  double clock_drift_mps = 0.0;
  bool velocity_valid = false;
  // 1-sigma from the a-priori weights: east, north, up (m), clock (m), time error (s).
  Eigen::Vector3d sigma_enu_m = Eigen::Vector3d::Zero();
  double sigma_clock_m = 0.0, sigma_time_s = 0.0;
  std::vector<SnapshotSatellite> satellites;  // every measurement, used or not
  std::vector<int> excluded_prns;
  int used = 0;
  double residual_rms_m = 0.0;
  double test_statistic = 0.0, test_threshold = 0.0;  // weighted SSE and its chi-square threshold
  double doppler_statistic = 0.0;  // weighted SSE of the Doppler residuals after the velocity + drift solve
  // "pass": residual test passed with >= 1 degree of freedom and the fix is unambiguous; "unverified": 5
  // satellites (no redundancy); "fail": residual test failed or a second, different solution fits about as well.
  std::string quality = "fail";
  std::string a_priori;                              // "approximate position" or "doppler"
  std::optional<Eigen::Vector3d> doppler_fix_r_e_m;  // the Doppler-only a-priori position when one was made
  int candidates_tried = 0;
  int distinct_solutions = 0;  // passing solutions further apart than 1 km (grid search)
};

// A-priori position from Doppler alone: ECEF position and clock drift of a static receiver (4 unknowns, needs
// 4 satellites; 5+ for a residual), iterated from the point under the satellites' mean direction. nullopt when
// it does not converge.
std::optional<Eigen::Vector3d> doppler_position(const std::vector<SnapshotMeasurement>& measurements,
                                                const signals::GpsTime& approx_time);

// Steps 1-3 from one a-priori position.
SnapshotSolution solve_snapshot_from(const std::vector<SnapshotMeasurement>& measurements,
                                     const signals::GpsTime& approx_time, const Eigen::Vector3d& a_priori_r_e_m,
                                     const SnapshotOptions& options);

// The snapshot fix: from approx_r_e_m when given, else the Doppler fix and the grid search. Needs 5
// measurements with valid ephemerides (failure otherwise, with the reason).
SnapshotSolution solve_snapshot(const std::vector<SnapshotMeasurement>& measurements,
                                const signals::GpsTime& approx_time, const std::optional<Eigen::Vector3d>& approx_r_e_m,
                                const SnapshotOptions& options);

}  // namespace ultratrack::receiver
