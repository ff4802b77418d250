// SPDX-License-Identifier: GPL-3.0-or-later
// gnss.csv (fuse's external fixes) and fuse's nav.csv: exact round trips, position-only rows, and every kind
// of malformed row rejected with the file and the line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "ins/earth_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using ultratrack::io::InputError;
using ultratrack::pipelines::GnssCsvRow;

namespace {

const char* kHeader = "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n";

fs::path write(const std::string& body) {
  const fs::path f = ultratrack::test::scratch_dir() / "gnss.csv";
  std::ofstream(f) << body;
  return f;
}

// The error must name the file and the given line.
void expect_error_at(const std::string& body, int line, const std::string& words) {
  const fs::path f = write(body);
  try {
    ultratrack::pipelines::read_gnss_csv(f);
    ADD_FAILURE() << "accepted: " << body;
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.file(), f.string());
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(FuseGnssCsv, RoundTripIsExactWithAndWithoutVelocity) {
  std::vector<GnssCsvRow> in(3);
  for (int k = 0; k < 3; ++k) {
    in[k].t_s = 0.137 + 0.2 * k;
    in[k].lat_rad = (36.1234567891 + 1e-7 * k) * ultratrack::io::kRadPerDeg;
    in[k].lon_rad = 127.3 * ultratrack::io::kRadPerDeg - 1e-9 * k;
    in[k].height_m = 100.0 / 3.0 + k;
    in[k].has_velocity = k != 1;
    if (in[k].has_velocity) in[k].v_n = {1.0 / 3.0, -2.5, 0.01 * k};
    in[k].sigma_ned_m = {1.5, 1.6, 3.1};
  }
  const fs::path f = ultratrack::test::scratch_dir() / "g.csv";
  ultratrack::pipelines::write_gnss_csv(f, in);
  const auto out = ultratrack::pipelines::read_gnss_csv(f);
  ASSERT_EQ(out.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(out[k].t_s, in[k].t_s);
    EXPECT_NEAR(out[k].lat_rad, in[k].lat_rad, 1e-15);  // degrees round trip exactly, radians to the last bit
    EXPECT_NEAR(out[k].lon_rad, in[k].lon_rad, 1e-15);
    EXPECT_EQ(out[k].height_m, in[k].height_m);
    EXPECT_EQ(out[k].has_velocity, in[k].has_velocity);
    EXPECT_EQ(out[k].v_n, in[k].v_n);
    EXPECT_EQ(out[k].sigma_ned_m, in[k].sigma_ned_m);
  }
}

TEST(FuseGnssCsv, EmptyVelocityColumnsMeanPositionOnly) {
  const auto fixes =
      ultratrack::pipelines::read_gnss_csv(write(std::string(kHeader) + "# comment\n\n1.5,36,127,50, , ,,2,2,4\n"));
  ASSERT_EQ(fixes.size(), 1u);
  EXPECT_FALSE(fixes[0].has_velocity);
  EXPECT_EQ(fixes[0].sigma_ned_m, Eigen::Vector3d(2, 2, 4));
}

TEST(FuseGnssCsv, MalformedRowsAreInputErrorsWithTheLine) {
  const std::string h = kHeader;
  const std::string ok = "0.1,36,127,50,1,2,3,2,2,4\n";
  expect_error_at("t_s,lat_deg\n", 1, "bad header");
  expect_error_at(h + ok + "0.2,36,127,nan,1,2,3,2,2,4\n", 3, "height_m is not finite");
  expect_error_at(h + ok + "0.2,36,127,50,1,2,3,2,2,inf\n", 3, "not finite");
  expect_error_at(h + ok + "0.2,36,127,5x,1,2,3,2,2,4\n", 3, "height_m is not a number");
  expect_error_at(h + ok + "0.1,36,127,50,1,2,3,2,2,4\n", 3, "time does not increase");
  expect_error_at(h + ok + "0.05,36,127,50,1,2,3,2,2,4\n", 3, "time does not increase");
  expect_error_at(h + ok + "0.2,36,127,50,1,,3,2,2,4\n", 3, "all three");
  expect_error_at(h + ok + "0.2,36,127,50,1,2,3,2,2\n", 3, "expected 10 fields, got 9");
  expect_error_at(h + ok + "0.2,36,127,50,1,2,3,2,2,4,5\n", 3, "more than 10 fields");
  expect_error_at(h + ok + "0.2,96,127,50,1,2,3,2,2,4\n", 3, "lat_deg");
  expect_error_at(h + ok + "0.2,36,127,50,1,2,3,0,2,4\n", 3, "sigma_n_m must be positive");
  expect_error_at(h + ok + "0.2,,127,50,1,2,3,2,2,4\n", 3, "lat_deg is empty");
  expect_error_at(h, 0, "no data rows");
  expect_error_at("", 0, "missing header");
}

TEST(FuseGnssCsv, MissingFileIsAnInputError) {
  EXPECT_THROW(ultratrack::pipelines::read_gnss_csv(ultratrack::test::scratch_dir() / "absent.csv"), InputError);
}

TEST(FuseNavCsv, RoundTripKeepsStateAndSigmas) {
  const fs::path f = ultratrack::test::scratch_dir() / "nav.csv";
  ultratrack::ins::NavState s;
  s.t_s = 12.345;
  s.lat_rad = 0.6;
  s.lon_rad = 2.2;
  s.height_m = 321.5;
  s.v_n = {10, -3, 0.25};
  s.q_nb = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  ultratrack::pipelines::NavSigma g{{1, 2, 3}, {0.1, 0.2, 0.3}, {0.001, 0.002, 0.01}};
  {
    ultratrack::pipelines::FusedNavCsvWriter w(f);
    w.write(s, g);
    s.t_s += 0.005;
    w.write(s, g);
    w.commit();
  }
  const auto rows = ultratrack::pipelines::read_fused_nav_csv(f);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].nav.t_s, s.t_s);
  EXPECT_NEAR(rows[1].nav.lat_rad, s.lat_rad, 1e-15);
  EXPECT_EQ(rows[1].nav.v_n, s.v_n);
  EXPECT_LT(rows[1].nav.q_nb.angularDistance(s.q_nb), 1e-12);
  EXPECT_EQ(rows[1].sigma.position_ned_m, g.position_ned_m);
  EXPECT_EQ(rows[1].sigma.velocity_ned_mps, g.velocity_ned_mps);
  EXPECT_TRUE(rows[1].sigma.attitude_ned_rad.isApprox(g.attitude_ned_rad, 1e-14));
}

// Simulated fixes: exact non-integer times, and errors with the requested white statistics (2000 fixes: the
// sample standard deviation is within 5 sampling sigmas, sqrt(1 / (2 n)) ~ 1.6 %, of the setting).
TEST(FuseGnssFixSimulation, TimesAndErrorStatistics) {
  const auto spec = ultratrack::ins::profile_spec("straight", 401.0, 36.0 * ultratrack::io::kRadPerDeg,
                                                  127.0 * ultratrack::io::kRadPerDeg, 100.0);
  const ultratrack::ins::TruthInterpolator truth(ultratrack::ins::simulate(spec, 20.0).truth);
  ultratrack::pipelines::GnssFixSimulationOptions o;
  o.rate_hz = 5.0;
  o.first_time_s = 0.137;
  o.sigma_ned_m = {2.0, 3.0, 4.0};
  o.sigma_velocity_mps = 0.05;
  o.seed = 9;
  const auto fixes = ultratrack::pipelines::simulate_gnss_fixes(truth, o);
  ASSERT_EQ(fixes.size(), 2005u);  // 0.137 ... 400.937
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  double vel2 = 0.0;
  for (std::size_t k = 0; k < fixes.size(); ++k) {
    EXPECT_NEAR(fixes[k].t_s, 0.137 + 0.2 * static_cast<double>(k), 1e-12);
    const auto m = truth.antenna(fixes[k].t_s, Eigen::Vector3d::Zero());
    const Eigen::Vector3d d =
        ultratrack::ins::C_en(fixes[k].lat_rad, fixes[k].lon_rad).transpose() *
        (ultratrack::ins::ecef_from_geodetic(fixes[k].lat_rad, fixes[k].lon_rad, fixes[k].height_m) - m.r_e);
    sum2 += d.cwiseAbs2();
    vel2 +=
        (fixes[k].v_n - ultratrack::ins::C_en(fixes[k].lat_rad, fixes[k].lon_rad).transpose() * m.v_e).squaredNorm();
  }
  const double n = static_cast<double>(fixes.size());
  const Eigen::Vector3d sd = (sum2 / n).cwiseSqrt();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(sd[i] / o.sigma_ned_m[i], 1.0, 0.08) << i;
  EXPECT_NEAR(std::sqrt(vel2 / (3.0 * n)) / 0.05, 1.0, 0.05);
}

// A white part on top of 60 s Gauss-Markov errors: the fix-to-fix differences hold the white part (2 sigma_w^2 plus
// 2 sigma^2 dt / tau of the correlated part), the columns the total unless a stated sigma is asked for, and the
// correlated part's draws are those of the run without the white part.
TEST(FuseGnssFixSimulation, AWhitePartOnTopAndAStatedSigma) {
  const auto spec = ultratrack::ins::profile_spec("straight", 401.0, 36.0 * ultratrack::io::kRadPerDeg,
                                                  127.0 * ultratrack::io::kRadPerDeg, 100.0);
  const ultratrack::ins::TruthInterpolator truth(ultratrack::ins::simulate(spec, 20.0).truth);
  ultratrack::pipelines::GnssFixSimulationOptions o;
  o.rate_hz = 5.0;
  o.sigma_ned_m = {1.0, 1.0, 2.0};
  o.correlation_time_s = 60.0;
  o.seed = 4;
  const auto plain = ultratrack::pipelines::simulate_gnss_fixes(truth, o);
  o.white_sigma_ned_m = {0.3, 0.4, 0.6};
  const auto both = ultratrack::pipelines::simulate_gnss_fixes(truth, o);
  o.stated_sigma_ned_m = Eigen::Vector3d(0.1, 0.1, 0.2);
  const auto stated = ultratrack::pipelines::simulate_gnss_fixes(truth, o);
  ASSERT_EQ(plain.size(), both.size());
  EXPECT_TRUE(both[0].sigma_ned_m.isApprox(
      Eigen::Vector3d(std::hypot(1.0, 0.3), std::hypot(1.0, 0.4), std::hypot(2.0, 0.6)), 1e-12));
  EXPECT_EQ(stated[0].sigma_ned_m, Eigen::Vector3d(0.1, 0.1, 0.2));
  EXPECT_EQ(stated[7].lat_rad, both[7].lat_rad);  // the stated sigma changes the column only
  EXPECT_EQ(plain[0].sigma_ned_m, o.sigma_ned_m);
  // The white part alone: both minus plain (the same Gauss-Markov draws), per axis, against its setting (2000
  // samples: 5 sampling sigmas ~ 8 %).
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < plain.size(); ++k) {
    const Eigen::Vector3d d =
        ultratrack::ins::C_en(plain[k].lat_rad, plain[k].lon_rad).transpose() *
        (ultratrack::ins::ecef_from_geodetic(both[k].lat_rad, both[k].lon_rad, both[k].height_m) -
         ultratrack::ins::ecef_from_geodetic(plain[k].lat_rad, plain[k].lon_rad, plain[k].height_m));
    sum2 += d.cwiseAbs2();
  }
  const Eigen::Vector3d sd = (sum2 / static_cast<double>(plain.size())).cwiseSqrt();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(sd[i] / o.white_sigma_ned_m[i], 1.0, 0.08) << i;
}
