// SPDX-License-Identifier: GPL-3.0-or-later
// Odometer aiding (fusion/vms_measurement.hpp, fusion/odometer_error_model.hpp): the VMS/NHC Jacobian against
// central differences of h, h against the closed form for known errors, the gating rule of [KimVMS] eqs.
// 16-17, a short drive where the 19-state filter recovers a simulated scale factor, and the tight layout (clock at
// [15, 17), odometer at [17, 21)): the measurement moved there by OdometerStatesAt, the model's blocks.
#include "fusion/vms_measurement.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "fusion/ekf.hpp"
#include "fusion/ukf.hpp"
#include "ins/attitude.hpp"
#include "ins/odometer.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

NominalState moving_nominal() {
  NominalState s;
  s.nav.lat_rad = 37.4 * kDeg;
  s.nav.lon_rad = 127.0 * kDeg;
  s.nav.height_m = 80.0;
  s.nav.q_nb = ins::quaternion_from_euler({1.5 * kDeg, -2.0 * kDeg, 117.0 * kDeg});
  s.nav.v_n = s.nav.q_nb * Eigen::Vector3d(22.0, 0.3, -0.2);
  return s;
}

OdometerNominal some_odometer() { return {0.03, 0.4 * kDeg, -0.7 * kDeg, 0.012}; }

TEST(VmsMeasurement, JacobianMatchesCentralDifferences) {
  for (const Eigen::Vector3d& lever : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(-1.4, 0.3, 0.9)}) {
    OdometerAidingOptions o;
    o.lever_arm_b = lever;
    const VmsMeasurement m(moving_nominal(), some_odometer(), Eigen::Vector3d(0.01, -0.02, 0.05),
                           Eigen::Vector3d(0.8, 0.3, -0.1), {100.0, 22.3, 1.0}, o);
    const MeasurementJacobian<19> H = m.H(StateVector<19>::Zero());
    StateVector<19> steps;
    steps << 0.1, 0.1, 0.1, 1e-3, 1e-3, 1e-3, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-7, 1e-7, 1e-7, 1e-4, 1e-6, 1e-6,
        1e-6;
    for (int j = 0; j < 19; ++j) {
      StateVector<19> d = StateVector<19>::Zero();
      d(j) = steps(j);
      const Eigen::VectorXd numeric = (m.h(d) - m.h(-d)) / (2.0 * steps(j));
      for (int i = 0; i < 3; ++i) {
        // Position columns: earth-rate terms (~1e-7) left out of H, as in the NHC measurement.
        const double scale = std::max(1.0, std::abs(numeric(i)));
        EXPECT_NEAR(H(i, j), numeric(i), 2e-4 * scale) << "row " << i << " state " << j;
      }
    }
  }
}

TEST(VmsMeasurement, PredictsTheScaledDelayedSpeedOfAMisalignedVehicle) {
  // Truth: the vehicle moves at 20 m/s along its own x, accelerating 1 m/s^2; the IMU is mounted with a 1 deg yaw
  // misalignment; the VMS reads 1.5 % high and lags 0.1 s; window 1 s (its mean speed is the speed at its middle).
  const OdometerNominal truth{0.1, 0.0, 1.0 * kDeg, 0.015};
  const Eigen::Matrix3d C_bv = ins::C_bv_from_misalignment(truth.pitch_rad, truth.yaw_rad);
  NominalState s;
  s.nav.lat_rad = 0.6;
  s.nav.q_nb = ins::quaternion_from_euler({0.0, 0.0, 30.0 * kDeg});
  const Eigen::Vector3d v_v(20.0, 0.0, 0.0), a_v(1.0, 0.0, 0.0);
  s.nav.v_n = s.nav.q_nb * (C_bv * v_v);
  OdometerAidingOptions o;
  const VmsMeasurement m(s, truth, Eigen::Vector3d::Zero(), C_bv * a_v, {10.0, 0.0, 1.0}, o);
  const Eigen::VectorXd h = m.h(StateVector<19>::Zero());
  EXPECT_NEAR(h(0), 1.015 * (20.0 - (0.5 + 0.1) * 1.0), 1e-3);  // earth-rate terms only
  EXPECT_NEAR(h(1), 0.0, 1e-3);
  EXPECT_NEAR(h(2), 0.0, 1e-3);
  // The same vehicle seen through a zero misalignment: the IMU's body velocity, v_b = Rz(1 deg) v_v, whose
  // lateral component is v sin(1 deg).
  const VmsMeasurement aligned(s, {0.1, 0.0, 0.0, 0.015}, Eigen::Vector3d::Zero(), C_bv * a_v, {10.0, 0.0, 1.0}, o);
  EXPECT_NEAR(aligned.h(StateVector<19>::Zero())(1), 20.0 * std::sin(1.0 * kDeg), 1e-3);
}

TEST(OdometerGate, FollowsTheHeadingRateAndSpeedRules) {
  OdometerAidingOptions o;  // 1.5 deg/s, 5 m/s
  EXPECT_TRUE(odometer_gate(o, 1.4 * kDeg, 1.0, 6.0).update());
  const OdometerGate turning = odometer_gate(o, 1.6 * kDeg, 1.0, 6.0);
  EXPECT_FALSE(turning.yaw_rate_ok);
  EXPECT_TRUE(turning.speed_ok);
  const OdometerGate slow = odometer_gate(o, 0.0, 1.0, 4.9);
  EXPECT_TRUE(slow.yaw_rate_ok);
  EXPECT_FALSE(slow.speed_ok);
  EXPECT_FALSE(odometer_gate(o, -1.6 * kDeg, 1.0, 10.0).yaw_rate_ok);                         // either sense of turn
  EXPECT_TRUE(odometer_gate(o, 2.0 * std::numbers::pi + 0.1 * kDeg, 1.0, 10.0).yaw_rate_ok);  // wrapped
  EXPECT_TRUE(odometer_gate(o, 2.0 * kDeg, 2.0, 10.0).yaw_rate_ok);  // 1 deg/s over a 2 s window
  o.mode = OdometerMode::kAlways;
  EXPECT_TRUE(odometer_gate(o, 10.0 * kDeg, 1.0, 0.0).update());
}

TEST(OdometerAugmentedModel, KeepsTheOdometerStatesConstantAndRunsInBothFilters) {
  OdometerAidingOptions oo;
  InsErrorModelOptions mo;
  mo.accel.bias_sigma = 1e-3;
  mo.gyro.bias_sigma = 1e-5;
  OdometerAugmentedModel<15> model(mo, oo);
  InsLinearisation lin;
  lin.nav = moving_nominal().nav;
  lin.f_b = Eigen::Vector3d(0.0, 0.0, -9.8);
  model.set_linearisation(lin);
  StateVector<19> x = StateVector<19>::Zero();
  x.tail<4>() << 0.01, 0.002, -0.003, 0.02;
  EXPECT_TRUE(model.f(x, 1.0).tail<4>().isApprox(x.tail<4>()));
  const StateMatrix<19> P0 = model.initial_covariance(Eigen::Vector3d::Constant(1.0), Eigen::Vector3d::Constant(0.1),
                                                      Eigen::Vector3d::Constant(1e-3));
  EXPECT_DOUBLE_EQ(P0(ix::kOdoScale, ix::kOdoScale), oo.sigma_scale_factor * oo.sigma_scale_factor);
  // One update of a VMS speed 2 % above the INS's: both filters move the scale-factor estimate towards +2 %.
  const NominalState s = moving_nominal();
  const double v_fwd = (s.nav.q_nb.conjugate() * s.nav.v_n).x();
  const VmsMeasurement m(s, {}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {0.0, 1.02 * v_fwd, 1.0}, oo);
  Ekf<19> ekf(StateVector<19>::Zero(), P0);
  Ukf<19> ukf(StateVector<19>::Zero(), P0);
  ekf.predict(model, 0.1);
  ukf.predict(model, 0.1);
  ASSERT_TRUE(ekf.update(m).accepted);
  ASSERT_TRUE(ukf.update(m).accepted);
  // Estimate minus truth with truth = nominal (0) - dx: dx < 0 means an estimated scale factor > 0.
  EXPECT_LT(ekf.x()(ix::kOdoScale), -0.002);
  EXPECT_NEAR(ukf.x()(ix::kOdoScale), ekf.x()(ix::kOdoScale), 1e-3);
}

// The tight layout's measurement: h and H on 21 states equal the 19-state ones with the clock states inert and the
// odometer block moved to [17, 21) (a copy of the state vector made here, not by the adapter).
TEST(OdometerStatesAt, MovesTheOdometerBlockBehindTheClock) {
  const VmsMeasurement m(moving_nominal(), some_odometer(), Eigen::Vector3d(0.01, -0.02, 0.05),
                         Eigen::Vector3d(0.8, 0.3, -0.1), {100.0, 22.3, 1.0}, OdometerAidingOptions{});
  const OdometerStatesAt<VmsMeasurement, 17, 21> moved(m);
  StateVector<19> x19;
  x19 << 0.3, -0.2, 0.5, 0.01, -0.02, 0.03, 1e-4, -2e-4, 3e-4, 1e-3, 2e-3, -1e-3, 1e-5, 2e-5, -3e-5, 0.01, 1e-3, -2e-3,
      0.004;
  StateVector<21> x21;
  x21 << x19.head<15>(), 7.0, -3.0, x19.tail<4>();  // clock bias and drift errors: no effect on the odometer
  EXPECT_TRUE(moved.h(x21).isApprox(m.h(x19), 1e-12));
  const MeasurementJacobian<19> H19 = m.H(x19);
  const MeasurementJacobian<21> H21 = moved.H(x21);
  EXPECT_TRUE(H21.leftCols<15>().isApprox(H19.leftCols<15>()));
  EXPECT_TRUE(H21.middleCols<2>(15).isZero());
  EXPECT_TRUE(H21.rightCols<4>().isApprox(H19.rightCols<4>()));
}

// The 21-state model: the INS-and-clock block is InsErrorModel<17>'s, the odometer states are constant, the initial
// covariance holds the odometer sigmas at [17, 21).
TEST(OdometerAugmentedModel, TightLayoutKeepsTheClockModelAndTheOdometerStatesConstant) {
  OdometerAidingOptions oo;
  InsErrorModelOptions mo;
  mo.accel.bias_sigma = 1e-3;
  mo.gyro.bias_sigma = 1e-5;
  OdometerAugmentedModel<17> model(mo, oo);
  InsErrorModel<17> base(mo);
  InsLinearisation lin;
  lin.nav = moving_nominal().nav;
  lin.f_b = Eigen::Vector3d(0.0, 0.0, -9.8);
  model.set_linearisation(lin);
  base.set_linearisation(lin);
  const StateMatrix<21> phi = model.transition(0.5);
  EXPECT_TRUE((phi.topLeftCorner<17, 17>().isApprox(base.transition(0.5))));
  EXPECT_TRUE((phi.bottomRightCorner<4, 4>().isIdentity()));
  EXPECT_TRUE((phi.topRightCorner<17, 4>().isZero()));
  const StateMatrix<21> P0 = model.initial_covariance(Eigen::Vector3d::Constant(1.0), Eigen::Vector3d::Constant(0.1),
                                                      Eigen::Vector3d::Constant(1e-3));
  EXPECT_DOUBLE_EQ(P0(17, 17), oo.sigma_delay_s * oo.sigma_delay_s);
  EXPECT_DOUBLE_EQ(P0(20, 20), oo.sigma_scale_factor * oo.sigma_scale_factor);
  EXPECT_GT(P0(ix::kClockBias, ix::kClockBias), 0.0);
}

}  // namespace
}  // namespace ultratrack::fusion
