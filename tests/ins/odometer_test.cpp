// SPDX-License-Identifier: GPL-3.0-or-later
// The odometer: simulated pulses against closed forms (scale factor, delay, slips, misalignment rotation), the
// simulator's file read back, and every kind of bad odometer.csv rejected naming the file and the line.
#include "ins/odometer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "ins/attitude.hpp"
#include "ins/ins_error.hpp"
#include "ins/odometer_csv.hpp"
#include "support/expect_input_error.hpp"
#include "support/test_data.hpp"

using namespace ultratrack::ins;
namespace fs = std::filesystem;

namespace {

using ultratrack::test::expect_error_at;

fs::path write_text(const std::string& name, const std::string& text) {
  const fs::path p = ultratrack::test::scratch_dir() / name;
  std::ofstream(p) << text;
  return p;
}

// 20 s at a constant 10 m/s, truth at 100 Hz.
std::vector<TruthSample> straight_truth() {
  std::vector<TruthSample> t(2001);
  for (std::size_t i = 0; i < t.size(); ++i) {
    t[i].t_s = 0.01 * static_cast<double>(i);
    t[i].distance_m = 10.0 * t[i].t_s;
  }
  return t;
}

double total_distance(const std::vector<OdometerSample>& s) {
  double d = 0.0;
  for (const auto& x : s) d += x.distance_m;
  return d;
}

}  // namespace

TEST(OdometerSimulation, CountsScaleFactorDelayAndSlips) {
  const auto truth = straight_truth();
  OdometerOptions o;
  o.scale_factor_error = 0.02;
  EXPECT_NEAR(total_distance(simulate_odometer(truth, o)), 1.02 * 200.0, 0.02);
  o.delay_s = 0.5;  // the last 0.5 s of motion not counted yet, the first 0.5 s none
  EXPECT_NEAR(total_distance(simulate_odometer(truth, o)), 1.02 * 195.0, 0.02);
  o.slips = {{5.0, 2.0, -1.0}, {12.0, 1.0, 0.5}};  // a locked wheel for 2 s (20 m lost), a spin (+5 m)
  EXPECT_NEAR(total_distance(simulate_odometer(truth, o)), 1.02 * (195.0 - 20.0 + 5.0), 0.03);
  const auto s = simulate_odometer(truth, o);
  EXPECT_EQ(s[60].pulses, 0);  // t = 6.1 s: inside the skid (delayed by 0.5 s)
}

TEST(OdometerSimulation, MisalignmentRotationIsYawThenPitch) {
  const Eigen::Matrix3d C = C_bv_from_misalignment(0.02, 0.03);
  EXPECT_TRUE(C.isApprox(quaternion_from_euler({0.0, 0.02, 0.03}).toRotationMatrix(), 1e-12));
}

TEST(OdometerCsv, ReadsTheSimulatorsFile) {
  const fs::path f = write_text("odo_ok.csv", "t_s,pulses,distance_m\n0.1,50,1.0\n0.2,51,1.02\n0.3,49,0.98\n");
  const OdometerRecord r = read_odometer_csv(f);
  ASSERT_EQ(r.samples.size(), 3u);
  EXPECT_NEAR(r.rate_hz, 10.0, 1e-9);
  EXPECT_EQ(r.samples[1].pulses, 51);
  EXPECT_DOUBLE_EQ(r.samples[2].distance_m, 0.98);
  EXPECT_NO_THROW(read_odometer_csv(f, {10.0}));
}

TEST(OdometerCsv, RejectsBadFilesNamingTheLine) {
  const std::string h = "t_s,pulses,distance_m\n";
  const fs::path back = write_text("odo_back.csv", h + "0.1,5,0.1\n0.2,5,0.1\n0.15,5,0.1\n");
  expect_error_at([&] { read_odometer_csv(back); }, back, 4, "does not increase");
  const fs::path neg = write_text("odo_neg.csv", h + "0.1,5,0.1\n0.2,-3,0.1\n");
  expect_error_at([&] { read_odometer_csv(neg); }, neg, 3, "pulses");
  const fs::path nan = write_text("odo_nan.csv", h + "0.1,5,0.1\n0.2,5,nan\n");
  expect_error_at([&] { read_odometer_csv(nan); }, nan, 3, "");
  const fs::path gap = write_text("odo_gap.csv", h + "0.1,5,0.1\n0.2,5,0.1\n0.4,5,0.1\n");
  expect_error_at([&] { read_odometer_csv(gap); }, gap, 4, "rate");
  const fs::path declared = write_text("odo_rate.csv", h + "0.1,5,0.1\n0.2,5,0.1\n");
  expect_error_at([&] { read_odometer_csv(declared, {20.0}); }, declared, 3, "declared");
  const fs::path empty = write_text("odo_empty.csv", "");
  EXPECT_THROW(read_odometer_csv(empty), InputError);
  const fs::path header_only = write_text("odo_header.csv", h);
  EXPECT_THROW(read_odometer_csv(header_only), InputError);
  const fs::path wrong = write_text("odo_wrong.csv", "t,pulses,distance_m\n0.1,5,0.1\n");
  expect_error_at([&] { read_odometer_csv(wrong); }, wrong, 1, "");
}
