// SPDX-License-Identifier: GPL-3.0-or-later
// PVT against simulator truth: pseudoranges and Dopplers are generated here from a known receiver
// position, velocity and clock with an independent light-time iteration, then solved for.
#include "receiver/pvt.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <GeographicLib/Geocentric.hpp>
#include <cmath>

#include "receiver/chi_square.hpp"
#include "signals/atmosphere.hpp"
#include "signals/gps_constants.hpp"
#include "signals/satellite_state.hpp"

using namespace ultratrack;
using signals::kSpeedOfLight_mps;

namespace {

const signals::GpsTime kEpoch{2190, 518400.0};

// A near-circular GPS-like orbit in plane `plane` (0..5) at mean anomaly m0_deg.
signals::Ephemeris orbit(int prn, int plane, double m0_deg) {
  signals::Ephemeris e;
  e.prn = prn;
  e.week = kEpoch.week;
  e.toe_s = e.toc_s = kEpoch.tow_s;
  e.sqrt_a_sqrtm = std::sqrt(26559.7e3);
  e.e = 0.005;
  e.i0_rad = 55.0 * M_PI / 180.0;
  e.omega0_rad = (plane * 60.0 - 160.0) * M_PI / 180.0;
  e.m0_rad = m0_deg * M_PI / 180.0;
  e.omega_rad = 0.3;
  e.omega_dot_radps = -8e-9;
  e.af0_s = 1e-5 * (prn % 5 - 2);
  e.af1_sps = 1e-12 * (prn % 3);
  e.tgd_s = -5e-9;
  e.iode = e.iodc = prn;
  return e;
}

struct Receiver {
  Eigen::Vector3d r_e, v_e;
  double clock_bias_m, clock_drift_mps;
  double lat_rad, lon_rad, height_m;
};

Receiver make_receiver(double lat_deg, double lon_deg, double h) {
  Receiver rx{};
  GeographicLib::Geocentric::WGS84().Forward(lat_deg, lon_deg, h, rx.r_e.x(), rx.r_e.y(), rx.r_e.z());
  rx.lat_rad = lat_deg * M_PI / 180.0;
  rx.lon_rad = lon_deg * M_PI / 180.0;
  rx.height_m = h;
  rx.clock_bias_m = 12345.6;
  rx.clock_drift_mps = 3.2;
  rx.v_e.setZero();
  return rx;
}

// Elevation/azimuth of a satellite position seen from the receiver (computed here, independently).
void el_az(const Receiver& rx, const Eigen::Vector3d& r_sat, double& el, double& az) {
  std::vector<double> m(9);
  double lat, lon, h;
  GeographicLib::Geocentric::WGS84().Reverse(rx.r_e.x(), rx.r_e.y(), rx.r_e.z(), lat, lon, h, m);
  const Eigen::Vector3d d = (r_sat - rx.r_e).normalized();
  const double e = m[0] * d.x() + m[3] * d.y() + m[6] * d.z();
  const double n = m[1] * d.x() + m[4] * d.y() + m[7] * d.z();
  const double u = m[2] * d.x() + m[5] * d.y() + m[8] * d.z();
  el = std::asin(u);
  az = std::atan2(e, n);
}

// Pseudorange as a receiver would measure it at true GPS receive time t_gps, for a receiver at
// rx.r_e + rx.v_e * dt_s: exact light-time solution |R(tau) r_sat(t - tau) - r_rx| = c tau.
double pseudorange(const signals::Ephemeris& eph, const Receiver& rx, const signals::GpsTime& t_gps, double dt_s,
                   const signals::KlobucharParameters& iono, bool atmosphere, double* elevation = nullptr) {
  const signals::GpsTime t = signals::add_seconds(t_gps, dt_s);
  const Eigen::Vector3d r_rx = rx.r_e + rx.v_e * dt_s;
  double tau = 0.07;
  Eigen::Vector3d r_sat;
  for (int i = 0; i < 20; ++i) {
    const signals::SatelliteState s = signals::satellite_state(eph, signals::add_seconds(t, -tau));
    const double th = signals::kEarthRotationRate_radps * tau;
    Eigen::Matrix3d R;
    R << std::cos(th), std::sin(th), 0, -std::sin(th), std::cos(th), 0, 0, 0, 1;
    r_sat = R * s.r_e_m;
    tau = (r_sat - r_rx).norm() / kSpeedOfLight_mps;
  }
  Receiver at = rx;
  at.r_e = r_rx;
  double el, az;
  el_az(at, r_sat, el, az);
  if (elevation) *elevation = el;
  double delay = 0.0;
  if (atmosphere) {
    delay += kSpeedOfLight_mps *
             signals::klobuchar_delay_s(iono, rx.lat_rad, rx.lon_rad, az, el, signals::add_seconds(t, -tau).tow_s);
    delay += signals::troposphere_delay_m(rx.lat_rad, rx.height_m, el);
  }
  const double dt_sv = signals::l1_ca_clock_correction_s(eph, signals::add_seconds(t, -tau));
  return kSpeedOfLight_mps * tau + rx.clock_bias_m + rx.clock_drift_mps * dt_s - kSpeedOfLight_mps * dt_sv + delay;
}

// Pseudorange and Doppler: the Doppler is the central difference of the exact pseudorange over +-50 ms
// (truncation error h^2/6 * third derivative: far below 1e-6 m/s here).
receiver::SatelliteMeasurement measure(const signals::Ephemeris& eph, const Receiver& rx, const signals::GpsTime& t_gps,
                                       const signals::KlobucharParameters& iono, bool atmosphere, double& elevation) {
  receiver::SatelliteMeasurement m;
  m.prn = eph.prn;
  m.ephemeris = eph;
  m.pseudorange_m = pseudorange(eph, rx, t_gps, 0.0, iono, atmosphere, &elevation);
  const double h = 0.05;
  const double rate =
      (pseudorange(eph, rx, t_gps, h, iono, false) - pseudorange(eph, rx, t_gps, -h, iono, false)) / (2.0 * h);
  m.doppler_hz = -rate / signals::kL1Wavelength_m;
  m.has_doppler = true;
  return m;
}

signals::KlobucharParameters sample_iono() {
  signals::KlobucharParameters k;
  const double a[4] = {1.1176e-08, 7.4506e-09, -5.9605e-08, -5.9605e-08};
  const double b[4] = {9.0112e+04, 1.6384e+04, -1.9661e+05, -6.5536e+04};
  for (int i = 0; i < 4; ++i) {
    k.alpha[i] = a[i];
    k.beta[i] = b[i];
  }
  k.valid = true;
  return k;
}

std::vector<receiver::SatelliteMeasurement> visible_measurements(const Receiver& rx, bool atmosphere,
                                                                 double mask_deg = 10.0) {
  std::vector<receiver::SatelliteMeasurement> out;
  const auto t_gps = signals::add_seconds(kEpoch, 0.0);
  int prn = 1;
  for (int plane = 0; plane < 6; ++plane) {
    for (double m0 : {0.0, 90.0, 180.0, 270.0}) {
      double el = 0.0;
      auto m = measure(orbit(prn, plane, m0 + 25.0 * plane), rx, t_gps, sample_iono(), atmosphere, el);
      if (el > mask_deg * M_PI / 180.0) out.push_back(m);
      ++prn;
    }
  }
  return out;
}

signals::GpsTime receiver_clock_time(const Receiver& rx) {
  return signals::add_seconds(kEpoch, rx.clock_bias_m / kSpeedOfLight_mps);
}

}  // namespace

TEST(Pvt, RecoversPositionClockAndVelocityWithoutNoise) {
  Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  rx.v_e = Eigen::Vector3d(12.0, -7.5, 3.0);
  const auto meas = visible_measurements(rx, true);
  ASSERT_GE(meas.size(), 5u);
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), sample_iono(), opt);
  ASSERT_TRUE(sol.valid) << sol.failure;
  // Noise-free data: the only error is the solver's convergence and model agreement (sub-millimetre).
  EXPECT_LT((sol.r_e_m - rx.r_e).norm(), 1e-3);
  EXPECT_NEAR(sol.clock_bias_m, rx.clock_bias_m, 1e-3);
  ASSERT_TRUE(sol.velocity_valid);
  // The solver's range-rate model leaves out the receiver's share of the light-time rate (|v_rx| / c times
  // the satellite velocity: ~0.1 mm/s per satellite here), so 1 mm/s bounds it.
  EXPECT_LT((sol.v_e_mps - rx.v_e).norm(), 1e-3) << "velocity error " << (sol.v_e_mps - rx.v_e).norm();
  RecordProperty("velocity_error_mps", std::to_string((sol.v_e_mps - rx.v_e).norm()));
  EXPECT_NEAR(sol.clock_drift_mps, rx.clock_drift_mps, 1e-3);
  EXPECT_EQ(sol.used_prns.size(), meas.size());
  EXPECT_NEAR(sol.lat_rad, rx.lat_rad, 1e-9);
  EXPECT_NEAR(sol.height_m, 100.0, 1e-3);
  EXPECT_GT(sol.pdop, 1.0);
  EXPECT_NEAR(sol.pdop * sol.pdop, sol.hdop * sol.hdop + sol.vdop * sol.vdop, 1e-9);
}

TEST(Pvt, AtmosphereOffBiasesTheSolutionWhenDataHasIt) {
  const Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  const auto meas = visible_measurements(rx, true);
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  opt.ionosphere = opt.troposphere = false;
  opt.fault_exclusion = false;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), sample_iono(), opt);
  ASSERT_TRUE(sol.valid);
  EXPECT_GT((sol.r_e_m - rx.r_e).norm(), 1.0);  // metres of unmodelled delay must show
}

TEST(Pvt, ExcludesOneFaultySatellite) {
  const Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  auto meas = visible_measurements(rx, false, 5.0);
  ASSERT_GE(meas.size(), 6u);
  const int faulty = meas[2].prn;
  meas[2].pseudorange_m += 150.0;
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  opt.ionosphere = opt.troposphere = false;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  ASSERT_TRUE(sol.valid);
  ASSERT_TRUE(sol.excluded_prn.has_value());
  EXPECT_EQ(*sol.excluded_prn, faulty);
  EXPECT_LT((sol.r_e_m - rx.r_e).norm(), 1e-3);
}

TEST(Pvt, ElevationMaskAndTooFewSatellites) {
  const Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  auto meas = visible_measurements(rx, false, 5.0);
  meas.resize(3);
  receiver::PvtOptions opt;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  EXPECT_FALSE(sol.valid);
  EXPECT_FALSE(sol.failure.empty());
}

TEST(Pvt, UnhealthySatelliteIsNotUsedByDefault) {
  const Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  auto meas = visible_measurements(rx, false, 5.0);
  meas[0].ephemeris.health = 1;
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  opt.ionosphere = opt.troposphere = false;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  ASSERT_TRUE(sol.valid);
  EXPECT_EQ(std::count(sol.used_prns.begin(), sol.used_prns.end(), meas[0].prn), 0);
}

TEST(Pvt, ChiSquareQuantileMatchesPublishedTable) {
  // Standard chi-square table values (upper tail). Wilson-Hilferty is within ~2 % for dof >= 2.
  // Published table values to 3 decimals.
  EXPECT_NEAR(receiver::chi_square_upper_quantile(2, 0.05), 5.991, 0.0005);
  EXPECT_NEAR(receiver::chi_square_upper_quantile(4, 0.001), 18.467, 0.0005);
  EXPECT_NEAR(receiver::chi_square_upper_quantile(10, 0.01), 23.209, 0.0005);
  EXPECT_NEAR(receiver::chi_square_upper_quantile(30, 0.05), 43.773, 0.0005);
}

// The a-priori covariances (new with the GNSS/INS integration, which weights the fixes by them): the weights
// 1 / sigma_i^2 with sigma_i = sigma_zenith / sin(el_i) at 45 dB-Hz lie between those of the lowest and the
// highest satellite, so N = sum w_i h h^T lies between w_min G and w_max G (G the unweighted normal matrix, whose
// inverse gives the DOPs) and trace(position covariance) between PDOP^2 / w_max and PDOP^2 / w_min. The rate rows
// share the geometry with sigmas scaled by sigma_doppler / sigma_zenith: the velocity covariance is the position
// covariance times that ratio squared.
TEST(Pvt, CovarianceLiesBetweenTheDopBoundsOfItsWeights) {
  Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  const auto meas = visible_measurements(rx, true);
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), sample_iono(), opt);
  ASSERT_TRUE(sol.valid && sol.velocity_valid);
  double el_min = M_PI, el_max = 0.0;
  for (const auto& s : sol.satellites) {
    el_min = std::min(el_min, s.elevation_rad);
    el_max = std::max(el_max, s.elevation_rad);
  }
  ASSERT_LT(el_min + 0.1, el_max);
  const double w_min = std::pow(std::sin(el_min) / opt.sigma_zenith_m, 2);
  const double w_max = std::pow(std::sin(el_max) / opt.sigma_zenith_m, 2);
  const double trace = sol.covariance_m2.topLeftCorner<3, 3>().trace();
  EXPECT_GT(trace, sol.pdop * sol.pdop / w_max);
  EXPECT_LT(trace, sol.pdop * sol.pdop / w_min);
  EXPECT_LT((sol.covariance_m2 - sol.covariance_m2.transpose()).norm(), 1e-9 * sol.covariance_m2.norm());
  EXPECT_EQ(Eigen::LLT<Eigen::Matrix4d>(sol.covariance_m2).info(), Eigen::Success);  // positive definite
  const double ratio2 = std::pow(opt.sigma_doppler_mps / opt.sigma_zenith_m, 2);
  EXPECT_LT((sol.velocity_covariance_m2ps2 - ratio2 * sol.covariance_m2).norm(),
            1e-6 * ratio2 * sol.covariance_m2.norm());
}

// RTKLIB's default GDOP limit (30): a normal sky passes it; the same epoch with the limit just below its GDOP is no
// solution, whose failure names the GDOP; just above, the same solution as without a limit.
TEST(Pvt, AGdopAboveTheLimitIsNoSolution) {
  const Receiver rx = make_receiver(35.274016, 137.013759, 100.0);
  const auto meas = visible_measurements(rx, false, 5.0);
  receiver::PvtOptions opt;
  opt.elevation_mask_rad = 0.0;
  opt.ionosphere = opt.troposphere = false;
  EXPECT_DOUBLE_EQ(opt.max_gdop, 30.0);
  const auto sol = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  ASSERT_TRUE(sol.valid) << sol.failure;
  ASSERT_GT(sol.gdop, 1.0);
  opt.max_gdop = 0.999 * sol.gdop;
  const auto refused = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  EXPECT_FALSE(refused.valid);
  EXPECT_NE(refused.failure.find("GDOP"), std::string::npos) << refused.failure;
  opt.max_gdop = 1.001 * sol.gdop;
  const auto kept = receiver::solve_pvt(meas, receiver_clock_time(rx), {}, opt);
  ASSERT_TRUE(kept.valid);
  EXPECT_EQ(kept.r_e_m, sol.r_e_m);
  opt.max_gdop = 0.0;
  std::string why;
  EXPECT_FALSE(opt.IsValid(&why));
}
