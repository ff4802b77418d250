// SPDX-License-Identifier: GPL-3.0-or-later
// Tightly coupled GNSS measurements: the pseudorange and pseudorange rate of one satellite predicted from the
// INS antenna position/velocity and the receiver clock states (17-state error model). Satellite position,
// velocity and clock come from the broadcast ephemeris at the transmit time implied by the pseudorange
// (t_tx = t_rx - rho / c - dt_sv), rotated into the receive-time ECEF frame (Sagnac); L1 C/A clock
// correction (af polynomial + relativistic - TGD), broadcast Klobuchar ionosphere and the standard
// troposphere exactly as receiver/pvt. Pseudorange rate = -lambda_L1 * Doppler; prediction
// u . (v_sat_apparent - v_ant_e) + clock drift - c * SV clock drift (pvt's apparent satellite velocity, plus the
// receiver's own velocity in the travel-time rate, which pvt leaves out) plus the troposphere's rate (its delay
// changes with the elevation, by the satellite's and the antenna's motion, and with the antenna height: up to
// ~10 mm/s at 10 deg from the satellite alone; the Klobuchar ionosphere's rate, < 1 mm/s, is left out).
// Metres, m/s, seconds.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "receiver/observables.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::fusion {

struct TightOptions {
  double elevation_mask_rad = 10.0 * 3.14159265358979 / 180.0;
  bool ionosphere = true;  // broadcast Klobuchar when the parameters are valid
  bool troposphere = true;
  bool use_range_rate = true;  // Doppler rows (a non-finite doppler_hz means absent for that satellite)
  // 1-sigma at zenith and 45 dB-Hz; grows with 1/sin(elevation) and lower C/N0 as in receiver/pvt.
  double sigma_range_zenith_m = 1.0;
  double sigma_rate_zenith_mps = 0.05;
  bool elevation_weighting = true;  // false: the zenith sigmas for every satellite
};

// Everything about one satellite at one epoch that does not depend on the receiver state.
struct SatelliteObservable {
  int prn = 0;
  Eigen::Vector3d r_sat_e = Eigen::Vector3d::Zero();  // at transmit time, rotated to the receive-time frame
  Eigen::Vector3d v_sat_e = Eigen::Vector3d::Zero();  // apparent velocity in the receive-time frame
  double sv_clock_m = 0.0;                            // c * (af polynomial + relativistic - TGD)
  double sv_drift_mps = 0.0;                          // c * SV clock drift
  double atmosphere_m = 0.0;                          // ionosphere + troposphere delay
  // The troposphere model's slopes at the antenna (0 without troposphere): d delay / d elevation (m/rad) and
  // d delay / d height (m/m), with the local up direction (ECEF unit vector) they refer to.
  double troposphere_per_elevation_m = 0.0, troposphere_per_height = 0.0;
  Eigen::Vector3d up_e = Eigen::Vector3d::Zero();
  double elevation_rad = 0.0, azimuth_rad = 0.0;
  double pseudorange_m = 0.0;
  double range_rate_mps = 0.0;  // -lambda * Doppler
  bool has_rate = false;
  double sigma_range_m = 1.0, sigma_rate_mps = 0.05;
};

// Satellites of an epoch with usable ephemeris (signals::select_ephemeris at the transmit time), above the
// mask as seen from r_ant_e (the current antenna estimate, ECEF), with the atmosphere evaluated there.
// receive_time is the epoch by the receiver clock. `stats` (optional) counts what was left out.
struct PrepareStats {
  int missing_ephemeris = 0;
  int below_mask = 0;
};
std::vector<SatelliteObservable> prepare_satellites(const receiver::ObservationEpoch& epoch,
                                                    const std::vector<signals::Ephemeris>& ephemerides,
                                                    const signals::KlobucharParameters& iono,
                                                    const Eigen::Vector3d& r_ant_e, const TightOptions& options,
                                                    PrepareStats* stats = nullptr);

// Predicted pseudorange (m) and rate (m/s) at an antenna position/velocity (ECEF) and clock bias/drift.
double predicted_pseudorange_m(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e, double clock_bias_m);
double predicted_range_rate_mps(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e,
                                const Eigen::Vector3d& v_ant_e, double clock_drift_mps);
// Rate of the troposphere delay (m/s) for an antenna at r_ant_e moving with v_ant_e (ECEF): the elevation's rate
// from the line of sight turning (satellite minus antenna velocity) and the local vertical turning with the
// antenna (spherical earth), and the height's rate; part of predicted_range_rate_mps.
double troposphere_rate_mps(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e,
                            const Eigen::Vector3d& v_ant_e);

// One satellite's pseudorange (row 0) and, when available and wanted, pseudorange rate (row 1), for the
// 17-state error model. w_ib_b: compensated body rate (lever-arm velocity).
// h(dx) is evaluated at every sigma point of the UKF (35 per satellite update), so it does not go through
// fusion::corrected + antenna_position_e + antenna_velocity_e (four sine/cosine pairs of the same latitude and
// longitude, GeographicLib's degree-based conversion): the nominal's radii of curvature (what correct_position
// uses) are computed once here, and per dx one sine/cosine pair each of the corrected latitude and longitude
// gives the ECEF position, C_en, the earth and transport rates. Equal to that composition within rounding
// (tests/fusion/error_model_test.cpp `TightMeasurement.SigmaPointFormEqualsCorrectedNominalComposition`).
class SatelliteMeasurement17 {
 public:
  SatelliteMeasurement17(const NominalState& nominal, const SatelliteObservable& sat,
                         const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b, bool use_rate);

  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const;
  // h's pseudorange (m) and range rate (m/s) without a heap allocation; the rate is computed whether or not
  // the measurement uses it (the satellite must have one: sat.has_rate).
  Eigen::Vector2d range_and_rate(const StateVector<17>& dx) const { return predicted(dx, true); }
  MeasurementJacobian<17> H(const StateVector<17>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return static_cast<int>(z_.size()); }
  int prn() const { return sat_.prn; }

 private:
  Eigen::Vector2d predicted(const StateVector<17>& dx, bool with_rate) const;  // (range, rate or 0)
  NominalState nominal_;
  SatelliteObservable sat_;
  Eigen::Vector3d lever_b_, w_ib_b_;
  bool rate_ = false;
  bool has_lever_ = false;  // a zero lever arm makes the attitude error move nothing (skipped: same bits)
  double meridian_plus_h_ = 0.0, transverse_plus_h_ = 0.0;  // the nominal's R_M + h, R_N + h (correct_position)
  // sin and cos of the nominal's latitude and longitude: h reuses them for hypotheses that leave the position
  // unchanged (most UKF sigma points: exactly the same values, no sincos call).
  double sin_lat0_ = 0.0, cos_lat0_ = 1.0, sin_lon0_ = 0.0, cos_lon0_ = 1.0;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

// All satellites of an epoch stacked in one measurement (k or 2k rows: all pseudoranges, then the rates of
// the satellites that have them). The driver updates satellite by satellite (each gated on its own); this
// form is for batch use (covariance analysis, tests).
class EpochMeasurement17 {
 public:
  EpochMeasurement17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                     const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b, bool use_rate);

  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<17>& dx) const;
  MeasurementJacobian<17> H(const StateVector<17>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return static_cast<int>(z_.size()); }

 private:
  NominalState nominal_;
  std::vector<SatelliteObservable> sats_;
  Eigen::Vector3d lever_b_, w_ib_b_;
  bool rate_ = false;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

}  // namespace ultratrack::fusion
