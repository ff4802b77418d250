// SPDX-License-Identifier: GPL-3.0-or-later
// Double-difference algebra, Wahba's rotation and the attitude frames, against closed forms.
#include "receiver/attitude_geometry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <GeographicLib/Geocentric.hpp>
#include <cmath>
#include <random>

#include "attitude_phase_simulator.hpp"
#include "receiver/phase_differences.hpp"
#include "receiver/wahba_rotation.hpp"

using namespace ultratrack::receiver;
using ultratrack::io::kRadPerDeg;

TEST(AttitudeGeometry, DoubleDifferenceCovarianceHasTheSharedTerms) {
  // 3 antennas, 3 satellites, the highest (prn 2) the reference: rows (1,1) (1,3) (2,1) (2,3).
  std::vector<AntennaPhaseObservation> obs(3);
  const double el[3] = {0.3, 1.2, 0.7};
  for (int s = 0; s < 3; ++s) {
    obs[static_cast<std::size_t>(s)].prn = s + 1;
    obs[static_cast<std::size_t>(s)].elevation_rad = el[s];
    obs[static_cast<std::size_t>(s)].los_e = Eigen::Vector3d(std::cos(el[s]), 0.0, std::sin(el[s]));
    for (int a = 0; a < 3; ++a)
      obs[static_cast<std::size_t>(s)].carrier_phase_cycles[static_cast<std::size_t>(a)] = 10 * s + a * a;
  }
  std::vector<const AntennaPhaseObservation*> p{&obs[0], &obs[1], &obs[2]};
  const double sigma = 0.1;
  const DoubleDifferences d = form_double_differences(p, 3, sigma, [](std::size_t, int) { return true; });
  ASSERT_EQ(d.rows.size(), 4u);
  for (const DdRow& r : d.rows) EXPECT_EQ(r.ref_prn, 2);
  const double v = sigma * sigma;
  Eigen::Matrix4d expected;
  // same baseline: phi_k^r and phi_0^r shared (2 v); other baseline, same sat: phi_0^s, phi_0^r (2 v); else phi_0^r.
  expected << 4 * v, 2 * v, 2 * v, v,  //
      2 * v, 4 * v, v, 2 * v,          //
      2 * v, v, 4 * v, 2 * v,          //
      v, 2 * v, 2 * v, 4 * v;
  EXPECT_LT((d.covariance - expected).norm(), 1e-15);
  // DD value: (phi_k^s - phi_0^s) - (phi_k^r - phi_0^r) = (10 s + k^2 - 10 s) - (10 r + k^2 - 10 r) = 0 here; and
  // geometry row = -(u_s - u_r) / lambda.
  EXPECT_NEAR(d.dd_cycles.norm(), 0.0, 1e-12);
  const Eigen::RowVector3d g = -(obs[0].los_e - obs[1].los_e).transpose() / ultratrack::signals::kL1Wavelength_m;
  EXPECT_LT((d.geometry.row(0) - g).norm(), 1e-9);
}

TEST(AttitudeGeometry, WahbaRecoversARotationIncludingTheDeterminantFix) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Matrix3d R = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    // Two vectors only: B has rank 2 and the SVD's third axis has an arbitrary sign, so the det fix is needed.
    const std::vector<Eigen::Vector3d> l{Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.025, 0.0)};
    const std::vector<Eigen::Vector3d> v{R * l[0], R * l[1]};
    const Eigen::Matrix3d Rw = wahba_rotation(l, v, {1.0, 1.0});
    EXPECT_LT((Rw - R).norm(), 1e-12);
    EXPECT_NEAR(Rw.determinant(), 1.0, 1e-12);
  }
}

TEST(AttitudeGeometry, EulerRoundTripAndNedFrame) {
  const EulerAngles e{10 * kRadPerDeg, -25 * kRadPerDeg, 300 * kRadPerDeg};
  const Eigen::Matrix3d C = C_nb_from_euler(e);
  EXPECT_LT((C - testsim::dcm_nb(e.roll_rad, e.pitch_rad, e.yaw_rad)).norm(), 1e-14);
  const EulerAngles back = euler_from_C_nb(C);
  EXPECT_NEAR(back.roll_rad, e.roll_rad, 1e-12);
  EXPECT_NEAR(back.pitch_rad, e.pitch_rad, 1e-12);
  EXPECT_NEAR(back.yaw_rad, e.yaw_rad, 1e-12);
  // At latitude 0, longitude 0: north = +z, east = +y, down = -x (ECEF).
  const Eigen::Matrix3d C_en = ned_to_ecef_rotation(Eigen::Vector3d(6378137.0, 0.0, 0.0));
  EXPECT_LT((C_en.col(0) - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  EXPECT_LT((C_en.col(1) - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((C_en.col(2) + Eigen::Vector3d::UnitX()).norm(), 1e-12);
}

TEST(AttitudeGeometry, EulerCovarianceOfAYawRotation) {
  // A small rotation about the NED down axis changes yaw only, one for one, when roll = pitch = 0.
  const Eigen::Matrix3d C = C_nb_from_euler({0.0, 0.0, 1.0});
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  P(2, 2) = 1e-6;
  const Eigen::Matrix3d E = euler_covariance(C, P);
  EXPECT_NEAR(E(2, 2), 1e-6, 1e-12);
  EXPECT_NEAR(E(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(E(1, 1), 0.0, 1e-12);
  // At yaw 90 deg the body x axis points east and y south: a rotation about north tilts x, a pure pitch change.
  const Eigen::Matrix3d C90 = C_nb_from_euler({0.0, 0.0, M_PI / 2});
  P.setZero();
  P(0, 0) = 1e-6;
  const Eigen::Matrix3d E90 = euler_covariance(C90, P);
  EXPECT_NEAR(E90(1, 1), 1e-6, 1e-11);
  EXPECT_NEAR(E90(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(E90(2, 2), 0.0, 1e-12);
}
