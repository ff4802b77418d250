// Covariance analysis of tightly coupled GPS/INS (seed 001 section IV.1): the 17-state INS error model
// linearised along a simulated trajectory (seed 001 profiles: straight, circle, s, spiral), propagated by an
// EKF or a UKF and updated once per second with the pseudoranges (optionally rates) of every satellite above
// the mask, with the seed's noise settings (eq. 38). The nominal is the truth, so the innovations are zero and
// only the covariance moves. Reports position 1-sigma (north, east, down) after each update.
// Units SI; NED; times in seconds from the trajectory start.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ukf.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::fusion {

struct CovarianceAnalysisOptions {
  std::string trajectory = "straight";  // ins::profile_spec names: straight, circle, s, spiral (also land)
  FilterKind filter = FilterKind::Ekf;
  double duration_s = 150.0;
  double propagation_interval_s = 0.1;  // linearisation along the truth at this spacing
  double update_interval_s = 1.0;
  double lat_rad = 36.37 * 3.14159265358979323846 / 180.0;
  double lon_rad = 127.36 * 3.14159265358979323846 / 180.0;
  double height_m = 1000.0;
  signals::GpsTime start{2190, 525600.0};                // 2022-01-01 02:00 GPST (inside brdc0010.22n)
  std::vector<signals::Ephemeris> ephemerides;           // empty: the nominal 24-slot constellation
  double elevation_mask_rad = 10.0 * 3.14159265358979323846 / 180.0;
  double sigma_range_m = 5.0;     // eq. 38 R^N
  bool use_range_rate = false;    // eq. 38 gives only pseudorange noise
  double sigma_rate_mps = 0.1;
  InsErrorModelOptions model;     // eq. 38 R^V and the bias part of P0 (seed001_eq38_model())
  Eigen::Vector3d sigma_pos_ned_m{5.0, 5.0, 3.1622776601683795};  // eq. 38 P0: (5 m)^2, (5 m)^2, 10 m^2
  Eigen::Vector3d sigma_vel_n_mps{2.0, 2.0, 2.0};
  Eigen::Vector3d sigma_att_rad{0.03 * 3.14159265358979323846 / 180.0, 0.03 * 3.14159265358979323846 / 180.0,
                                2.2360679774997896 * 3.14159265358979323846 / 180.0};  // 0.03, 0.03 deg; 5 deg^2
  UkfParameters ukf;
};

// Eq. 38: R^V = diag(0, (100 ug)^2, (0.1 deg/h)^2, 0) taken as white-noise PSDs per second on velocity and
// attitude; biases random constant with P0 sigmas 500 ug and 3 deg/h; clock P0 sigmas 10 m, 1 m/s and no
// clock process noise (R^V's last entries are zero).
InsErrorModelOptions seed001_eq38_model();
CovarianceAnalysisOptions seed001_covariance_options(const std::string& trajectory, FilterKind filter);

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
