// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/pvt.hpp"

#include <Eigen/Dense>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "receiver/chi_square.hpp"
#include "signals/atmosphere.hpp"
#include "signals/gps_constants.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver {
namespace {

using signals::kSpeedOfLight_mps;
using Vector4 = Eigen::Vector4d;

// Below this distance from the earth's centre the receiver position is not yet known well enough for
// elevation-dependent terms (mask, weights, atmosphere): the first iterations run without them.
constexpr double kPositionKnownRadius_m = 6.0e6;

struct Geometry {
  int prn = 0;
  Eigen::Vector3d u_e;      // unit line of sight receiver -> satellite
  double residual_m = 0.0;  // measured minus predicted pseudorange
  double rate_residual_mps = 0.0;
  bool has_rate = false;
  double weight = 1.0;  // 1 / sigma^2 (pseudorange)
  double rate_weight = 1.0;
  double elevation_rad = 0.0, azimuth_rad = 0.0;
  double cn0_dbhz = 0.0;
};

struct LocalFrame {
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Matrix3d C_enu_to_e = Eigen::Matrix3d::Identity();  // columns: east, north, up in ECEF
};

LocalFrame local_frame(const Eigen::Vector3d& r_e) {
  LocalFrame f;
  std::vector<double> m(9);
  double lat_deg, lon_deg;
  GeographicLib::Geocentric::WGS84().Reverse(r_e.x(), r_e.y(), r_e.z(), lat_deg, lon_deg, f.height_m, m);
  f.lat_rad = lat_deg * M_PI / 180.0;
  f.lon_rad = lon_deg * M_PI / 180.0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) f.C_enu_to_e(r, c) = m[3 * r + c];  // GeographicLib: row-major, ENU -> ECEF
  return f;
}

// Noise weight: 1-sigma grows as 1/sin(el) and with lower C/N0 (amplitude ratio relative to 45 dB-Hz).
double sigma_scale(double elevation_rad, double cn0_dbhz) {
  const double el = std::max(elevation_rad, 5.0 * M_PI / 180.0);
  const double cn0_factor = std::pow(10.0, (45.0 - std::min(cn0_dbhz, 55.0)) / 20.0);
  return std::max(cn0_factor, 0.3) / std::sin(el);
}

// Builds the linearised system at x = (r_e, clock bias) for the usable satellites.
std::vector<Geometry> linearise(const std::vector<SatelliteMeasurement>& meas, const signals::GpsTime& receive_time,
                                const signals::KlobucharParameters& iono, const PvtOptions& opt, const Vector4& x,
                                const Eigen::Vector3d& v_e, double drift_mps, const std::vector<bool>& active) {
  std::vector<Geometry> rows;
  const Eigen::Vector3d r_rx = x.head<3>();
  const bool position_known = r_rx.norm() > kPositionKnownRadius_m;
  const LocalFrame frame = position_known ? local_frame(r_rx) : LocalFrame{};
  for (std::size_t i = 0; i < meas.size(); ++i) {
    if (!active[i]) continue;
    const auto& m = meas[i];
    // Transmit time by the SV clock is exact from the pseudorange; GPS time follows from the SV clock model.
    const signals::GpsTime t_tx_sv = signals::add_seconds(receive_time, -m.pseudorange_m / kSpeedOfLight_mps);
    const double dt_sv = signals::l1_ca_clock_correction_s(m.ephemeris, t_tx_sv);
    const signals::GpsTime t_tx = signals::add_seconds(t_tx_sv, -dt_sv);
    const signals::SatelliteState sat = signals::satellite_state(m.ephemeris, t_tx);

    double rho = (sat.r_e_m - r_rx).norm();
    Eigen::Vector3d r_sat = signals::rotate_to_receive_frame(sat.r_e_m, rho / kSpeedOfLight_mps);
    rho = (r_sat - r_rx).norm();
    const Eigen::Vector3d v_sat = signals::rotate_to_receive_frame(sat.v_e_mps, rho / kSpeedOfLight_mps);
    Geometry g;
    g.prn = m.prn;
    g.u_e = (r_sat - r_rx) / rho;
    g.cn0_dbhz = m.cn0_dbhz;

    double delay_m = 0.0, sigma = opt.sigma_zenith_m;
    if (position_known) {
      const Eigen::Vector3d enu = frame.C_enu_to_e.transpose() * g.u_e;
      g.elevation_rad = std::asin(std::clamp(enu.z(), -1.0, 1.0));
      if (g.elevation_rad < opt.elevation_mask_rad) continue;
      const double azimuth = std::atan2(enu.x(), enu.y());
      g.azimuth_rad = azimuth < 0.0 ? azimuth + 2.0 * M_PI : azimuth;
      if (opt.ionosphere && iono.valid)
        delay_m += kSpeedOfLight_mps *
                   signals::klobuchar_delay_s(iono, frame.lat_rad, frame.lon_rad, azimuth, g.elevation_rad, t_tx.tow_s);
      if (opt.troposphere) delay_m += signals::troposphere_delay_m(frame.lat_rad, frame.height_m, g.elevation_rad);
      sigma *= sigma_scale(g.elevation_rad, m.cn0_dbhz);
    }
    const double predicted = rho + x(3) - kSpeedOfLight_mps * dt_sv + delay_m;
    g.residual_m = m.pseudorange_m - predicted;
    g.weight = 1.0 / (sigma * sigma);
    if (m.has_doppler) {
      const double rate_measured = -signals::kL1Wavelength_m * m.doppler_hz;
      // The travel time changes at tau_dot = range rate / c (~3e-6): the satellite's transmit instant
      // slides by (1 - tau_dot) and the earth-rotation correction turns by -omega x r tau_dot. Both are
      // centimetre-per-second terms; the receiver's own velocity in tau_dot is below 1 mm/s and left out.
      const double tau_dot = g.u_e.dot(v_sat) / kSpeedOfLight_mps;
      const Eigen::Vector3d omega_e(0.0, 0.0, signals::kEarthRotationRate_radps);
      const Eigen::Vector3d v_sat_apparent = (1.0 - tau_dot) * v_sat - tau_dot * omega_e.cross(r_sat);
      const double rate_predicted =
          g.u_e.dot(v_sat_apparent - v_e) + drift_mps - kSpeedOfLight_mps * sat.clock_drift_sps;
      g.rate_residual_mps = rate_measured - rate_predicted;
      g.has_rate = true;
      const double sigma_rate = opt.sigma_doppler_mps * sigma / opt.sigma_zenith_m;
      g.rate_weight = 1.0 / (sigma_rate * sigma_rate);
    }
    rows.push_back(g);
  }
  return rows;
}

struct LsqResult {
  Vector4 dx = Vector4::Zero();
  Eigen::Matrix4d normal_inverse = Eigen::Matrix4d::Zero();
  bool ok = false;
};

LsqResult weighted_lsq(const std::vector<Geometry>& rows, bool rates) {
  Eigen::Matrix4d N = Eigen::Matrix4d::Zero();
  Vector4 b = Vector4::Zero();
  int n = 0;
  for (const auto& g : rows) {
    if (rates && !g.has_rate) continue;
    Vector4 h;
    h << -g.u_e, 1.0;
    const double w = rates ? g.rate_weight : g.weight;
    N += w * h * h.transpose();
    b += w * h * (rates ? g.rate_residual_mps : g.residual_m);
    ++n;
  }
  LsqResult out;
  if (n < 4) return out;
  Eigen::LDLT<Eigen::Matrix4d> ldlt(N);
  if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-12) return out;
  out.dx = ldlt.solve(b);
  out.normal_inverse = ldlt.solve(Eigen::Matrix4d::Identity());
  out.ok = out.dx.allFinite();
  return out;
}

double weighted_sse(const std::vector<Geometry>& rows) {
  double sse = 0.0;
  for (const auto& g : rows) sse += g.weight * g.residual_m * g.residual_m;
  return sse;
}

// Iterates the position/clock solution for the active satellites. Returns false if it fails to converge.
bool iterate_position(const std::vector<SatelliteMeasurement>& meas, const signals::GpsTime& t,
                      const signals::KlobucharParameters& iono, const PvtOptions& opt, const std::vector<bool>& active,
                      Vector4& x, std::vector<Geometry>& rows, int& iterations) {
  for (iterations = 1; iterations <= opt.max_iterations + 5; ++iterations) {
    rows = linearise(meas, t, iono, opt, x, Eigen::Vector3d::Zero(), 0.0, active);
    const LsqResult lsq = weighted_lsq(rows, false);
    if (!lsq.ok) return false;
    x += lsq.dx;
    const bool was_known = (x.head<3>() - lsq.dx.head<3>()).norm() > kPositionKnownRadius_m;
    if (lsq.dx.head<3>().norm() < 1e-4 && was_known) {
      rows = linearise(meas, t, iono, opt, x, Eigen::Vector3d::Zero(), 0.0, active);
      return rows.size() >= 4;
    }
  }
  return false;
}

}  // namespace

bool PvtOptions::IsValid(std::string* why) const {
  const std::string problem = [&]() -> std::string {
    if (!(elevation_mask_rad >= -M_PI / 2 && elevation_mask_rad < M_PI / 2))
      return "elevation mask outside [-90, 90) deg";
    if (!(false_alarm_probability > 0.0 && false_alarm_probability < 1.0))
      return "false-alarm probability not in (0, 1)";
    if (!(sigma_zenith_m > 0.0) || !(sigma_doppler_mps > 0.0)) return "measurement sigmas must be positive";
    if (max_iterations < 1) return "max_iterations must be at least 1";
    if (!(max_gdop > 0.0)) return "max_gdop must be positive";
    return {};
  }();
  if (why) *why = problem;
  return problem.empty();
}

PvtSolution solve_pvt(const std::vector<SatelliteMeasurement>& meas, const signals::GpsTime& receive_time,
                      const signals::KlobucharParameters& iono, const PvtOptions& opt,
                      const Eigen::Vector3d& initial_r_e_m) {
  PvtSolution sol;
  std::vector<bool> active(meas.size(), true);
  for (std::size_t i = 0; i < meas.size(); ++i) {
    const auto& m = meas[i];
    if ((opt.exclude_unhealthy && m.ephemeris.health != 0) || !std::isfinite(m.pseudorange_m)) active[i] = false;
  }

  Vector4 x = Vector4::Zero();
  x.head<3>() = initial_r_e_m;
  std::vector<Geometry> rows;
  int iterations = 0;
  if (!iterate_position(meas, receive_time, iono, opt, active, x, rows, iterations)) {
    sol.failure = "position did not converge with the usable satellites";
    return sol;
  }

  // Residual test: weighted SSE against the chi-square bound; try excluding each satellite once.
  auto passes = [&](const std::vector<Geometry>& r) {
    const int dof = static_cast<int>(r.size()) - 4;
    return dof < 1 || weighted_sse(r) <= chi_square_upper_quantile(dof, opt.false_alarm_probability);
  };
  if (opt.fault_exclusion && !passes(rows) && rows.size() >= 6) {
    double best_sse = std::numeric_limits<double>::infinity();
    std::optional<int> best_prn;
    Vector4 best_x = x;
    std::vector<Geometry> best_rows;
    for (const auto& candidate : rows) {
      std::vector<bool> trial = active;
      for (std::size_t i = 0; i < meas.size(); ++i)
        if (meas[i].prn == candidate.prn) trial[i] = false;
      Vector4 xt = x;
      std::vector<Geometry> rt;
      int it = 0;
      if (!iterate_position(meas, receive_time, iono, opt, trial, xt, rt, it)) continue;
      const double sse = weighted_sse(rt);
      if (sse < best_sse && passes(rt)) {
        best_sse = sse;
        best_prn = candidate.prn;
        best_x = xt;
        best_rows = rt;
      }
    }
    if (best_prn) {
      sol.excluded_prn = best_prn;
      x = best_x;
      rows = best_rows;
      for (std::size_t i = 0; i < meas.size(); ++i)
        if (meas[i].prn == *best_prn) active[i] = false;
    }
  }

  sol.valid = true;
  sol.iterations = iterations;
  sol.r_e_m = x.head<3>();
  sol.clock_bias_m = x(3);
  sol.time = signals::add_seconds(receive_time, -x(3) / kSpeedOfLight_mps);
  const LocalFrame frame = local_frame(sol.r_e_m);
  sol.lat_rad = frame.lat_rad;
  sol.lon_rad = frame.lon_rad;
  sol.height_m = frame.height_m;
  double sq = 0.0;
  for (const auto& g : rows) {
    sol.used_prns.push_back(g.prn);
    sol.satellites.push_back({g.prn, g.elevation_rad, g.azimuth_rad, g.residual_m, g.cn0_dbhz});
    sq += g.residual_m * g.residual_m;
  }
  sol.residual_rms_m = std::sqrt(sq / rows.size());
  if (const LsqResult w = weighted_lsq(rows, false); w.ok) sol.covariance_m2 = w.normal_inverse;

  // DOPs from the unweighted geometry.
  Eigen::Matrix4d G = Eigen::Matrix4d::Zero();
  for (const auto& g : rows) {
    Vector4 h;
    h << -g.u_e, 1.0;
    G += h * h.transpose();
  }
  const Eigen::Matrix4d Q = G.inverse();
  const Eigen::Matrix3d Q_enu = frame.C_enu_to_e.transpose() * Q.topLeftCorner<3, 3>() * frame.C_enu_to_e;
  sol.gdop = std::sqrt(Q.trace());
  sol.pdop = std::sqrt(Q.topLeftCorner<3, 3>().trace());
  sol.hdop = std::sqrt(Q_enu(0, 0) + Q_enu(1, 1));
  sol.vdop = std::sqrt(Q_enu(2, 2));
  sol.tdop = std::sqrt(Q(3, 3));
  if (!(sol.gdop <= opt.max_gdop)) {
    sol.valid = false;
    sol.failure = "GDOP " + std::to_string(sol.gdop) + " above the limit " + std::to_string(opt.max_gdop);
    return sol;
  }

  // Velocity and clock drift: one linear solve (the range-rate model is linear in them).
  std::vector<Geometry> rate_rows = linearise(meas, receive_time, iono, opt, x, Eigen::Vector3d::Zero(), 0.0, active);
  const LsqResult rate = weighted_lsq(rate_rows, true);
  if (rate.ok) {
    sol.v_e_mps = rate.dx.head<3>();
    sol.clock_drift_mps = rate.dx(3);
    sol.velocity_valid = true;
    sol.velocity_covariance_m2ps2 = rate.normal_inverse;
    sol.v_enu_mps = frame.C_enu_to_e.transpose() * sol.v_e_mps;
  }
  return sol;
}

}  // namespace ultratrack::receiver
