// SPDX-License-Identifier: GPL-3.0-or-later
// Test-only simulator of multi-antenna carrier phases (independent truth for the attitude solver tests): a rigid
// array with a known attitude at a known place, satellites on a random sky, per-antenna phase = range / lambda
// + a random integer per antenna and satellite + a random line bias per antenna + white noise.
#pragma once

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "io/units.hpp"
#include "receiver/antenna_phase.hpp"
#include "signals/gps_constants.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver::testsim {

struct Sky {
  int prn;
  double azimuth_rad, elevation_rad;
};

// The seed geometry: master at the centre, slaves on the roll (x) and pitch (y) axes, 1 m and 1.025 m.
inline std::vector<Eigen::Vector3d> seed_lever_arms() {
  return {Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.025, 0.0)};
}

// Body to NED for z-y-x Euler angles, written out element by element (not through the solver's helper).
inline Eigen::Matrix3d dcm_nb(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch);
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  Eigen::Matrix3d C;
  C << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return C;
}

struct PhaseSimulator {
  Eigen::Vector3d r_master_e;
  Eigen::Matrix3d C_en;  // NED -> ECEF at the master, from GeographicLib's local frame (ENU) re-ordered
  std::vector<Eigen::Vector3d> lever;
  double sigma_m = 0.003;
  std::mt19937_64 rng;
  std::vector<long> integer_ambiguity;  // [antenna * 64 + prn]
  std::vector<double> line_bias_cycles;
  std::vector<double> range_offset;  // per prn, cycles (a large common term that must cancel)

  PhaseSimulator(std::vector<Eigen::Vector3d> lever_arms, std::uint64_t seed, double lat_deg = 36.37,
                 double lon_deg = 127.36, double h_m = 80.0)
      : lever(std::move(lever_arms)), rng(seed) {
    const auto& g = GeographicLib::Geocentric::WGS84();
    std::vector<double> M(9);
    double x, y, z;
    g.Forward(lat_deg, lon_deg, h_m, x, y, z, M);
    r_master_e = Eigen::Vector3d(x, y, z);
    Eigen::Matrix3d C_e_enu;  // columns: east, north, up in ECEF (GeographicLib's M is row-major ENU -> ECEF)
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) C_e_enu(i, j) = M[3 * static_cast<std::size_t>(i) + static_cast<std::size_t>(j)];
    }
    C_en.col(0) = C_e_enu.col(1);
    C_en.col(1) = C_e_enu.col(0);
    C_en.col(2) = -C_e_enu.col(2);
    reseed_biases();
  }

  void reseed_biases() {
    std::uniform_int_distribution<long> amb(-5000000, 5000000);
    std::uniform_real_distribution<double> bias(-20.0, 20.0), offset(1.0e7, 1.3e8);
    integer_ambiguity.assign(static_cast<std::size_t>(kMaxAntennas) * 64, 0);
    for (auto& n : integer_ambiguity) n = amb(rng);
    line_bias_cycles.assign(lever.size(), 0.0);
    for (auto& b : line_bias_cycles) b = bias(rng);
    range_offset.assign(64, 0.0);
    for (auto& r : range_offset) r = offset(rng);
  }

  long& ambiguity(int antenna, int prn) {
    return integer_ambiguity[static_cast<std::size_t>(antenna) * 64 + static_cast<std::size_t>(prn)];
  }

  // A random sky of n satellites above min_elevation (elevation uniform in sin, azimuth uniform).
  std::vector<Sky> random_sky(int n, double min_elevation_rad = 15.0 * io::kRadPerDeg) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Sky> sky;
    for (int i = 0; i < n; ++i) {
      const double s = std::sin(min_elevation_rad) + u(rng) * (1.0 - std::sin(min_elevation_rad));
      sky.push_back({i + 1, u(rng) * 2.0 * 3.14159265358979323846, std::asin(s)});
    }
    return sky;
  }

  // The satellites of the nominal 24-slot constellation above the mask at time t, seen from the master.
  std::vector<Sky> nominal_sky(const signals::GpsTime& t, double mask_rad = 10.0 * io::kRadPerDeg) const {
    std::vector<Sky> sky;
    for (const signals::Ephemeris& eph : signals::nominal_constellation(t).ephemerides) {
      const Eigen::Vector3d d_n = C_en.transpose() * (signals::satellite_state(eph, t).r_e_m - r_master_e);
      const double el = std::asin(-d_n.z() / d_n.norm());
      if (el < mask_rad) continue;
      sky.push_back({eph.prn, std::atan2(d_n.y(), d_n.x()), el});
    }
    return sky;
  }

  Eigen::Vector3d los_e(const Sky& s) const {
    const Eigen::Vector3d u_n(std::cos(s.elevation_rad) * std::cos(s.azimuth_rad),
                              std::cos(s.elevation_rad) * std::sin(s.azimuth_rad), -std::sin(s.elevation_rad));
    return C_en * u_n;
  }

  // One epoch: true attitude C_nb; slip_cycles[antenna][prn] added to the phase (and to the truth integers);
  // flagged[antenna][prn]: raise the slip flag; blocked antennas are not usable.
  AntennaPhaseEpoch epoch(const std::vector<Sky>& sky, const Eigen::Matrix3d& C_nb, double tow_s = 0.0,
                          const std::vector<bool>& blocked = {}) {
    std::normal_distribution<double> noise(0.0, sigma_m / signals::kL1Wavelength_m);
    AntennaPhaseEpoch e;
    e.receive_time = {2300, tow_s};
    e.master_position_e = r_master_e;
    for (const Sky& s : sky) {
      AntennaPhaseObservation o;
      o.prn = s.prn;
      o.los_e = los_e(s);
      o.elevation_rad = s.elevation_rad;
      o.num_antennas = static_cast<int>(lever.size());
      for (std::size_t a = 0; a < lever.size(); ++a) {
        // The far-field range change of antenna a against the array origin is -u . r_a.
        const Eigen::Vector3d r_a_e = C_en * C_nb * lever[a];
        const double range_cycles =
            range_offset[static_cast<std::size_t>(s.prn)] - o.los_e.dot(r_a_e) / signals::kL1Wavelength_m;
        o.carrier_phase_cycles[a] = range_cycles + static_cast<double>(ambiguity(static_cast<int>(a), s.prn)) +
                                    line_bias_cycles[a] + noise(rng);
        o.cn0_dbhz[a] = 45.0;
        o.usable[a] = blocked.empty() || !blocked[a];
      }
      e.satellites.push_back(o);
    }
    return e;
  }

  // True DD ambiguity of antenna k between satellites s and t.
  long true_dd(int k, int s, int t) { return ambiguity(k, s) - ambiguity(0, s) - ambiguity(k, t) + ambiguity(0, t); }
};

}  // namespace ultratrack::receiver::testsim
