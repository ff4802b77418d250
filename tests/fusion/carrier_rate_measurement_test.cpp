// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight filter's carrier-phase rate measurement (fusion/carrier_rate_measurement.hpp): the phase-noise
// variance against its closed form, z and R as defined (predicted minus measured rate; phase noise plus the common
// clock term), h of a clock-drift error against the convention "replica minus signal" (the drift error itself on
// every row), and H against central differences of h for a moving receiver.
#include "fusion/carrier_rate_measurement.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;

NominalState moving_nominal() {
  NominalState n;
  n.nav.lat_rad = 35.27 * kPi / 180.0;
  n.nav.lon_rad = 137.01 * kPi / 180.0;
  n.nav.height_m = 100.0;
  n.nav.v_n = Eigen::Vector3d(6.0, 5.5, 0.1);
  n.nav.q_nb = ins::quaternion_from_euler({0.01, -0.02, 0.74});
  n.clock_bias_m = 1200.0;
  n.clock_drift_mps = -35.0;
  return n;
}

SatelliteObservable satellite(const NominalState& n, double azimuth_rad, double elevation_rad, int prn) {
  const Eigen::Vector3d r_e = ins::ecef_from_geodetic(n.nav.lat_rad, n.nav.lon_rad, n.nav.height_m);
  const Eigen::Vector3d u_n(std::cos(elevation_rad) * std::cos(azimuth_rad),
                            std::cos(elevation_rad) * std::sin(azimuth_rad), -std::sin(elevation_rad));
  const Eigen::Vector3d u_e = ins::C_en(n.nav.lat_rad, n.nav.lon_rad) * u_n;
  SatelliteObservable s;
  s.prn = prn;
  s.r_sat_e = r_e + 2.2e7 * u_e;
  s.v_sat_e = 3000.0 * u_e.cross(Eigen::Vector3d::UnitZ()).normalized();
  s.elevation_rad = elevation_rad;
  s.azimuth_rad = azimuth_rad;
  s.has_rate = true;
  return s;
}

std::vector<CarrierRateRow> rows(const NominalState& n) {
  std::vector<CarrierRateRow> out;
  const double az[3] = {0.3, 2.1, 4.4}, el[3] = {0.9, 0.4, 1.2};
  for (int i = 0; i < 3; ++i) {
    CarrierRateRow r;
    r.sat = satellite(n, az[i], el[i], 3 + i);
    r.predicted_rate_mps = 100.0 * i - 250.0;
    r.rate_at_update_mps = r.predicted_rate_mps - 0.1 * (i + 1);
    r.phase_noise_var_m2ps2 = 1e-3 * (i + 1);
    out.push_back(r);
  }
  return out;
}

TEST(CarrierRateMeasurement, PhaseVarianceIsTheJitterOfBothEndsOverTheWindow) {
  const double lambda = signals::kL1Wavelength_m;
  // 0.04 and 0.09 rad^2 at the ends of a 0.2 s window: (lambda / (2 pi 0.2))^2 (0.13).
  const double expected = std::pow(lambda / (2.0 * kPi * 0.2), 2) * 0.13;
  EXPECT_NEAR(carrier_rate_phase_variance(0.04, 0.09, 0.2), expected, 1e-15);
  EXPECT_THROW(carrier_rate_phase_variance(0.04, 0.09, 0.0), std::invalid_argument);
  EXPECT_THROW(carrier_rate_phase_variance(0.04, 0.09, NAN), std::invalid_argument);
}

TEST(CarrierRateMeasurement, InnovationsAndNoiseAreAsDefined) {
  const NominalState n = moving_nominal();
  const std::vector<CarrierRateRow> r = rows(n);
  const CarrierRateMeasurement m(n, r, Eigen::Vector3d(0.5, 0.0, -1.0), Eigen::Vector3d(0.0, 0.0, 0.1), 2.5e-3);
  ASSERT_EQ(m.z().size(), 3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(m.z()(i), r[i].predicted_rate_mps - r[i].rate_at_update_mps);
    for (int j = 0; j < 3; ++j)
      EXPECT_DOUBLE_EQ(m.R()(i, j), 2.5e-3 + (i == j ? r[i].phase_noise_var_m2ps2 : 0.0)) << i << "," << j;
  }
}

TEST(CarrierRateMeasurement, ClockDriftErrorIsTheRateErrorOfEverySatellite) {
  // dx = estimate minus truth: a drift estimate 0.3 m/s low makes every replica's rate 0.3 m/s below the signal's.
  const NominalState n = moving_nominal();
  const CarrierRateMeasurement m(n, rows(n), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0);
  StateVector<17> dx = StateVector<17>::Zero();
  dx(ix::kClockDrift) = -0.3;
  const Eigen::VectorXd h = m.h(dx);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(h(i), -0.3, 1e-9) << i;
  EXPECT_NEAR(m.h(StateVector<17>::Zero()).norm(), 0.0, 1e-12);
}

TEST(CarrierRateMeasurement, JacobianMatchesCentralDifferences) {
  const NominalState n = moving_nominal();
  const CarrierRateMeasurement m(n, rows(n), Eigen::Vector3d(0.5, 0.2, -1.0), Eigen::Vector3d(0.01, 0.0, 0.1), 0.0);
  const MeasurementJacobian<17> H = m.H(StateVector<17>::Zero());
  // Velocity, accelerometer bias and clock: the states the rate is linear in (attitude enters through the lever
  // arm's velocity only, at 1e-3 of these).
  const int states[] = {ix::kVel, ix::kVel + 1, ix::kVel + 2, ix::kClockBias, ix::kClockDrift};
  for (int k : states) {
    StateVector<17> d = StateVector<17>::Zero();
    d(k) = 1e-3;
    const Eigen::VectorXd numeric = (m.h(d) - m.h(-d)) / 2e-3;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(H(i, k), numeric(i), 1e-6) << "state " << k << " row " << i;
  }
}

}  // namespace
}  // namespace ultratrack::fusion
