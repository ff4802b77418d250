// SPDX-License-Identifier: GPL-3.0-or-later
// pipelines/solution_compare: a known error put on a known trajectory comes back. The truth is a 100 m circle at
// 8.33 m/s in a local tangent plane, turned into ECEF by GeographicLib's LocalCartesian (not by the code under
// test); the solution is that circle at times between the truth rows plus a fixed ENU position offset and a
// fixed velocity offset, so every RMS is the offset's norm (to the truth's interpolation error, < 1 mm).
#include "pipelines/solution_compare.hpp"

#include <gtest/gtest.h>

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <cmath>
#include <fstream>
#include <string>

#include "io/input_error.hpp"
#include "support/test_data.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kLat = 35.274016, kLon = 137.013759, kH = 100.0;
constexpr double kR = 100.0, kV = 30.0 / 3.6, kW = kV / kR;
constexpr double kTow0 = 518772.0;
constexpr double kC = 299792458.0;

// Position (ENU, m) and velocity (ENU, m/s) on the circle at t seconds: centre at (R, 0), start at the origin
// heading north, turning right (clockwise seen from above).
void circle(double t, double enu[3], double v_enu[3]) {
  enu[0] = kR - kR * std::cos(kW * t);
  enu[1] = kR * std::sin(kW * t);
  enu[2] = 0.0;
  v_enu[0] = kV * std::sin(kW * t);
  v_enu[1] = kV * std::cos(kW * t);
  v_enu[2] = 0.0;
}

void write_truth(const std::filesystem::path& path) {
  const GeographicLib::LocalCartesian lc(kLat, kLon, kH);
  std::ofstream out(path);
  out << "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
         "clock_bias_m,clock_drift_mps\n";
  out.precision(12);
  for (int k = 0; k <= 300; ++k) {  // 30 s at 10 Hz
    const double t = 0.1 * k;
    double enu[3], v[3], lat, lon, h, X, Y, Z;
    circle(t, enu, v);
    lc.Reverse(enu[0], enu[1], enu[2], lat, lon, h);
    GeographicLib::Geocentric::WGS84().Forward(lat, lon, h, X, Y, Z);
    // The truth's NED velocity at its own point (the local frames 100 m apart differ by 1.6e-5 rad: < 0.2 mm/s).
    out << t << ",2190," << kTow0 + t << "," << X << "," << Y << "," << Z << "," << lat << "," << lon << "," << h << ","
        << v[1] << "," << v[0] << "," << -v[2] << ",0,0\n";
  }
}

// Fixes at t = 0.05 + 0.1 k (between truth rows), each with clock bias b: the fix's receiver time is the true
// time plus b / c.
void write_solution(const std::filesystem::path& path, const double offset_enu[3], const double dv_enu[3],
                    double clock_bias_m) {
  const GeographicLib::LocalCartesian lc(kLat, kLon, kH);
  std::ofstream out(path);
  out << "gps_week,tow_s,lat_deg,lon_deg,height_m,ecef_x_m,ecef_y_m,ecef_z_m,vel_e_mps,vel_n_mps,vel_u_mps,"
         "clock_bias_m,clock_drift_mps,num_sats,pdop,hdop,vdop,excluded_prn\n";
  out.precision(12);
  for (int k = 0; k < 290; ++k) {
    const double t = 0.05 + 0.1 * k;
    double enu[3], v[3];
    circle(t, enu, v);
    double lat, lon, h, X, Y, Z;
    lc.Reverse(enu[0] + offset_enu[0], enu[1] + offset_enu[1], enu[2] + offset_enu[2], lat, lon, h);
    GeographicLib::Geocentric::WGS84().Forward(lat, lon, h, X, Y, Z);
    out << "2190," << kTow0 + t + clock_bias_m / kC << "," << lat << "," << lon << "," << h << "," << X << "," << Y
        << "," << Z << "," << v[0] + dv_enu[0] << "," << v[1] + dv_enu[1] << "," << v[2] + dv_enu[2] << ","
        << clock_bias_m << ",0,8,1.9,1.0,1.6,\n";
  }
}

TEST(SolutionCompare, AKnownOffsetOnACircleComesBack) {
  const auto dir = test::scratch_dir();
  write_truth(dir / "truth.csv");
  const double offset[3] = {1.0, -2.0, 2.0};  // |.| = 3 m, horizontal sqrt(5), vertical 2
  const double dv[3] = {0.03, 0.0, -0.04};    // |.| = 0.05 m/s
  // A receiver clock 100 ms ahead: compared at the receiver's time instead of the true one, every fix would be
  // 0.83 m off along the track (3-D RMS 3.11 m); the comparison takes the true time, so 3 m comes back.
  write_solution(dir / "solution.csv", offset, dv, kC * 0.1);
  const auto c =
      compare_solution(read_solution_csv(dir / "solution.csv"), read_simulation_truth_csv(dir / "truth.csv"));
  EXPECT_EQ(c.fixes, 290);
  EXPECT_EQ(c.fixes_outside_truth, 0);
  EXPECT_NEAR(c.rms_3d_m, 3.0, 1e-3);
  EXPECT_NEAR(c.rms_horizontal_m, std::sqrt(5.0), 1e-3);
  EXPECT_NEAR(c.rms_vertical_m, 2.0, 1e-3);
  EXPECT_NEAR(c.max_3d_m, 3.0, 1e-3);
  EXPECT_NEAR(c.mean_enu_m.x(), 1.0, 1e-3);
  EXPECT_NEAR(c.mean_enu_m.y(), -2.0, 1e-3);
  EXPECT_NEAR(c.mean_enu_m.z(), 2.0, 1e-3);
  EXPECT_NEAR(c.rms_velocity_mps, 0.05, 1e-4);
  EXPECT_NEAR(c.rms_velocity_horizontal_mps, 0.03, 1e-4);
  EXPECT_NEAR(c.rms_velocity_vertical_mps, 0.04, 1e-4);
}

TEST(SolutionCompare, SkipAndTheTruthsSpanLimitWhatIsCompared) {
  const auto dir = test::scratch_dir();
  write_truth(dir / "truth.csv");
  const double zero[3] = {0.0, 0.0, 0.0};
  write_solution(dir / "solution.csv", zero, zero, 0.0);
  auto fixes = read_solution_csv(dir / "solution.csv");
  fixes.push_back(fixes.back());
  fixes.back().tow_s = kTow0 + 31.0;  // after the truth's last row (30 s)
  const auto c = compare_solution(fixes, read_simulation_truth_csv(dir / "truth.csv"), {.skip_s = 10.0});
  EXPECT_EQ(c.fixes, 190);  // t = 10.05 .. 28.95 s
  EXPECT_EQ(c.fixes_outside_truth, 1);
  EXPECT_NEAR(c.first_tow_s, kTow0 + 10.05, 1e-6);
  EXPECT_LT(c.rms_3d_m, 1e-3);
  EXPECT_LT(c.rms_velocity_mps, 1e-4);
}

TEST(SolutionCompare, AMissingColumnOrABadNumberNamesTheFileAndLine) {
  const auto dir = test::scratch_dir();
  std::ofstream(dir / "no_column.csv") << "gps_week,tow_s,ecef_x_m\n2190,1,2\n";
  try {
    read_solution_csv(dir / "no_column.csv");
    FAIL() << "no InputError";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_column.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ecef_y_m"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "bad.csv") << "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,vel_n_mps,vel_e_mps,vel_d_mps\n"
                                 << "0,2190,1,2,3,4,5,6,7\n0.1,2190,1.1,2,x,4,5,6,7\n";
  try {
    read_simulation_truth_csv(dir / "bad.csv");
    FAIL() << "no InputError";
  } catch (const io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv"), std::string::npos) << e.what();
    EXPECT_EQ(e.line(), 3);
  }
  EXPECT_THROW(read_solution_csv(dir / "absent.csv"), io::InputError);
}

}  // namespace
}  // namespace ultratrack::pipelines
