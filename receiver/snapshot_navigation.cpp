// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/snapshot_navigation.hpp"

#include <Eigen/Dense>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <cmath>
#include <limits>

#include "receiver/chi_square.hpp"
#include "receiver/pvt.hpp"
#include "signals/atmosphere.hpp"
#include "signals/gps_constants.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver {
namespace {

using signals::kSpeedOfLight_mps;
constexpr double kMillisecond_s = 1e-3;
constexpr double kChip_m = kSpeedOfLight_mps / signals::kCaChipRate_hz;
// Elevation-dependent terms (mask, weights, atmosphere) wait until the position is near the earth's surface.
constexpr double kNearSurface_m = 6.0e6;
constexpr double kPi = 3.14159265358979323846;

// Geodetic position and the ENU axes (columns, in ECEF) at an ECEF point.
struct Geodetic {
  double lat_rad = 0.0, lon_rad = 0.0, height_m = 0.0;
  Eigen::Matrix3d enu_axes_e = Eigen::Matrix3d::Identity();
};

Geodetic geodetic(const Eigen::Vector3d& r_e) {
  Geodetic g;
  std::vector<double> rotation(9);
  double lat_deg = 0.0, lon_deg = 0.0;
  GeographicLib::Geocentric::WGS84().Reverse(r_e.x(), r_e.y(), r_e.z(), lat_deg, lon_deg, g.height_m, rotation);
  g.lat_rad = lat_deg * kPi / 180.0;
  g.lon_rad = lon_deg * kPi / 180.0;
  g.enu_axes_e = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation.data());
  return g;
}

// One satellite seen from r_rx for a transmit time by the SV clock.
struct Sighting {
  Eigen::Vector3d u_e = Eigen::Vector3d::UnitX();  // receiver -> satellite
  Eigen::Vector3d v_sat_e = Eigen::Vector3d::Zero();
  double range_m = 0.0;
  double sv_clock_s = 0.0;  // L1 C/A correction: af polynomial + relativistic - TGD
  double delay_m = 0.0;     // ionosphere + troposphere (0 until near the surface)
  double elevation_rad = kPi / 2.0, azimuth_rad = 0.0;
  bool located = false;  // elevation and delays computed
  // The modelled pseudorange without receiver clock: range - c dt_sv + delays.
  double pseudorange_m() const { return range_m - kSpeedOfLight_mps * sv_clock_s + delay_m; }
  // Range rate of the satellite's motion alone (the coarse-time column).
  double satellite_rate_mps() const { return u_e.dot(v_sat_e); }
};

Sighting sight(const SnapshotMeasurement& m, const signals::GpsTime& t_tx_sv, const Eigen::Vector3d& r_rx,
               const SnapshotOptions& opt) {
  Sighting s;
  s.sv_clock_s = signals::l1_ca_clock_correction_s(m.ephemeris, t_tx_sv);
  const signals::GpsTime t_tx = signals::add_seconds(t_tx_sv, -s.sv_clock_s);
  const signals::SatelliteState state = signals::satellite_state(m.ephemeris, t_tx);
  const double travel_s = (state.r_e_m - r_rx).norm() / kSpeedOfLight_mps;
  const Eigen::Vector3d r_sat = signals::rotate_to_receive_frame(state.r_e_m, travel_s);
  s.range_m = (r_sat - r_rx).norm();
  s.v_sat_e = signals::rotate_to_receive_frame(state.v_e_mps, travel_s);
  s.u_e = (r_sat - r_rx) / s.range_m;
  if (r_rx.norm() > kNearSurface_m) {
    const Geodetic g = geodetic(r_rx);
    const Eigen::Vector3d enu = g.enu_axes_e.transpose() * s.u_e;
    s.elevation_rad = std::asin(std::clamp(enu.z(), -1.0, 1.0));
    s.azimuth_rad = std::atan2(enu.x(), enu.y());
    if (s.azimuth_rad < 0.0) s.azimuth_rad += 2.0 * kPi;
    s.located = true;
    if (s.elevation_rad > 0.0) {
      if (opt.ionosphere && opt.klobuchar.valid)
        s.delay_m += kSpeedOfLight_mps * signals::klobuchar_delay_s(opt.klobuchar, g.lat_rad, g.lon_rad, s.azimuth_rad,
                                                                    s.elevation_rad, t_tx.tow_s);
      if (opt.troposphere) s.delay_m += signals::troposphere_delay_m(g.lat_rad, g.height_m, s.elevation_rad);
    }
  }
  return s;
}

double pseudorange_sigma_m(const SnapshotMeasurement& m, const Sighting& s, const SnapshotOptions& opt) {
  const double sin_el = std::sin(std::max(s.elevation_rad, 5.0 * kPi / 180.0));
  const double code = m.code_sigma_chips * kChip_m;
  const double model = opt.model_sigma_m / sin_el;
  return std::sqrt(code * code + model * model);
}

// Step 1: the full transmit times by the SV clock, t_tx_sv = M ms + code phase / 1.023 MHz, from (x0, t0).
std::vector<signals::GpsTime> transmit_times(const std::vector<SnapshotMeasurement>& meas, const signals::GpsTime& t0,
                                             const Eigen::Vector3d& x0, const SnapshotOptions& opt) {
  const std::size_t n = meas.size();
  std::vector<double> predicted_m(n), fraction_s(n);
  std::size_t reference = 0;
  double best_elevation = -10.0;
  for (std::size_t i = 0; i < n; ++i) {
    fraction_s[i] = meas[i].code_phase_chips / signals::kCaChipRate_hz;
    Sighting s = sight(meas[i], signals::add_seconds(t0, -0.075), x0, opt);
    s = sight(meas[i], signals::add_seconds(t0, -s.pseudorange_m() / kSpeedOfLight_mps), x0, opt);
    predicted_m[i] = s.pseudorange_m();
    const double elevation = s.located ? s.elevation_rad : -1.0;
    if (elevation > best_elevation) best_elevation = elevation, reference = i;
  }
  // Integer milliseconds counted from t0's week start; t0 - rho/c - fraction is the SV-time ms boundary.
  auto boundary_ms = [&](std::size_t i, double common_s) {
    return (t0.tow_s - predicted_m[i] / kSpeedOfLight_mps - common_s - fraction_s[i]) / kMillisecond_s;
  };
  const double m_ref = std::round(boundary_ms(reference, 0.0));
  const double common_s = (boundary_ms(reference, 0.0) - m_ref) * kMillisecond_s;  // receiver clock, |.| <= 0.5 ms
  std::vector<signals::GpsTime> t_tx(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double m = i == reference ? m_ref : std::round(boundary_ms(i, common_s));
    t_tx[i] = signals::normalised(signals::GpsTime{t0.week, m * kMillisecond_s + fraction_s[i]});
  }
  return t_tx;
}

using Vector5 = Eigen::Matrix<double, 5, 1>;
using Matrix5 = Eigen::Matrix<double, 5, 5>;

struct Estimate {
  bool converged = false;
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  double clock_m = 0.0, time_s = 0.0;
  Matrix5 covariance = Matrix5::Zero();
  double statistic = 0.0;  // weighted SSE
  int used = 0;
};

// Step 2 over the `active` satellites (those below the mask at the solution drop out).
Estimate coarse_time_lsq(const std::vector<SnapshotMeasurement>& meas, const std::vector<signals::GpsTime>& t_tx_sv,
                         const signals::GpsTime& t0, const Eigen::Vector3d& r0, double clock0_m, double time0_s,
                         std::vector<bool>& active, const SnapshotOptions& opt) {
  Estimate e;
  e.r_e_m = r0;
  e.clock_m = clock0_m;
  e.time_s = time0_s;
  const std::size_t n = meas.size();
  for (int iteration = 0; iteration < opt.max_iterations; ++iteration) {
    Eigen::MatrixXd H(n, 5);
    Eigen::VectorXd z(n), w(n);
    int rows = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!active[i]) continue;
      const Sighting s = sight(meas[i], signals::add_seconds(t_tx_sv[i], e.time_s), e.r_e_m, opt);
      if (s.located && s.elevation_rad < opt.elevation_mask_rad) {
        active[i] = false;
        continue;
      }
      const double measured_m = kSpeedOfLight_mps * signals::seconds_between(t0, t_tx_sv[i]);
      H.row(rows) << -s.u_e.transpose(), 1.0, s.satellite_rate_mps();
      z(rows) = measured_m - (s.pseudorange_m() + e.clock_m);
      const double sigma = pseudorange_sigma_m(meas[i], s, opt);
      w(rows) = 1.0 / (sigma * sigma);
      ++rows;
    }
    e.used = rows;
    if (rows < 5) return e;
    const Eigen::MatrixXd Hr = H.topRows(rows);
    const Eigen::VectorXd zr = z.head(rows), wr = w.head(rows);
    const Matrix5 normal = Hr.transpose() * wr.asDiagonal() * Hr;
    Eigen::LDLT<Matrix5> ldlt(normal);
    if (ldlt.info() != Eigen::Success) return e;
    const Vector5 dx = ldlt.solve(Hr.transpose() * wr.asDiagonal() * zr);
    if (!dx.allFinite()) return e;
    e.r_e_m += dx.head<3>();
    e.clock_m += dx(3);
    e.time_s += dx(4);
    e.covariance = ldlt.solve(Matrix5::Identity());
    e.statistic = (zr - Hr * dx).cwiseAbs2().dot(wr);
    if (dx.head<3>().norm() < 1e-3 && std::fabs(dx(4)) < 1e-7 && e.r_e_m.norm() > kNearSurface_m) {
      e.converged = true;
      return e;
    }
    if (e.r_e_m.norm() > 1e8 || std::fabs(e.time_s) > 3600.0) return e;
  }
  return e;
}

double threshold_for(int used, const SnapshotOptions& opt) {
  return used > 5 ? chi_square_upper_quantile(used - 5, opt.false_alarm_probability)
                  : std::numeric_limits<double>::infinity();
}

// Step 3: the estimate with at most opt.max_exclusions satellites left out by the residual test.
Estimate with_fault_exclusion(const std::vector<SnapshotMeasurement>& meas, const std::vector<signals::GpsTime>& t_tx,
                              const signals::GpsTime& t0, const Eigen::Vector3d& x0, double clock0_m,
                              std::vector<bool>& active, int exclusions_left, const SnapshotOptions& opt) {
  Estimate e = coarse_time_lsq(meas, t_tx, t0, x0, clock0_m, 0.0, active, opt);
  if (!e.converged || e.statistic <= threshold_for(e.used, opt) || exclusions_left == 0 || e.used <= 6) return e;
  Estimate best;
  std::vector<bool> best_active;
  double best_ratio = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < meas.size(); ++k) {
    if (!active[k]) continue;
    std::vector<bool> trial = active;
    trial[k] = false;
    Estimate t = coarse_time_lsq(meas, t_tx, t0, e.r_e_m, e.clock_m, e.time_s, trial, opt);
    if (!t.converged) continue;
    const double ratio = t.statistic / threshold_for(t.used, opt);
    if (ratio < best_ratio) best_ratio = ratio, best = t, best_active = trial;
  }
  if (best_active.empty()) return e;
  if (best_ratio > 1.0 && exclusions_left > 1) {
    std::vector<bool> trial = best_active;
    Estimate again = with_fault_exclusion(meas, t_tx, t0, best.r_e_m, best.clock_m, trial, exclusions_left - 1, opt);
    if (again.converged && again.statistic / threshold_for(again.used, opt) < best_ratio) {
      active = trial;
      return again;
    }
  }
  active = best_active;
  return best;
}

// Velocity and clock drift from the Doppler at a known position (4 unknowns); fills the Doppler residuals.
void doppler_velocity(const std::vector<SnapshotMeasurement>& meas, const std::vector<signals::GpsTime>& t_tx,
                      const std::vector<bool>& active, SnapshotSolution& sol, const SnapshotOptions& opt) {
  const std::size_t n = meas.size();
  Eigen::MatrixXd H(n, 4);
  Eigen::VectorXd z(n), w(n);
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < n; ++i) {
    if (!active[i]) continue;
    const Sighting s = sight(meas[i], signals::add_seconds(t_tx[i], sol.time_correction_s), sol.r_e_m, opt);
    const auto r = static_cast<Eigen::Index>(index.size());
    // -lambda D = u . (v_sat - v) + drift
    H.row(r) << -s.u_e.transpose(), 1.0;
    z(r) = -signals::kL1Wavelength_m * meas[i].doppler_hz - s.satellite_rate_mps();
    const double sigma = signals::kL1Wavelength_m * meas[i].doppler_sigma_hz;
    w(r) = 1.0 / (sigma * sigma);
    index.push_back(i);
  }
  const auto rows = static_cast<Eigen::Index>(index.size());
  if (rows < 5) return;
  const Eigen::MatrixXd Hr = H.topRows(rows);
  const Eigen::VectorXd zr = z.head(rows), wr = w.head(rows);
  const Eigen::Vector4d x = (Hr.transpose() * wr.asDiagonal() * Hr).ldlt().solve(Hr.transpose() * wr.asDiagonal() * zr);
  const Eigen::VectorXd residual = zr - Hr * x;
  sol.v_e_mps = x.head<3>();
  sol.clock_drift_mps = x(3);
  sol.velocity_valid = rows >= 7;
  sol.doppler_statistic = residual.cwiseAbs2().dot(wr);
  for (Eigen::Index r = 0; r < rows; ++r)
    sol.satellites[index[static_cast<std::size_t>(r)]].doppler_residual_hz = -residual(r) / signals::kL1Wavelength_m;
}

int usable_count(const std::vector<SnapshotMeasurement>& meas) {
  return static_cast<int>(std::count_if(meas.begin(), meas.end(), [](const auto& m) { return m.prn > 0; }));
}

}  // namespace

bool SnapshotOptions::IsValid(std::string* why) const {
  const std::string problem = [&]() -> std::string {
    if (!(elevation_mask_rad >= -kPi / 2 && elevation_mask_rad < kPi / 2)) return "elevation mask out of range";
    if (!(model_sigma_m > 0.0)) return "model sigma must be > 0";
    if (!(time_sigma_s > 0.0 && time_sigma_s <= 600.0)) return "time sigma must be in (0, 600] s";
    if (!(false_alarm_probability > 0.0 && false_alarm_probability < 0.5))
      return "false-alarm probability out of (0, 0.5)";
    if (max_exclusions < 0) return "max exclusions must be >= 0";
    if (!(grid_step_m > 1e3 && grid_radius_m >= 0.0)) return "grid step must be > 1 km, radius >= 0";
    if (max_iterations < 1) return "max iterations must be >= 1";
    return {};
  }();
  if (why) *why = problem;
  return problem.empty();
}

std::optional<Eigen::Vector3d> doppler_position(const std::vector<SnapshotMeasurement>& meas,
                                                const signals::GpsTime& approx_time) {
  const std::size_t n = meas.size();
  if (n < 4) return std::nullopt;
  SnapshotOptions plain;
  plain.ionosphere = plain.troposphere = false;
  const signals::GpsTime t_tx = signals::add_seconds(approx_time, -0.075);
  Eigen::Vector3d mean_direction = Eigen::Vector3d::Zero();
  for (const auto& m : meas) mean_direction += signals::satellite_state(m.ephemeris, t_tx).r_e_m.normalized();
  Eigen::Vector3d r = 6.371e6 * mean_direction.normalized();
  double drift_mps = 0.0;
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::MatrixXd H(n, 4);
    Eigen::VectorXd z(n);
    for (std::size_t i = 0; i < n; ++i) {
      // Satellite in the receive frame; the receiver's small distance from the truth changes it by < 1 m.
      const Sighting s = sight(meas[i], t_tx, Eigen::Vector3d::Zero(), plain);
      const Eigen::Vector3d r_sat = s.u_e * s.range_m;  // from the earth's centre
      const Eigen::Vector3d los = r_sat - r;
      const double range = los.norm();
      const Eigen::Vector3d u = los / range;
      const double rate = u.dot(s.v_sat_e);
      // d(u . v_sat)/dr = -(v_sat - (u . v_sat) u) / range
      H.row(static_cast<Eigen::Index>(i)) << (-(s.v_sat_e - rate * u) / range).transpose(), 1.0;
      z(static_cast<Eigen::Index>(i)) = -signals::kL1Wavelength_m * meas[i].doppler_hz - (rate + drift_mps);
    }
    const Eigen::Vector4d dx = (H.transpose() * H).ldlt().solve(H.transpose() * z);
    if (!dx.allFinite()) return std::nullopt;
    // Steps are limited: the problem is very nonlinear far from the solution.
    const double step = dx.head<3>().norm();
    const double scale = step > 1.0e6 ? 1.0e6 / step : 1.0;
    r += scale * dx.head<3>();
    drift_mps += scale * dx(3);
    if (step < 1.0) break;
  }
  if (!r.allFinite() || r.norm() < 5.0e6 || r.norm() > 8.0e6) return std::nullopt;
  return r;
}

SnapshotSolution solve_snapshot_from(const std::vector<SnapshotMeasurement>& meas, const signals::GpsTime& t0,
                                     const Eigen::Vector3d& x0, const SnapshotOptions& opt) {
  SnapshotSolution sol;
  sol.candidates_tried = 1;
  if (usable_count(meas) < 5) {
    sol.failure = "fewer than 5 satellites";
    return sol;
  }
  const std::vector<signals::GpsTime> t_tx = transmit_times(meas, t0, x0, opt);
  // Initial clock: the reference's offset, common to all by construction (mean of the prediction errors).
  double clock0 = 0.0;
  for (std::size_t i = 0; i < meas.size(); ++i) {
    const Sighting s = sight(meas[i], t_tx[i], x0, opt);
    clock0 += kSpeedOfLight_mps * signals::seconds_between(t0, t_tx[i]) - s.pseudorange_m();
  }
  clock0 /= static_cast<double>(meas.size());
  std::vector<bool> active(meas.size(), true);
  const Estimate e = with_fault_exclusion(meas, t_tx, t0, x0, clock0, active, opt.max_exclusions, opt);
  if (!e.converged) {
    sol.failure = e.used < 5 ? "fewer than 5 satellites above the elevation mask" : "no convergence";
    return sol;
  }
  sol.r_e_m = e.r_e_m;
  sol.clock_bias_m = e.clock_m;
  sol.time_correction_s = e.time_s - e.clock_m / kSpeedOfLight_mps;
  sol.time = signals::add_seconds(t0, sol.time_correction_s);
  const Geodetic g = geodetic(e.r_e_m);
  sol.lat_rad = g.lat_rad;
  sol.lon_rad = g.lon_rad;
  sol.height_m = g.height_m;
  const Eigen::Matrix3d position_cov = g.enu_axes_e.transpose() * e.covariance.topLeftCorner<3, 3>() * g.enu_axes_e;
  sol.sigma_enu_m = position_cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  sol.sigma_clock_m = std::sqrt(std::max(e.covariance(3, 3), 0.0));
  // The time correction is time_s - clock / c: its variance includes their covariance.
  const double c = kSpeedOfLight_mps;
  sol.sigma_time_s =
      std::sqrt(std::max(e.covariance(4, 4) + e.covariance(3, 3) / (c * c) - 2.0 * e.covariance(3, 4) / c, 0.0));
  sol.used = e.used;
  sol.test_statistic = e.statistic;
  sol.test_threshold = threshold_for(e.used, opt);
  double sum2 = 0.0, weight_sum = 0.0;
  for (std::size_t i = 0; i < meas.size(); ++i) {
    const Sighting s = sight(meas[i], signals::add_seconds(t_tx[i], e.time_s), e.r_e_m, opt);
    SnapshotSatellite sat;
    sat.prn = meas[i].prn;
    sat.used = active[i];
    sat.elevation_rad = s.elevation_rad;
    sat.azimuth_rad = s.azimuth_rad;
    sat.cn0_dbhz = meas[i].cn0_dbhz;
    sat.residual_m = kSpeedOfLight_mps * signals::seconds_between(t0, t_tx[i]) - (s.pseudorange_m() + e.clock_m);
    sat.sigma_m = pseudorange_sigma_m(meas[i], s, opt);
    if (active[i]) {
      sum2 += sat.residual_m * sat.residual_m;
      weight_sum += 1.0;
    } else if (s.elevation_rad >= opt.elevation_mask_rad) {
      sol.excluded_prns.push_back(sat.prn);
    }
    sol.satellites.push_back(sat);
  }
  sol.residual_rms_m = std::sqrt(sum2 / std::max(weight_sum, 1.0));
  doppler_velocity(meas, t_tx, active, sol, opt);
  const bool passes = e.statistic <= sol.test_threshold;
  sol.quality = e.used == 5 ? "unverified" : (passes ? "pass" : "fail");
  sol.valid = true;
  if (std::fabs(sol.time_correction_s) > 3.0 * opt.time_sigma_s) {
    sol.valid = false;
    sol.failure =
        "the solved time is " + std::to_string(sol.time_correction_s) +
        " s from the approximate time, beyond the search (3 x time sigma = " + std::to_string(3.0 * opt.time_sigma_s) +
        " s)";
  } else if (std::fabs(sol.height_m) > opt.max_height_m) {
    sol.valid = false;
    sol.failure = "the solved height " + std::to_string(sol.height_m) + " m is not plausible";
  }
  return sol;
}

SnapshotSolution solve_snapshot(const std::vector<SnapshotMeasurement>& meas, const signals::GpsTime& t0,
                                const std::optional<Eigen::Vector3d>& approx_r_e_m, const SnapshotOptions& opt) {
  if (usable_count(meas) < 5) {
    SnapshotSolution sol;
    sol.failure = "fewer than 5 usable satellites (" + std::to_string(usable_count(meas)) + ")";
    return sol;
  }
  if (approx_r_e_m) {
    SnapshotSolution sol = solve_snapshot_from(meas, t0, *approx_r_e_m, opt);
    sol.a_priori = "approximate position";
    return sol;
  }
  const std::optional<Eigen::Vector3d> seed = doppler_position(meas, t0);
  std::vector<Eigen::Vector3d> candidates;
  std::vector<double> distances;  // from the Doppler fix (grid around it only)
  if (seed) {
    // Rings of a-priori positions around the Doppler fix, nearest first, on the sphere through the seed's foot.
    const Geodetic g = geodetic(*seed);
    double x = 0, y = 0, z = 0;
    GeographicLib::Geocentric::WGS84().Forward(g.lat_rad * 180.0 / kPi, g.lon_rad * 180.0 / kPi, 0.0, x, y, z);
    const Eigen::Vector3d foot(x, y, z);
    const int steps = static_cast<int>(opt.grid_radius_m / opt.grid_step_m);
    std::vector<std::pair<double, Eigen::Vector3d>> ring;
    for (int i = -steps; i <= steps; ++i)
      for (int j = -steps; j <= steps; ++j) {
        const double east = i * opt.grid_step_m, north = j * opt.grid_step_m;
        const double d = std::hypot(east, north);
        if (d > opt.grid_radius_m) continue;
        const Eigen::Vector3d p = foot + g.enu_axes_e.col(0) * east + g.enu_axes_e.col(1) * north;
        ring.emplace_back(d, p * (foot.norm() / p.norm()));
      }
    std::stable_sort(ring.begin(), ring.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [d, p] : ring) {
      candidates.push_back(p);
      distances.push_back(d);
    }
  } else {
    // No Doppler fix: a global grid of a-priori positions under the satellites (every 2 degrees ~ 220 km is
    // too coarse for the integers; 1 degree of latitude, longitude spaced to keep ~110 km).
    for (double lat = -89.5; lat < 90.0; lat += 1.0)
      for (double lon = -180.0; lon < 180.0; lon += 1.0 / std::max(std::cos(lat * kPi / 180.0), 0.02)) {
        double x = 0, y = 0, z = 0;
        GeographicLib::Geocentric::WGS84().Forward(lat, lon, 0.0, x, y, z);
        candidates.emplace_back(x, y, z);
      }
  }
  // Pass 1: candidates without fault exclusion, nearest the Doppler fix first; keep distinct converged solutions
  // that fit to < 1 km. Once one passes both residual tests with 2+ degrees of freedom, the search goes on only
  // to kStopMargin_m beyond the candidate that found it (other solutions that fit come from a-priori positions
  // near it: a wrong millisecond set is hundreds of km away, and the Doppler residuals reject it there).
  constexpr double kStopMargin_m = 3.0e5;
  SnapshotOptions quick = opt;
  quick.max_exclusions = 0;
  std::vector<SnapshotSolution> found;
  int tried = 0;
  double stop_beyond_m = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const Eigen::Vector3d& c = candidates[k];
    if (k < distances.size() && distances[k] > stop_beyond_m) break;
    ++tried;
    SnapshotSolution s = solve_snapshot_from(meas, t0, c, quick);
    const bool strong = s.valid && s.used >= 7 && s.test_statistic <= s.test_threshold &&
                        s.doppler_statistic <= chi_square_upper_quantile(s.used - 4, opt.false_alarm_probability);
    if (strong && k < distances.size()) stop_beyond_m = std::min(stop_beyond_m, distances[k] + kStopMargin_m);
    if (s.used < 5 || !(s.residual_rms_m < 1000.0) || std::fabs(s.height_m) > opt.max_height_m) continue;
    if (std::fabs(s.time_correction_s) > 3.0 * opt.time_sigma_s) continue;
    const bool known =
        std::any_of(found.begin(), found.end(), [&](const auto& f) { return (f.r_e_m - s.r_e_m).norm() < 1000.0; });
    if (!known) found.push_back(std::move(s));
  }
  // Pass 2: the distinct ones again with fault exclusion, ranked by pseudorange and Doppler cost.
  std::vector<SnapshotSolution> ranked;
  for (const SnapshotSolution& f : found) {
    SnapshotSolution s = solve_snapshot_from(meas, t0, f.r_e_m, opt);
    if (!s.valid && s.used < 5) continue;
    ranked.push_back(std::move(s));
  }
  auto cost = [](const SnapshotSolution& s) {
    const double pr = s.test_statistic / std::max(s.used - 5, 1);
    return pr + s.doppler_statistic / std::max(s.used - 4, 1) + (s.valid ? 0.0 : 1e9);
  };
  std::sort(ranked.begin(), ranked.end(), [&](const auto& a, const auto& b) { return cost(a) < cost(b); });
  SnapshotSolution best;
  if (ranked.empty()) {
    best.failure = seed ? "no a-priori position around the Doppler fix gave a consistent solution"
                        : "no Doppler fix and no a-priori position gave a consistent solution";
  } else {
    best = ranked.front();
    // Ambiguity: a second distinct solution that also passes and costs less than twice as much.
    int passing = 0;
    for (const auto& s : ranked) passing += s.valid && s.quality == "pass";
    best.distinct_solutions = passing;
    if (ranked.size() > 1 && ranked[1].valid && ranked[1].quality != "fail" &&
        (ranked[1].r_e_m - best.r_e_m).norm() > 1000.0 && cost(ranked[1]) < 2.0 * cost(best) + 5.0)
      best.quality = "fail";
  }
  best.a_priori = "doppler";
  best.doppler_fix_r_e_m = seed;
  best.candidates_tried = tried;
  return best;
}

}  // namespace ultratrack::receiver
