// SPDX-License-Identifier: GPL-3.0-or-later
// Covariance analysis of tightly coupled GPS/INS ([ChoUKF] section IV.1): the 17-state INS error model
// linearised along a simulated trajectory ([ChoUKF] profiles: straight, circle, s, spiral), propagated by an
// EKF or a UKF and updated once per second with the pseudoranges (optionally rates) of every satellite above
// the mask, with the seed's noise settings (eq. 38). The nominal is the truth, so the innovations are zero and
// only the covariance moves. Reports position 1-sigma (north, east, down) after each update.
// Ultra-tight ([ChoUKF] section IV.2, issue 7): the same filter updated every coherent integration T with the
// I&Q of every satellite (fusion/iq_measurements.hpp: 6 taps per satellite, normalised, amplitude from C/N0)
// or with their discriminators as range and range-rate errors. The EKF is linearised at the truth; the UKF
// draws its sigma points around the truth with its own covariance and pushes them through the nonlinear I&Q
// functions, so its covariance is what the UKF itself would report with a perfect estimate (the recursion of P
// does not depend on z); its true error covariance would need a Monte Carlo.
// Units SI; NED; times in seconds from the trajectory start.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fusion/coupling.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/iq_measurements.hpp"
#include "fusion/ukf.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::fusion {

enum class IqForm {
  Iq,             // the correlator taps themselves ([ChoUKF] eqs. 11-17)
  Discriminator,  // pre-filtered: code / frequency discriminators as range / range-rate errors
};

struct CovarianceAnalysisOptions {
  Coupling coupling = Coupling::kTight;  // kTight or kUltraTight
  std::string trajectory = "straight";   // ins::profile_spec names: straight, circle, s, spiral (also land)
  FilterKind filter = FilterKind::Ekf;
  double duration_s = 150.0;
  double propagation_interval_s = 0.1;  // linearisation along the truth at this spacing
  double update_interval_s = 1.0;
  double lat_rad = 36.37 * 3.14159265358979323846 / 180.0;
  double lon_rad = 127.36 * 3.14159265358979323846 / 180.0;
  double height_m = 1000.0;
  signals::GpsTime start{2190, 525600.0};       // 2022-01-01 02:00 GPST (inside brdc0010.22n)
  std::vector<signals::Ephemeris> ephemerides;  // empty: the nominal 24-slot constellation
  double elevation_mask_rad = 10.0 * 3.14159265358979323846 / 180.0;
  double sigma_range_m = 5.0;   // eq. 38 R^N
  bool use_range_rate = false;  // eq. 38 gives only pseudorange noise
  double sigma_rate_mps = 0.1;
  InsErrorModelOptions model;  // eq. 38 R^V and the bias part of P0 (seed001_eq38_model())
  Eigen::Vector3d sigma_pos_ned_m{5.0, 5.0, 3.1622776601683795};  // eq. 38 P0: (5 m)^2, (5 m)^2, 10 m^2
  Eigen::Vector3d sigma_vel_n_mps{2.0, 2.0, 2.0};
  Eigen::Vector3d sigma_att_rad{0.03 * 3.14159265358979323846 / 180.0, 0.03 * 3.14159265358979323846 / 180.0,
                                2.2360679774997896 * 3.14159265358979323846 / 180.0};  // 0.03, 0.03 deg; 5 deg^2
  UkfParameters ukf;
  // Ultra-tight only (update_interval_s should then be iq.integration_time_s: one update per integration).
  IqForm iq_form = IqForm::Iq;
  IqSettings iq;                             // C/N0, T, tap offset; the noise is N(0, 1) per I or Q (eq. 16)
  bool discriminator_squaring_loss = true;   // discriminator_noise's bracket; false: the first-order variances
  double discriminator_sigma_range_m = 0.0;  // > 0 overrides the closed form (for equivalence checks)
  double discriminator_sigma_rate_mps = 0.0;
  bool discriminator_use_rate = true;
};

// Eq. 38: R^V = diag(0, (100 ug)^2, (0.1 deg/h)^2, 0) taken as white-noise PSDs per second on velocity and
// attitude; biases random constant with P0 sigmas 500 ug and 3 deg/h; clock P0 sigmas 10 m, 1 m/s and no
// clock process noise (R^V's last entries are zero).
InsErrorModelOptions seed001_eq38_model();
CovarianceAnalysisOptions seed001_covariance_options(const std::string& trajectory, FilterKind filter);
// The same with ultra-tight updates every T (propagation at T as well), 45 dB-Hz, T = 20 ms, taps at +-0.5 chip.
CovarianceAnalysisOptions seed001_ultratight_options(const std::string& trajectory, FilterKind filter, IqForm form);

struct CovarianceSample {
  double t_s = 0.0;
  Eigen::Vector3d sigma_pos_ned_m = Eigen::Vector3d::Zero();
  int satellites = 0;
  std::vector<Eigen::Vector3d> los_ned;  // unit vectors antenna -> satellite (NED) of the update, for checks
};

struct CovarianceAnalysisResult {
  std::vector<CovarianceSample> samples;  // t = 0 (prior) then after every update
  // The sample at or just before t (the posterior of the last update not later than t).
  CovarianceSample at(double t_s) const;
};

// Throws io::InputError for an unknown trajectory, no satellites in view, or bad options.
CovarianceAnalysisResult run_covariance_analysis(const CovarianceAnalysisOptions& options);

}  // namespace ultratrack::fusion
