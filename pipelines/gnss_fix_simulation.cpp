// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/gnss_fix_simulation.hpp"

#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "ins/earth_model.hpp"
#include "io/input_error.hpp"

namespace ultratrack::pipelines {

std::vector<GnssCsvRow> simulate_gnss_fixes(const ins::TruthInterpolator& truth, const GnssFixSimulationOptions& o) {
  if (!(o.rate_hz > 0.0 && o.rate_hz <= 100.0)) throw io::InputError("GNSS simulation", "rate must be in (0, 100] Hz");
  if (!(o.sigma_ned_m.minCoeff() > 0.0)) throw io::InputError("GNSS simulation", "position sigmas must be positive");
  if (!(o.white_sigma_ned_m.minCoeff() >= 0.0) || (o.stated_sigma_ned_m && !(o.stated_sigma_ned_m->minCoeff() > 0.0)))
    throw io::InputError("GNSS simulation", "white sigmas must not be negative, stated sigmas must be positive");
  const bool white_part = o.white_sigma_ned_m.maxCoeff() > 0.0;
  const Eigen::Vector3d column =
      o.stated_sigma_ned_m.value_or((o.sigma_ned_m.cwiseAbs2() + o.white_sigma_ned_m.cwiseAbs2()).cwiseSqrt());
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto gauss3 = [&] { return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)); };
  // The white part has its own generator and distribution (a normal distribution keeps the second value of each pair
  // it draws): the other errors' draws are those of the same seed without it.
  std::mt19937_64 rng_white(o.seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> normal_white(0.0, 1.0);
  auto gauss3_white = [&] {
    return Eigen::Vector3d(normal_white(rng_white), normal_white(rng_white), normal_white(rng_white));
  };
  const double dt = 1.0 / o.rate_hz;
  long long k = 0;
  while (o.first_time_s + k * dt < truth.start_s()) ++k;
  std::vector<GnssCsvRow> fixes;
  Eigen::Vector3d err = o.sigma_ned_m.cwiseProduct(gauss3());  // stationary start
  const double phi = o.correlation_time_s > 0.0 ? std::exp(-dt / o.correlation_time_s) : 0.0;
  const double drive = std::sqrt(1.0 - phi * phi);
  if (!(o.velocity_correlation_time_s >= 0.0))
    throw io::InputError("GNSS simulation", "the velocity correlation time must not be negative");
  const double phi_v = o.velocity_correlation_time_s > 0.0 ? std::exp(-dt / o.velocity_correlation_time_s) : 0.0;
  const double drive_v = std::sqrt(1.0 - phi_v * phi_v);
  Eigen::Vector3d verr = Eigen::Vector3d::Zero();
  bool first_velocity = true;
  bool first = true;
  for (double t = o.first_time_s + k * dt; t <= truth.end_s() + 1e-9; t = o.first_time_s + (++k) * dt) {
    if (!first) err = phi * err + drive * o.sigma_ned_m.cwiseProduct(gauss3());
    first = false;
    const ins::EcefMotion m = truth.antenna(t, o.lever_arm_b);
    double lat_deg = 0, lon_deg = 0, h = 0;
    GeographicLib::Geocentric::WGS84().Reverse(m.r_e.x(), m.r_e.y(), m.r_e.z(), lat_deg, lon_deg, h);
    const double lat = lat_deg * std::numbers::pi / 180.0, lon = lon_deg * std::numbers::pi / 180.0;
    const ins::Radii r = ins::radii_of_curvature(lat);
    GnssCsvRow f;
    f.t_s = t;
    const Eigen::Vector3d e =
        white_part ? Eigen::Vector3d(err + o.white_sigma_ned_m.cwiseProduct(gauss3_white())) : err;
    f.lat_rad = lat + e.x() / (r.meridian_m + h);
    f.lon_rad = lon + e.y() / ((r.transverse_m + h) * std::cos(lat));
    f.height_m = h - e.z();
    f.sigma_ned_m = column;
    f.has_velocity = o.with_velocity;
    if (o.with_velocity) {  // one draw per fix either way: white velocity errors are those of before
      const Eigen::Vector3d g = gauss3();
      verr = first_velocity ? Eigen::Vector3d(o.sigma_velocity_mps * g)
                            : phi_v * verr + drive_v * o.sigma_velocity_mps * g;
      first_velocity = false;
      f.v_n = ins::C_en(lat, lon).transpose() * m.v_e + verr;
    }
    fixes.push_back(f);
  }
  return fixes;
}

std::vector<ins::TruthSample> truth_samples_from_nav(const std::vector<ins::NavState>& nav) {
  std::vector<ins::TruthSample> out;
  out.reserve(nav.size());
  for (const auto& s : nav) {
    ins::TruthSample t;
    t.t_s = s.t_s;
    t.lat_rad = s.lat_rad;
    t.lon_rad = s.lon_rad;
    t.height_m = s.height_m;
    t.v_n = s.v_n;
    t.q_nb = s.q_nb;
    out.push_back(t);
  }
  return out;
}

}  // namespace ultratrack::pipelines
