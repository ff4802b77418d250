// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack snapshot` end to end: a simulated 2-bit real snapshot (the format of the low-power front ends that
// snapshot receivers use) solved without an approximate position from a time 6 s off, against simulate's truth;
// and the bad inputs: no satellite (exit 2), fewer than 5 usable satellites and a time off by more than the
// search (exit 3 with snapshot.json saying why).
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/rinex_nav.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

constexpr double kTow = 540123.0;

struct SnapshotFiles {
  fs::path dir, input, nav;
  Eigen::Vector3d truth_e_m;
};

// 80 ms of r2 at 8.184 MHz (IF 2.046 MHz), 42 dB-Hz, nominal constellation, ionosphere on, clock 0.2 ms / 0.3 ppm.
const SnapshotFiles& files() {
  static const SnapshotFiles f =
      [] {
        SnapshotFiles s;
        s.dir = ultratrack::test::scratch_dir();
        std::ofstream(s.dir / "snap.toml")
            << "[signal]\nsample_rate_hz = 8.184e6\nif_hz = 2.046e6\nformat = \"r2\"\n"
               "duration_s = 0.082\ncn0_dbhz = 42.0\nseed = 11\n"
               "[time]\ngps_week = 2190\ntow_s = "
            << kTow
            << "\n[navigation]\nconstellation = \"nominal\"\nelevation_mask_deg = 5.0\n"
               "[receiver]\nllh_deg_m = [47.3, 8.55, 420.0]\nclock_bias_m = 60000.0\n"
               "clock_drift_mps = 90.0\n[atmosphere]\nionosphere = true\ntroposphere = true\n";
        ultratrack::test_support::run_command(
            "simulate", {"--scenario", (s.dir / "snap.toml").string(), "--out", (s.dir / "sim").string()});
        const auto c = ultratrack::signals::nominal_constellation({2190, kTow});
        ultratrack::signals::RinexNavData nav;
        nav.ephemerides = c.ephemerides;
        nav.klobuchar = c.klobuchar;
        nav.utc = c.utc;
        s.nav = s.dir / "nominal.rnx";
        ultratrack::signals::write_rinex_nav_304(s.nav, nav);
        s.input = s.dir / "sim" / "antenna0.r2.bin";
        std::ifstream truth(s.dir / "sim" / "truth.csv");
        std::string header, row;
        std::getline(truth, header);
        std::getline(truth, row);
        const auto names = ultratrack::test::split_csv_line(header);
        const auto values = ultratrack::test::split_csv_line(row);
        s.truth_e_m = {std::stod(values.at(ultratrack::test::csv_column(names, "ecef_x_m"))),
                       std::stod(values.at(ultratrack::test::csv_column(names, "ecef_y_m"))),
                       std::stod(values.at(ultratrack::test::csv_column(names, "ecef_z_m")))};
        return s;
      }();
  return f;
}

std::vector<std::string> snapshot_args(const SnapshotFiles& f, const fs::path& out, const std::string& time) {
  return {"--input", f.input.string(), "--format", "r2", "--fs",          "8.184e6", "--if",  "2.046e6",
          "--nav",   f.nav.string(),   "--time",   time, "--doppler-max", "6000",    "--out", out.string()};
}

// A number after "key": in a JSON text (the first occurrence).
double json_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\":");
  if (at == std::string::npos) throw std::runtime_error("no " + key);
  return std::stod(text.substr(at + key.size() + 3));
}

TEST(SnapshotCommand, TwoBitSnapshotWithoutApproximatePositionFixesWithin15m) {
  const SnapshotFiles& f = files();
  const fs::path out = f.dir / "fix";
  std::ostringstream time;
  time.precision(12);
  time << "2190:" << kTow + 6.0;
  ultratrack::test_support::run_command("snapshot", snapshot_args(f, out, time.str()));
  const std::string json = ultratrack::test::read_text_file(out / "snapshot.json");
  ASSERT_NE(json.find("\"valid\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"quality\": \"pass\""), std::string::npos) << json;
  const auto at = json.find("\"ecef_m\": [");
  ASSERT_NE(at, std::string::npos);
  std::istringstream xyz(json.substr(at + 11));
  Eigen::Vector3d r;
  char comma = 0;
  xyz >> r.x() >> comma >> r.y() >> comma >> r.z();
  EXPECT_LT((r - f.truth_e_m).norm(), 15.0) << json;
  // The time error is observed through the satellites' range rates only: within 3 of its own 1-sigma (~ms).
  const double sigma_time_s = json_number(json, "time_s");
  EXPECT_LT(sigma_time_s, 0.02);
  EXPECT_NEAR(json_number(json, "time_correction_s"), -6.0, 3.0 * sigma_time_s);
  // One row in solution.csv under the receiver's header.
  std::ifstream csv(out / "solution.csv");
  std::string line;
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 2);
}

TEST(SnapshotCommand, FewerThanFiveSatellitesAndATimeBeyondTheSearchExitWith3) {
  const SnapshotFiles& f = files();
  // Four PRNs searched: 4 or fewer detected.
  auto few = snapshot_args(f, f.dir / "few", "2190:540123");
  few.insert(few.end(), {"--prn", "1-4"});
  try {
    ultratrack::test_support::run_command("snapshot", few);
    FAIL() << "no exit";
  } catch (const ultratrack::tools::CommandExit& e) {
    EXPECT_EQ(e.code, 3);
    EXPECT_NE(std::string(e.what()).find("at least 5"), std::string::npos) << e.what();
  } catch (const ultratrack::signals::InputError& e) {
    // None of PRN 1-4 visible: "no satellite detected" is the other clear answer.
    EXPECT_NE(std::string(e.what()).find("no satellite"), std::string::npos) << e.what();
  }
  // 40 s off with a +-6 s search (sigma 2 s).
  auto late = snapshot_args(f, f.dir / "late", "2190:540163");
  late.insert(late.end(), {"--time-sigma-s", "2", "--approx-llh", "47.3,8.55,400"});
  try {
    ultratrack::test_support::run_command("snapshot", late);
    FAIL() << "no exit";
  } catch (const ultratrack::tools::CommandExit& e) {
    EXPECT_EQ(e.code, 3);
    EXPECT_NE(std::string(e.what()).find("beyond the search"), std::string::npos) << e.what();
  }
  EXPECT_NE(ultratrack::test::read_text_file(f.dir / "late" / "snapshot.json").find("\"valid\": false"),
            std::string::npos);
}

TEST(SnapshotCommand, NoiseOnlyFileIsAnInputError) {
  const SnapshotFiles& f = files();
  const fs::path noise = f.dir / "noise.i8";
  std::mt19937 rng(3);
  std::normal_distribution<float> g(0.0f, 20.0f);
  std::ofstream out(noise, std::ios::binary);
  for (int i = 0; i < 2 * 2600 * 40; ++i) out.put(static_cast<char>(static_cast<signed char>(g(rng))));
  out.close();
  EXPECT_THROW(ultratrack::test_support::run_command(
                   "snapshot", {"--input", noise.string(), "--format", "i8", "--fs", "2.6e6", "--nav", f.nav.string(),
                                "--time", "2190:540123", "--out", (f.dir / "noise").string()}),
               ultratrack::signals::InputError);
  // Bad --time text.
  EXPECT_THROW(ultratrack::test_support::run_command(
                   "snapshot", {"--input", noise.string(), "--format", "i8", "--fs", "2.6e6", "--nav", f.nav.string(),
                                "--time", "540123", "--out", (f.dir / "noise").string()}),
               ultratrack::signals::InputError);
}

}  // namespace
