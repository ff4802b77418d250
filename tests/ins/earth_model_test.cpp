// SPDX-License-Identifier: GPL-3.0-or-later
// Earth model against published WGS-84 values and against geometry computed by GeographicLib's Geocentric
// (independent of our closed forms): radii from the ECEF position's derivative, gravity at equator/pole.
#include "ins/earth_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <GeographicLib/NormalGravity.hpp>
#include <cmath>
#include <numbers>

#include "io/units.hpp"

using namespace ultratrack::ins;

namespace {}

TEST(EarthModel, RadiiMatchPublishedWgs84Values) {
  // NIMA TR8350.2: a = 6378137 m, b^2/a... R_M(0) = a(1-e^2) = 6335439.327 m, R_N(0) = a,
  // polar radius of curvature c = a^2/b = 6399593.626 m.
  const Radii eq = radii_of_curvature(0.0);
  EXPECT_NEAR(eq.meridian_m, 6335439.327, 1e-3);
  EXPECT_NEAR(eq.transverse_m, 6378137.0, 1e-6);
  const Radii pole = radii_of_curvature(90.0 * ultratrack::io::kRadPerDeg);
  EXPECT_NEAR(pole.meridian_m, 6399593.626, 1e-3);
  EXPECT_NEAR(pole.transverse_m, 6399593.626, 1e-3);
}

TEST(EarthModel, RadiiAreTheDerivativesOfTheEcefPosition) {
  for (double lat_deg : {-60.0, -10.0, 0.0, 36.37, 71.0}) {
    // Central differences over 2e-5 rad: chord and rounding errors below 1e-9 relative.
    const double lat = lat_deg * ultratrack::io::kRadPerDeg, lon = 127.0 * ultratrack::io::kRadPerDeg, h = 250.0,
                 d = 1e-5;
    const Radii r = radii_of_curvature(lat);
    const double north = (ecef_from_geodetic(lat + d, lon, h) - ecef_from_geodetic(lat - d, lon, h)).norm() / (2 * d);
    const double east = (ecef_from_geodetic(lat, lon + d, h) - ecef_from_geodetic(lat, lon - d, h)).norm() / (2 * d);
    EXPECT_NEAR(north, r.meridian_m + h, 1e-9 * north) << lat_deg;
    EXPECT_NEAR(east, (r.transverse_m + h) * std::cos(lat), 1e-9 * north) << lat_deg;
  }
}

TEST(EarthModel, NedAxesInEcefAreTheGeodeticDirections) {
  const double lat = 36.37 * ultratrack::io::kRadPerDeg, lon = 127.36 * ultratrack::io::kRadPerDeg, h = 100.0, d = 1e-7;
  const Eigen::Matrix3d C = C_en(lat, lon);
  EXPECT_LT((C.transpose() * C - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(C.determinant(), 1.0, 1e-14);
  const Eigen::Vector3d n = (ecef_from_geodetic(lat + d, lon, h) - ecef_from_geodetic(lat - d, lon, h)).normalized();
  const Eigen::Vector3d e = (ecef_from_geodetic(lat, lon + d, h) - ecef_from_geodetic(lat, lon - d, h)).normalized();
  const Eigen::Vector3d down = (ecef_from_geodetic(lat, lon, h - 1) - ecef_from_geodetic(lat, lon, h + 1)).normalized();
  EXPECT_LT((C.col(0) - n).norm(), 1e-8);
  EXPECT_LT((C.col(1) - e).norm(), 1e-8);
  EXPECT_LT((C.col(2) - down).norm(), 1e-8);
}

TEST(EarthModel, NormalGravityMatchesWgs84EquatorAndPole) {
  // WGS-84 normal gravity on the ellipsoid: 9.7803253359 m/s^2 at the equator, 9.8321849378 at the poles.
  EXPECT_NEAR(gravity_n(0.0, 0.0).z(), 9.7803253359, 1e-9);
  EXPECT_NEAR(gravity_n(90.0 * ultratrack::io::kRadPerDeg, 0.0).z(), 9.8321849378, 1e-9);
  EXPECT_NEAR(gravity_n(45.0 * ultratrack::io::kRadPerDeg, 0.0).x(), 0.0, 1e-12);  // normal to the ellipsoid on it
  // Free-air gradient about -3.086e-6 s^-2.
  const double grad = (gravity_n(45.0 * ultratrack::io::kRadPerDeg, 1000.0).z() -
                       gravity_n(45.0 * ultratrack::io::kRadPerDeg, 0.0).z()) /
                      1000.0;
  EXPECT_NEAR(grad, -3.086e-6, 0.01e-6);
}

TEST(EarthModel, EarthAndTransportRatesMatchTheirDefinitions) {
  const double lat = 36.37 * ultratrack::io::kRadPerDeg, h = 1000.0;
  const Eigen::Vector3d w_ie = earth_rate_n(lat);
  EXPECT_NEAR(w_ie.norm(), 7.292115e-5, 1e-17);
  // omega_en^n = (dlon/dt cos L, -dlat/dt, -dlon/dt sin L)  ([ParkSDINS] eq. 5 with the longitude rate)
  const Eigen::Vector3d v(120.0, -75.0, 3.0);
  const Eigen::Vector3d rates = geodetic_rates(lat, h, v);
  const Eigen::Vector3d w_en = transport_rate_n(lat, h, v);
  EXPECT_NEAR(w_en.x(), rates.y() * std::cos(lat), 1e-18);
  EXPECT_NEAR(w_en.y(), -rates.x(), 1e-18);
  EXPECT_NEAR(w_en.z(), -rates.y() * std::sin(lat), 1e-18);
  EXPECT_DOUBLE_EQ(rates.z(), -3.0);
}
