// SPDX-License-Identifier: GPL-3.0-or-later
// IMU and navigation CSV files: exact round trips, and every kind of bad input rejected with a typed
// error that names the file and the line. Also the segment-file reader of the trajectory description.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "ins/attitude.hpp"
#include "ins/imu_csv.hpp"
#include "ins/ins_error.hpp"
#include "ins/nav_csv.hpp"
#include "ins/trajectory.hpp"
#include "support/expect_input_error.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::ins;
namespace fs = std::filesystem;

namespace {

using ultratrack::test::expect_error_at;

constexpr char kImuHeader[] = "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n";
constexpr char kNavHeader[] = "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,roll_deg,pitch_deg,yaw_deg\n";

fs::path write_text(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST(ImuCsv, RoundTripIsExact) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::vector<ImuIncrement> in;
  for (int k = 1; k <= 100; ++k)
    in.push_back({k * 0.01, {1e-7 * k, -3.3e-6 / k, std::sqrt(2.0) * 1e-5}, {0.1 / 3, -0.0981 * k, std::numbers::pi}});
  write_imu_csv(dir / "imu.csv", in);
  EXPECT_FALSE(fs::exists(dir / "imu.csv.tmp"));
  const auto out = read_imu_csv(dir / "imu.csv");
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].t_s, in[i].t_s);
    EXPECT_EQ(out[i].dtheta_b, in[i].dtheta_b);
    EXPECT_EQ(out[i].dv_b, in[i].dv_b);
  }
}

TEST(ImuCsv, RejectsBadInputNamingFileAndLine) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const std::string ok = "0.01,0,0,0,0,0,-0.098\n";
  struct Case {
    std::string name, text;
    int line;
    std::string what;
  };
  const std::vector<Case> cases{
      {"missing_field.csv", std::string(kImuHeader) + ok + "0.02,0,0,0,0,0\n", 3, "fields"},
      {"extra_field.csv", std::string(kImuHeader) + ok + "0.02,0,0,0,0,0,0,1\n", 3, "more than"},
      {"nan.csv", std::string(kImuHeader) + ok + "0.02,0,nan,0,0,0,0\n", 3, "not finite"},
      {"inf.csv", std::string(kImuHeader) + "0.01,0,0,0,inf,0,0\n", 2, "not finite"},
      {"text.csv", std::string(kImuHeader) + ok + "0.02,0,0,abc,0,0,0\n", 3, "not a number"},
      {"empty_field.csv", std::string(kImuHeader) + "0.01,0,,0,0,0,0\n", 2, "not a number"},
      {"time_back.csv", std::string(kImuHeader) + ok + "0.005,0,0,0,0,0,0\n", 3, "time does not increase"},
      {"time_same.csv", std::string(kImuHeader) + ok + ok, 3, "time does not increase"},
      {"bad_header.csv", "t,dx,dy,dz,vx,vy,vz\n" + ok, 1, "bad header"},
  };
  for (const auto& c : cases) {
    const fs::path p = write_text(dir, c.name, c.text);
    expect_error_at([&] { read_imu_csv(p); }, p, c.line, c.what);
  }
  const fs::path none = dir / "does_not_exist.csv";
  expect_error_at([&] { read_imu_csv(none); }, none, 0, "cannot open");
  const fs::path empty = write_text(dir, "empty.csv", "");
  expect_error_at([&] { read_imu_csv(empty); }, empty, 0, "missing header");
}

TEST(ImuCsv, RatesFormBecomesTrapezoidalIncrements) {
  const fs::path dir = ultratrack::test::scratch_dir();
  // Body rate and specific force linear in time: the trapezoidal rule is exact for them.
  std::string text = "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyro_x_radps,gyro_y_radps,gyro_z_radps\n";
  auto f = [](double t) { return Eigen::Vector3d(0.5 + 2.0 * t, -0.1, -9.8 + t); };
  auto w = [](double t) { return Eigen::Vector3d(0.01, -0.02 * t, 0.3); };
  for (int k = 0; k <= 200; ++k) {
    const double t = 10.0 + k * 0.005;
    const Eigen::Vector3d a = f(t), g = w(t);
    text += fmt::format("{},{},{},{},{},{},{}\n", t, a.x(), a.y(), a.z(), g.x(), g.y(), g.z());
  }
  const fs::path p = write_text(dir, "rates.csv", text);
  EXPECT_EQ(imu_csv_form(p), ImuCsvForm::Rates);
  const auto out = read_imu_csv(p);
  ASSERT_EQ(out.size(), 200u);  // the first sample opens the first interval
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double t1 = 10.0 + (i + 1) * 0.005, t0 = t1 - 0.005;
    EXPECT_NEAR(out[i].t_s, t1, 1e-12);
    EXPECT_TRUE(out[i].dv_b.isApprox(0.5 * (f(t0) + f(t1)) * 0.005, 1e-9)) << i;
    EXPECT_TRUE(out[i].dtheta_b.isApprox(0.5 * (w(t0) + w(t1)) * 0.005, 1e-9)) << i;
  }
}

TEST(ImuCsv, RejectsUnknownHeadersGapsAndSingleSamples) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const fs::path odd = write_text(dir, "odd.csv", "# logger v2\ntime,ax,ay,az,gx,gy,gz\n0,0,0,0,0,0,0\n");
  expect_error_at([&] { read_imu_csv(odd); }, odd, 2, "expected increments");
  const fs::path gap = write_text(dir, "gap.csv", std::string(kImuHeader) + "0.01,0,0,0,0,0,0\n2.5,0,0,0,0,0,0\n");
  expect_error_at([&] { read_imu_csv(gap); }, gap, 3, "gap of 2.490 s");
  EXPECT_NO_THROW(read_imu_csv(gap, {3.0}));
  const fs::path one = write_text(dir, "one.csv",
                                  "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyro_x_radps,gyro_y_radps,gyro_z_radps\n"
                                  "0,0,0,-9.8,0,0,0\n");
  expect_error_at([&] { read_imu_csv(one); }, one, 0, "single rate sample");
  const fs::path nan = write_text(dir, "nan_rate.csv",
                                  "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyro_x_radps,gyro_y_radps,gyro_z_radps\n"
                                  "0,0,0,-9.8,0,0,0\n0.01,0,nan,-9.8,0,0,0\n");
  expect_error_at([&] { read_imu_csv(nan); }, nan, 3, "not finite");
}

TEST(NavCsv, RoundTripKeepsStateToRoundingPrecision) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::vector<NavState> in;
  for (int k = 0; k < 20; ++k) {
    NavState s;
    s.t_s = 0.1 * k;
    s.lat_rad = 0.63 + 1e-7 * k;
    s.lon_rad = -2.2 + 3e-7 * k;
    s.height_m = 123.456 + k;
    s.v_n = {1.0 / 3, -k * 0.7, 0.01};
    s.q_nb = quaternion_from_euler({0.01 * k, -0.2, 3.0 - 0.3 * k});
    in.push_back(s);
  }
  write_nav_csv(dir / "nav.csv", in);
  const auto out = read_nav_csv(dir / "nav.csv");
  ASSERT_EQ(out.size(), in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].t_s, in[i].t_s);
    EXPECT_NEAR(out[i].lat_rad, in[i].lat_rad, 1e-15);
    EXPECT_NEAR(out[i].lon_rad, in[i].lon_rad, 1e-15);
    EXPECT_EQ(out[i].height_m, in[i].height_m);
    EXPECT_EQ(out[i].v_n, in[i].v_n);
    EXPECT_LT(attitude_error_n(out[i].q_nb, in[i].q_nb).norm(), 1e-14);
  }
}

TEST(NavCsv, RejectsBadInputNamingFileAndLine) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const std::string ok = "0,36.3,127.3,100,0,0,0,0,0,0\n";
  struct Case {
    std::string name, text;
    int line;
    std::string what;
  };
  const std::vector<Case> cases{
      {"short.csv", std::string(kNavHeader) + ok + "1,36.3,127.3,100,0,0,0,0,0\n", 3, "fields"},
      {"nan.csv", std::string(kNavHeader) + "0,NaN,127.3,100,0,0,0,0,0,0\n", 2, "not finite"},
      {"lat.csv", std::string(kNavHeader) + "0,95,127.3,100,0,0,0,0,0,0\n", 2, "lat_deg"},
      {"pitch.csv", std::string(kNavHeader) + "0,36,127.3,100,0,0,0,0,91,0\n", 2, "pitch_deg"},
      {"time.csv", std::string(kNavHeader) + ok + ok, 3, "time does not increase"},
      {"header.csv", "t_s,lat_deg\n" + ok, 1, "bad header"},
  };
  for (const auto& c : cases) {
    const fs::path p = write_text(dir, c.name, c.text);
    expect_error_at([&] { read_nav_csv(p); }, p, c.line, c.what);
  }
}

TEST(SegmentsCsv, ReadsSegmentsAndRejectsBadRows) {
  const fs::path dir = ultratrack::test::scratch_dir();
  const fs::path good = write_text(dir, "segs.csv",
                                   "# a test drive\nduration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                   "10,1,0,0,0\n\n20,0,3,0.5,2\n");
  TrajectorySpec start;
  start.lat0_rad = 0.5;
  const TrajectorySpec spec = read_segments_csv(good, start);
  ASSERT_EQ(spec.segments.size(), 2u);
  EXPECT_EQ(spec.lat0_rad, 0.5);
  EXPECT_EQ(spec.segments[1].duration_s, 20.0);
  EXPECT_NEAR(spec.segments[1].turn_rate_rps, 3 * std::numbers::pi / 180, 1e-15);
  EXPECT_NEAR(spec.segments[1].grade_rad, 2 * std::numbers::pi / 180, 1e-15);
  EXPECT_DOUBLE_EQ(spec.duration_s(), 30.0);
  const fs::path neg =
      write_text(dir, "neg.csv", "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n-1,0,0,0,0\n");
  expect_error_at([&] { read_segments_csv(neg, start); }, neg, 2, "duration");
  const fs::path bad =
      write_text(dir, "bad.csv", "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n5,x,0,0,0\n");
  expect_error_at([&] { read_segments_csv(bad, start); }, bad, 2, "not a number");
}

TEST(Profiles, UnknownNameAndBadDurationAreInputErrors) {
  EXPECT_THROW(profile_spec("loop", 10, 0, 0, 0), InputError);
  EXPECT_THROW(profile_spec("circle", 0, 0, 0, 0), InputError);
  EXPECT_THROW(profile_spec("circle", std::nan(""), 0, 0, 0), InputError);
}
