// SPDX-License-Identifier: GPL-3.0-or-later
// IS-GPS-200 Table 20-IV user algorithm for position, with velocity by analytic differentiation of the
// same equations, the SV clock polynomial with its relativistic term, and the Sagnac-corrected range.
#include "signals/satellite_state.hpp"

#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals {
namespace {

constexpr double kKeplerTolerance_rad = 1e-12;
constexpr int kKeplerMaxIterations = 30;

// Newton iteration on M = E - e sin E, started at E = M (converges for every e < 1 within a few steps).
double eccentric_anomaly(double mean_anomaly_rad, double e) {
  double E = mean_anomaly_rad;
  for (int i = 0; i < kKeplerMaxIterations; ++i) {
    const double dE = (mean_anomaly_rad - E + e * std::sin(E)) / (1.0 - e * std::cos(E));
    E += dE;
    if (std::abs(dE) < kKeplerTolerance_rad) break;
  }
  return E;
}

}  // namespace

SatelliteState satellite_state(const Ephemeris& eph, const GpsTime& t) {
  const double A = eph.sqrt_a_sqrtm * eph.sqrt_a_sqrtm;
  const double n0 = std::sqrt(kGM_m3ps2 / (A * A * A));
  const double tk = wrap_half_week(seconds_between(t, eph.toe()));
  const double n = n0 + eph.delta_n_radps;
  const double Mk = eph.m0_rad + n * tk;
  const double e = eph.e;
  const double Ek = eccentric_anomaly(Mk, e);
  const double sinE = std::sin(Ek), cosE = std::cos(Ek);
  const double one_minus_ecosE = 1.0 - e * cosE;
  const double sqrt_1me2 = std::sqrt(1.0 - e * e);
  const double vk = std::atan2(sqrt_1me2 * sinE, cosE - e);
  const double phi = vk + eph.omega_rad;
  const double s2 = std::sin(2.0 * phi), c2 = std::cos(2.0 * phi);

  const double du = eph.cus_rad * s2 + eph.cuc_rad * c2;
  const double dr = eph.crs_m * s2 + eph.crc_m * c2;
  const double di = eph.cis_rad * s2 + eph.cic_rad * c2;
  const double u = phi + du;
  const double r = A * one_minus_ecosE + dr;
  const double i = eph.i0_rad + di + eph.idot_radps * tk;
  const double xp = r * std::cos(u), yp = r * std::sin(u);
  const double omega_dot_k = eph.omega_dot_radps - kEarthRotationRate_radps;
  const double Om = eph.omega0_rad + omega_dot_k * tk - kEarthRotationRate_radps * eph.toe_s;
  const double sinO = std::sin(Om), cosO = std::cos(Om), sini = std::sin(i), cosi = std::cos(i);

  SatelliteState s;
  s.r_e_m = {xp * cosO - yp * cosi * sinO, xp * sinO + yp * cosi * cosO, yp * sini};

  // Time derivatives of the quantities above (the ephemeris parameters are constants).
  const double Edot = n / one_minus_ecosE;
  const double vdot = Edot * sqrt_1me2 / one_minus_ecosE;
  const double udot = vdot * (1.0 + 2.0 * (eph.cus_rad * c2 - eph.cuc_rad * s2));
  const double rdot = A * e * sinE * Edot + 2.0 * vdot * (eph.crs_m * c2 - eph.crc_m * s2);
  const double idot = eph.idot_radps + 2.0 * vdot * (eph.cis_rad * c2 - eph.cic_rad * s2);
  const double xpdot = rdot * std::cos(u) - r * udot * std::sin(u);
  const double ypdot = rdot * std::sin(u) + r * udot * std::cos(u);
  s.v_e_mps = {
      xpdot * cosO - ypdot * cosi * sinO + yp * sini * idot * sinO - omega_dot_k * (xp * sinO + yp * cosi * cosO),
      xpdot * sinO + ypdot * cosi * cosO - yp * sini * idot * cosO + omega_dot_k * (xp * cosO - yp * cosi * sinO),
      ypdot * sini + yp * cosi * idot};

  // Clock: IS-GPS-200 20.3.3.3.3.1, with dt = t - toc wrapped like t_k.
  const double dt = wrap_half_week(seconds_between(t, eph.toc()));
  const double rel_factor = kRelativisticF_spsqrtm * e * eph.sqrt_a_sqrtm;
  s.relativistic_s = rel_factor * sinE;
  s.clock_bias_s = eph.af0_s + eph.af1_sps * dt + eph.af2_sps2 * dt * dt + s.relativistic_s;
  s.clock_drift_sps = eph.af1_sps + 2.0 * eph.af2_sps2 * dt + rel_factor * cosE * Edot;
  s.tgd_s = eph.tgd_s;
  return s;
}

double l1_ca_clock_correction_s(const Ephemeris& eph, const GpsTime& t) {
  const SatelliteState s = satellite_state(eph, t);
  return s.clock_bias_s - s.tgd_s;
}

Eigen::Vector3d rotate_to_receive_frame(const Eigen::Vector3d& r_e_transmit, double travel_time_s) {
  // The receive-time ECEF axes have turned by omega_e * tau about z: coordinates rotate by -omega_e*tau.
  const double a = kEarthRotationRate_radps * travel_time_s;
  const double c = std::cos(a), s = std::sin(a);
  return {c * r_e_transmit.x() + s * r_e_transmit.y(), -s * r_e_transmit.x() + c * r_e_transmit.y(), r_e_transmit.z()};
}

double geometric_range_m(const Eigen::Vector3d& r_sat_e_transmit, const Eigen::Vector3d& r_rx_e_receive) {
  double range = (r_sat_e_transmit - r_rx_e_receive).norm();
  // Fixed-point iteration on the travel time: contracts by omega_e*|r_sat|/c ~ 6e-6 per step.
  for (int i = 0; i < 5; ++i) {
    const double next = (rotate_to_receive_frame(r_sat_e_transmit, range / kSpeedOfLight_mps) - r_rx_e_receive).norm();
    const bool done = std::abs(next - range) < 1e-9;
    range = next;
    if (done) break;
  }
  return range;
}

}  // namespace ultratrack::signals
