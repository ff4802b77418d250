// SPDX-License-Identifier: GPL-3.0-or-later
// Non-holonomic constraints (fusion/nhc_measurement.hpp): the Jacobian against central differences of h, and
// the constraint's zero on a vehicle moving along its own x axis.
#include "fusion/nhc_measurement.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "ins/attitude.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

NominalState moving_nominal() {
  NominalState s;
  s.nav.lat_rad = 47.4 * kDeg;
  s.nav.lon_rad = 8.5 * kDeg;
  s.nav.height_m = 420.0;
  s.nav.q_nb = ins::quaternion_from_euler({2.0 * kDeg, -3.0 * kDeg, 37.0 * kDeg});
  s.nav.v_n = s.nav.q_nb * Eigen::Vector3d(16.0, 0.0, 0.0);  // along the body's x axis
  return s;
}

TEST(NhcMeasurement, IsZeroForMotionAlongTheBodyAxis) {
  LandVehicleOptions o;
  const NhcMeasurement<15> m(moving_nominal(), Eigen::Vector3d::Zero(), o);
  EXPECT_LT(m.h(StateVector<15>::Zero()).norm(), 1e-3);  // earth and transport rate with a zero lever: none
}

TEST(NhcMeasurement, JacobianMatchesCentralDifferences) {
  for (const Eigen::Vector3d& lever : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(-1.2, 0.4, 0.8)}) {
    LandVehicleOptions o;
    o.lever_arm_b = lever;
    const Eigen::Vector3d w_ib_b(0.01, -0.02, 0.15);
    const NhcMeasurement<15> m(moving_nominal(), w_ib_b, o);
    const MeasurementJacobian<15> H = m.H(StateVector<15>::Zero());
    const StateVector<15> steps =
        (StateVector<15>() << 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-7, 1e-7, 1e-7)
            .finished();
    for (int j = 0; j < 15; ++j) {
      StateVector<15> d = StateVector<15>::Zero();
      d(j) = steps(j);
      const Eigen::VectorXd numeric = (m.h(d) - m.h(-d)) / (2.0 * steps(j));
      for (int i = 0; i < 2; ++i) {
        // Velocity and attitude columns: first order exact; position: earth-rate terms (~1e-7), left out of H.
        const double scale = std::max(1.0, std::abs(numeric(i)));
        EXPECT_NEAR(H(i, j), numeric(i), 2e-4 * scale) << "row " << i << " state " << j;
      }
    }
  }
}

}  // namespace
}  // namespace ultratrack::fusion
