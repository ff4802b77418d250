// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/tight_measurements.hpp"

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>

#include "fusion/loose_measurements.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "signals/atmosphere.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::fusion {
namespace {

using signals::kSpeedOfLight_mps;

// receiver/pvt's weighting: 1-sigma grows as 1/sin(el) and with lower C/N0 (amplitude ratio to 45 dB-Hz).
double sigma_scale(double elevation_rad, double cn0_dbhz) {
  const double el = std::max(elevation_rad, 5.0 * M_PI / 180.0);
  const double cn0_factor = std::pow(10.0, (45.0 - std::min(cn0_dbhz, 55.0)) / 20.0);
  return std::max(cn0_factor, 0.3) / std::sin(el);
}

Eigen::Vector3d antenna_velocity_e(const ins::NavState& nav, const Eigen::Vector3d& w_ib_b,
                                   const Eigen::Vector3d& l_b) {
  return ins::C_en(nav.lat_rad, nav.lon_rad) * antenna_velocity_n(nav, w_ib_b, l_b);
}

// Rows of one satellite's Jacobian (pseudorange; rate) with respect to the 17-state error.
void satellite_rows(const NominalState& nominal, const SatelliteObservable& sat, const Eigen::Vector3d& l_b,
                    const Eigen::Vector3d& w_ib_b, Eigen::Matrix<double, 1, 17>& h_pr,
                    Eigen::Matrix<double, 1, 17>& h_rate) {
  const ins::NavState& nav = nominal.nav;
  const Eigen::Matrix3d C_en = ins::C_en(nav.lat_rad, nav.lon_rad);
  const Eigen::Matrix3d C = nav.q_nb.toRotationMatrix();
  const Eigen::Vector3d l_n = C * l_b;
  const Eigen::Vector3d r_ant = antenna_position_e(nav, l_b);
  const Eigen::Vector3d los = sat.r_sat_e - r_ant;
  const double rho = los.norm();
  const Eigen::Vector3d u_e = los / rho;
  const Eigen::Vector3d u_n = C_en.transpose() * u_e;
  h_pr.setZero();
  h_pr.segment<3>(ix::kPos) = u_n.transpose();
  h_pr.segment<3>(ix::kAtt) = u_n.transpose() * ins::skew(l_n);
  h_pr(ix::kClockBias) = -1.0;

  const Eigen::Vector3d w_in =
      ins::earth_rate_n(nav.lat_rad) + ins::transport_rate_n(nav.lat_rad, nav.height_m, nav.v_n);
  const Eigen::Vector3d v_rel = sat.v_sat_e - antenna_velocity_e(nav, w_ib_b, l_b);
  const Eigen::Matrix3d Hv_psi = -ins::skew(C * w_ib_b.cross(l_b)) + ins::skew(w_in) * ins::skew(l_n);
  h_rate.setZero();
  // Line-of-sight change with position: d(u . v_rel)/dr_ant = -v_rel' (I - u u') / rho; r_ant moves by -C_en dr.
  const Eigen::RowVector3d a = (v_rel.transpose() * (Eigen::Matrix3d::Identity() - u_e * u_e.transpose()) * C_en) / rho;
  h_rate.segment<3>(ix::kPos) = a;
  // The antenna velocity enters as -(u - dT/dh up) . v_ant: the line of sight and the troposphere's height rate
  // (its elevation-rate share through v_ant is ~1e-5 and left out).
  const Eigen::Vector3d w_n = u_n - sat.troposphere_per_height * (C_en.transpose() * sat.up_e);
  h_rate.segment<3>(ix::kVel) = w_n.transpose();
  // Attitude moves the antenna velocity (lever arm) and, through the antenna position, the line of sight.
  h_rate.segment<3>(ix::kAtt) = -w_n.transpose() * Hv_psi + a * ins::skew(l_n);
  h_rate.segment<3>(ix::kGyroBias) = -w_n.transpose() * C * ins::skew(l_b);
  h_rate(ix::kClockDrift) = -1.0;
}

}  // namespace

std::vector<SatelliteObservable> prepare_satellites(const receiver::ObservationEpoch& epoch,
                                                    const std::vector<signals::Ephemeris>& ephemerides,
                                                    const signals::KlobucharParameters& iono,
                                                    const Eigen::Vector3d& r_ant_e, const TightOptions& opt,
                                                    PrepareStats* stats) {
  std::vector<SatelliteObservable> out;
  out.reserve(epoch.observations.size());
  double lat_deg = 0.0, lon_deg = 0.0, h = 0.0;
  GeographicLib::Geocentric::WGS84().Reverse(r_ant_e.x(), r_ant_e.y(), r_ant_e.z(), lat_deg, lon_deg, h);
  const double lat = lat_deg * M_PI / 180.0, lon = lon_deg * M_PI / 180.0;
  for (const auto& o : epoch.observations) {
    if (!std::isfinite(o.pseudorange_m)) continue;
    const signals::GpsTime t_tx_sv = signals::add_seconds(epoch.receive_time, -o.pseudorange_m / kSpeedOfLight_mps);
    const auto eph = signals::select_ephemeris(ephemerides, o.prn, t_tx_sv);
    if (!eph) {
      if (stats) ++stats->missing_ephemeris;
      continue;
    }
    const double dt_sv = signals::l1_ca_clock_correction_s(*eph, t_tx_sv);
    const signals::GpsTime t_tx = signals::add_seconds(t_tx_sv, -dt_sv);
    const signals::SatelliteState st = signals::satellite_state(*eph, t_tx);
    double rho = (st.r_e_m - r_ant_e).norm();
    const Eigen::Vector3d r_sat = signals::rotate_to_receive_frame(st.r_e_m, rho / kSpeedOfLight_mps);
    rho = (r_sat - r_ant_e).norm();
    const Eigen::Vector3d v_sat = signals::rotate_to_receive_frame(st.v_e_mps, rho / kSpeedOfLight_mps);
    const signals::LookAngles la = signals::look_angles(r_ant_e, r_sat);
    if (la.elevation_rad < opt.elevation_mask_rad) {
      if (stats) ++stats->below_mask;
      continue;
    }
    SatelliteObservable s;
    s.prn = o.prn;
    s.r_sat_e = r_sat;
    // Apparent satellite velocity as receiver/pvt: the transmit instant slides with the travel time.
    const Eigen::Vector3d u = (r_sat - r_ant_e) / rho;
    const double tau_dot = u.dot(v_sat) / kSpeedOfLight_mps;
    const Eigen::Vector3d omega_e(0.0, 0.0, signals::kEarthRotationRate_radps);
    s.v_sat_e = (1.0 - tau_dot) * v_sat - tau_dot * omega_e.cross(r_sat);
    s.sv_clock_m = kSpeedOfLight_mps * dt_sv;
    s.sv_drift_mps = kSpeedOfLight_mps * st.clock_drift_sps;
    s.elevation_rad = la.elevation_rad;
    s.azimuth_rad = la.azimuth_rad;
    if (opt.ionosphere && iono.valid)
      s.atmosphere_m +=
          kSpeedOfLight_mps * signals::klobuchar_delay_s(iono, lat, lon, la.azimuth_rad, la.elevation_rad, t_tx.tow_s);
    if (opt.troposphere) {
      const double el = la.elevation_rad;
      s.atmosphere_m += signals::troposphere_delay_m(lat, h, el);
      // Central differences of the model (smooth in both: mapping 1 / sqrt(0.002 + sin^2), barometric height).
      constexpr double kDel = 1e-4, kDh = 1.0;
      s.troposphere_per_elevation_m =
          (signals::troposphere_delay_m(lat, h, el + kDel) - signals::troposphere_delay_m(lat, h, el - kDel)) /
          (2.0 * kDel);
      s.troposphere_per_height =
          (signals::troposphere_delay_m(lat, h + kDh, el) - signals::troposphere_delay_m(lat, h - kDh, el)) /
          (2.0 * kDh);
      s.up_e = Eigen::Vector3d(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
    }
    s.pseudorange_m = o.pseudorange_m;
    s.has_rate = opt.use_range_rate && std::isfinite(o.doppler_hz);
    s.range_rate_mps = s.has_rate ? -signals::kL1Wavelength_m * o.doppler_hz : 0.0;
    const double scale = opt.elevation_weighting ? sigma_scale(la.elevation_rad, o.cn0_dbhz) : 1.0;
    s.sigma_range_m = opt.sigma_range_zenith_m * scale;
    s.sigma_rate_mps = opt.sigma_rate_zenith_mps * scale;
    out.push_back(s);
  }
  return out;
}

double predicted_pseudorange_m(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e, double clock_bias_m) {
  return (sat.r_sat_e - r_ant_e).norm() + clock_bias_m - sat.sv_clock_m + sat.atmosphere_m;
}

double predicted_range_rate_mps(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e,
                                const Eigen::Vector3d& v_ant_e, double clock_drift_mps) {
  const Eigen::Vector3d u = (sat.r_sat_e - r_ant_e).normalized();
  // The receiver's own part of the travel-time rate (receiver/pvt leaves it out: up to 2 mm/s at 140 m/s).
  const double dtau = -u.dot(v_ant_e) / kSpeedOfLight_mps;
  const Eigen::Vector3d omega_e(0.0, 0.0, signals::kEarthRotationRate_radps);
  const Eigen::Vector3d v_sat = sat.v_sat_e - dtau * (sat.v_sat_e + omega_e.cross(sat.r_sat_e));
  return u.dot(v_sat - v_ant_e) + clock_drift_mps - sat.sv_drift_mps + troposphere_rate_mps(sat, r_ant_e, v_ant_e);
}

double troposphere_rate_mps(const SatelliteObservable& sat, const Eigen::Vector3d& r_ant_e,
                            const Eigen::Vector3d& v_ant_e) {
  if (sat.troposphere_per_elevation_m == 0.0 && sat.troposphere_per_height == 0.0) return 0.0;
  const Eigen::Vector3d los = sat.r_sat_e - r_ant_e;
  const double rho = los.norm();
  const Eigen::Vector3d u = los / rho;
  const Eigen::Vector3d& up = sat.up_e;
  const Eigen::Vector3d v_rel = sat.v_sat_e - v_ant_e;
  const Eigen::Vector3d du = (v_rel - u * u.dot(v_rel)) / rho;  // the line of sight turning
  const double v_up = v_ant_e.dot(up);
  const Eigen::Vector3d dup = (v_ant_e - up * v_up) / (r_ant_e.norm());  // the local vertical turning
  const double sin_el = u.dot(up);
  const double cos_el = std::sqrt(std::max(1e-12, 1.0 - sin_el * sin_el));
  const double el_rate = (du.dot(up) + u.dot(dup)) / cos_el;
  return sat.troposphere_per_elevation_m * el_rate + sat.troposphere_per_height * v_up;
}

SatelliteMeasurement17::SatelliteMeasurement17(const NominalState& nominal, const SatelliteObservable& sat,
                                               const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                               bool use_rate)
    : nominal_(nominal), sat_(sat), lever_b_(lever_arm_b), w_ib_b_(w_ib_b), rate_(use_rate && sat.has_rate) {
  has_lever_ = !lever_b_.isZero(0.0);
  const ins::Radii radii = ins::radii_of_curvature(nominal.nav.lat_rad);
  meridian_plus_h_ = radii.meridian_m + nominal.nav.height_m;
  transverse_plus_h_ = radii.transverse_m + nominal.nav.height_m;
  sin_lat0_ = std::sin(nominal.nav.lat_rad);
  cos_lat0_ = std::cos(nominal.nav.lat_rad);
  sin_lon0_ = std::sin(nominal.nav.lon_rad);
  cos_lon0_ = std::cos(nominal.nav.lon_rad);
  const int k = rate_ ? 2 : 1;
  z_.resize(k);
  R_ = Eigen::MatrixXd::Zero(k, k);
  z_(0) = sat.pseudorange_m;
  R_(0, 0) = sat.sigma_range_m * sat.sigma_range_m;
  if (rate_) {
    z_(1) = sat.range_rate_mps;
    R_(1, 1) = sat.sigma_rate_mps * sat.sigma_rate_mps;
  }
}

Eigen::VectorXd SatelliteMeasurement17::h(const StateVector<17>& dx) const { return predicted(dx, rate_).head(size()); }

Eigen::Vector2d SatelliteMeasurement17::predicted(const StateVector<17>& dx, bool with_rate) const {
  // fusion::corrected's position step (ins::correct_position), with the nominal's radii computed once.
  const ins::NavState& n0 = nominal_.nav;
  // With a zero north (east) error the latitude (longitude) is the nominal's bit for bit (x - 0 / y == x for
  // finite y), so its cached sin and cos are the same numbers std::sin and std::cos would return.
  const double lat = n0.lat_rad - dx(ix::kPos) / meridian_plus_h_;
  const bool same_lat = dx(ix::kPos) == 0.0;
  const double sl = same_lat ? sin_lat0_ : std::sin(lat), cl = same_lat ? cos_lat0_ : std::cos(lat);
  const double lon = n0.lon_rad - dx(ix::kPos + 1) / (transverse_plus_h_ * cl);
  const bool same_lon = dx(ix::kPos + 1) == 0.0 && cl != 0.0;
  const double so = same_lon ? sin_lon0_ : std::sin(lon), co = same_lon ? cos_lon0_ : std::cos(lon);
  const double height = n0.height_m + dx(ix::kPos + 2);
  // WGS-84 geodetic -> ECEF and C_en (ins::ecef_from_geodetic, ins::C_en) from the one pair of each.
  static const double a = GeographicLib::Constants::WGS84_a(), f = GeographicLib::Constants::WGS84_f();
  static const double e2 = f * (2.0 - f);
  const double w2 = 1.0 - e2 * sl * sl, w = std::sqrt(w2);
  const double transverse = a / w;
  Eigen::Vector3d r_ant((transverse + height) * cl * co, (transverse + height) * cl * so,
                        (transverse * (1.0 - e2) + height) * sl);
  Eigen::Matrix3d C_en;
  // clang-format off
  C_en << -sl * co, -so, -cl * co,
          -sl * so,  co, -cl * so,
                cl, 0.0,      -sl;
  // clang-format on
  Eigen::Quaterniond q_nb = n0.q_nb;
  if (has_lever_) {
    q_nb = (ins::quaternion_from_rotation_vector(dx.segment<3>(ix::kAtt)) * n0.q_nb).normalized();
    r_ant += C_en * (q_nb * lever_b_);
  }
  Eigen::Vector2d out(predicted_pseudorange_m(sat_, r_ant, nominal_.clock_bias_m - dx(ix::kClockBias)), 0.0);
  if (with_rate) {
    const Eigen::Vector3d v_n = n0.v_n - dx.segment<3>(ix::kVel);
    Eigen::Vector3d v_ant_n = v_n;
    if (has_lever_) {  // antenna_velocity_n: the earth and transport rates at the corrected position
      const double meridian = a * (1.0 - e2) / (w2 * w);
      const double re = transverse + height;
      const Eigen::Vector3d w_in(ins::kEarthRate_rps * cl + v_n.y() / re, -v_n.x() / (meridian + height),
                                 -ins::kEarthRate_rps * sl - v_n.y() * (sl / cl) / re);
      const Eigen::Vector3d w_ib = w_ib_b_ - dx.segment<3>(ix::kGyroBias);
      v_ant_n += q_nb * (w_ib - q_nb.conjugate() * w_in).cross(lever_b_);
    }
    out(1) = predicted_range_rate_mps(sat_, r_ant, C_en * v_ant_n, nominal_.clock_drift_mps - dx(ix::kClockDrift));
  }
  return out;
}

MeasurementJacobian<17> SatelliteMeasurement17::H(const StateVector<17>&) const {
  MeasurementJacobian<17> H(z_.size(), 17);
  Eigen::Matrix<double, 1, 17> pr, rate;
  satellite_rows(nominal_, sat_, lever_b_, w_ib_b_, pr, rate);
  H.row(0) = pr;
  if (rate_) H.row(1) = rate;
  return H;
}

EpochMeasurement17::EpochMeasurement17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                                       const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b, bool use_rate)
    : nominal_(nominal), sats_(sats), lever_b_(lever_arm_b), w_ib_b_(w_ib_b), rate_(use_rate) {
  const int n = static_cast<int>(sats_.size());
  int k = n;
  if (rate_)
    for (const auto& s : sats_) k += s.has_rate ? 1 : 0;
  z_.resize(k);
  R_ = Eigen::MatrixXd::Zero(k, k);
  int row = n;
  for (int i = 0; i < n; ++i) {
    z_(i) = sats_[i].pseudorange_m;
    R_(i, i) = sats_[i].sigma_range_m * sats_[i].sigma_range_m;
    if (rate_ && sats_[i].has_rate) {
      z_(row) = sats_[i].range_rate_mps;
      R_(row, row) = sats_[i].sigma_rate_mps * sats_[i].sigma_rate_mps;
      ++row;
    }
  }
}

Eigen::VectorXd EpochMeasurement17::h(const StateVector<17>& dx) const {
  const NominalState s = corrected<17>(nominal_, dx);
  const Eigen::Vector3d r_ant = antenna_position_e(s.nav, lever_b_);
  const Eigen::Vector3d v_ant = antenna_velocity_e(s.nav, w_ib_b_ - dx.segment<3>(ix::kGyroBias), lever_b_);
  Eigen::VectorXd out(z_.size());
  const int n = static_cast<int>(sats_.size());
  int row = n;
  for (int i = 0; i < n; ++i) {
    out(i) = predicted_pseudorange_m(sats_[i], r_ant, s.clock_bias_m);
    if (rate_ && sats_[i].has_rate) out(row++) = predicted_range_rate_mps(sats_[i], r_ant, v_ant, s.clock_drift_mps);
  }
  return out;
}

MeasurementJacobian<17> EpochMeasurement17::H(const StateVector<17>&) const {
  MeasurementJacobian<17> H(z_.size(), 17);
  const int n = static_cast<int>(sats_.size());
  int row = n;
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 1, 17> pr, rate;
    satellite_rows(nominal_, sats_[i], lever_b_, w_ib_b_, pr, rate);
    H.row(i) = pr;
    if (rate_ && sats_[i].has_rate) H.row(row++) = rate;
  }
  return H;
}

}  // namespace ultratrack::fusion
