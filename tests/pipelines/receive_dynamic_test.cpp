// SPDX-License-Identifier: GPL-3.0-or-later
// The scalar receiver on a moving antenna (the dynamic check, shortened for CI), through the library: the simulator
// drives the antenna round a circle of radius 100 m at 30 km/h (centripetal 0.69 m/s^2, line-of-sight
// accelerations up to that, i.e. Doppler rates to 3.6 Hz/s) with tests/data's brdc3540; pipelines::receive_file starts
// hot (the same nav file) on 2.0 MHz i8 (1.96 samples per chip: a non-integer rate) and the fixes are compared with the
// truth by pipelines/solution_compare. The full 300 s run at 2.6 MHz is in docs/validation.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pipelines/solution_compare.hpp"
#include "support/simulated_receive.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack::pipelines;

namespace {

double json_number(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  const std::string json = s.str();
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 3));
}

}  // namespace

// Tolerances are the issue's (3-D RMS <= 2 m, velocity RMS <= 0.3 m/s). Expected at 45 dB-Hz: ~0.5-0.9 m
// (DLL noise ~0.3 m per pseudorange times PDOP ~2, less after the Hatch filter) and ~0.04 m/s (PLL frequency
// noise times PDOP): the tolerances fail on a loop that lags the dynamics (a 2nd-order PLL of 5 Hz would err
// by a / wn^2, degrees of phase; a velocity taken from an over-smoothed Doppler lags the 0.69 m/s^2 turn by
// metres per second) or on a lever-arm or time-tag error of a few milliseconds (8.3 m/s x 1 ms = 8 mm each).
// TTFF: hot, the first subframe starts 6.07 s into the file; a fix needs frame sync and its time tag.
TEST(ReceiveDynamic, CircleOf100mAt30kmhHotStartWithinTheIssuesTolerances) {
  const std::filesystem::path brdc = ultratrack::test::shipped_nav_file();
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "circle.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                       "25.0,0.0,4.774648,0.0,0.0\n";  // v / R = 8.3333 / 100 rad/s
  std::ofstream(dir / "circle.toml") << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 25.0\n"
                                        "cn0_dbhz = 45.0\nseed = 2\n"
                                        "[time]\ngps_week = 1823\ntow_s = 518772.0\n"
                                        "[navigation]\nrinex = \""
                                     << brdc.generic_string()
                                     << "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
                                        "[atmosphere]\nionosphere = true\ntroposphere = false\n"
                                        "[trajectory]\nfile = \"circle.csv\"\nspeed_mps = 8.333333333\n"
                                        "heading_deg = 0.0\n";
  const auto sim = dir / "sim", rx = dir / "rx";
  ultratrack::test::simulate_scenario(dir / "circle.toml", sim);
  ultratrack::test::receive_simulated({.input = sim / "antenna0.i8.bin", .nav = brdc, .out = rx, .troposphere = false});
  fs::remove(sim / "antenna0.i8.bin");

  using namespace ultratrack::pipelines;
  const SolutionComparison c =
      compare_solution(read_solution_csv(rx / "solution.csv"), read_simulation_truth_csv(sim / "truth.csv"));
  const double ttff = json_number(rx / "summary.json", "ttff_s");
  std::printf(
      "circle 100 m, 30 km/h, 25 s hot: TTFF %.2f s, %d fixes, 3-D RMS %.3f m (max %.3f), velocity RMS "
      "%.4f m/s\n",
      ttff, c.fixes, c.rms_3d_m, c.max_3d_m, c.rms_velocity_mps);
  EXPECT_GE(ttff, 6.07);
  EXPECT_LE(ttff, 18.2);
  EXPECT_GE(c.fixes, 60);  // at least 6 s of 10 Hz fixes
  EXPECT_LE(c.rms_3d_m, 2.0);
  EXPECT_LE(c.rms_velocity_mps, 0.3);
}

// Static at 35 dB-Hz (issue 3: "fixes"), hot on 2.0 MHz i8, 30 s. Every satellite must be tracked to the end
// (35 dB-Hz is 4 dB above the measured tracking threshold, docs/validation.md) and fixes must come. The position
// bound is from the DLL's thermal noise: 1 Hz, 1 chip E-L, 20 ms at 35 dB-Hz gives 0.0128 chip = 3.8 m per
// pseudorange, a third to a sixth of it as the Hatch filter converges (DLL noise correlated over ~0.3 s), times
// PDOP ~2: 1.5-3.5 m expected, 6 m allowed (the fixes span ~18 s, so their errors are strongly correlated).
TEST(ReceiveDynamic, Static35DbHzHotStartTracksEverySatelliteAndFixes) {
  const std::filesystem::path brdc = ultratrack::test::shipped_nav_file();
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "static.toml") << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 30.0\n"
                                        "cn0_dbhz = 35.0\nseed = 4\n"
                                        "[time]\ngps_week = 1823\ntow_s = 518772.0\n"
                                        "[navigation]\nrinex = \""
                                     << brdc.generic_string()
                                     << "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
                                        "[atmosphere]\nionosphere = true\ntroposphere = false\n";
  const auto sim = dir / "sim", rx = dir / "rx";
  ultratrack::test::simulate_scenario(dir / "static.toml", sim);
  ultratrack::test::receive_simulated({.input = sim / "antenna0.i8.bin", .nav = brdc, .out = rx, .troposphere = false});
  fs::remove(sim / "antenna0.i8.bin");

  using namespace ultratrack::pipelines;
  const SolutionComparison c =
      compare_solution(read_solution_csv(rx / "solution.csv"), read_simulation_truth_csv(sim / "truth.csv"));
  const double ttff = json_number(rx / "summary.json", "ttff_s");
  std::printf("static 35 dB-Hz, 30 s hot: TTFF %.2f s, %d fixes, 3-D RMS %.3f m (max %.3f), velocity RMS %.4f m/s\n",
              ttff, c.fixes, c.rms_3d_m, c.max_3d_m, c.rms_velocity_mps);
  EXPECT_GE(ttff, 6.07);
  EXPECT_LE(ttff, 18.2);
  EXPECT_GE(c.fixes, 100);
  EXPECT_LE(c.rms_3d_m, 6.0);
  // Every satellite of the file: one acquisition, no loss.
  std::ifstream sats(sim / "satellites.csv");
  std::string line;
  std::getline(sats, line);
  std::ifstream summary_in(rx / "summary.json");
  std::stringstream summary;
  summary << summary_in.rdbuf();
  int satellites = 0;
  while (std::getline(sats, line)) {
    const std::string prn = line.substr(0, line.find(','));
    const auto at = summary.str().find("{\"prn\": " + prn + ",");
    ASSERT_NE(at, std::string::npos) << "PRN " << prn << " not acquired";
    EXPECT_NE(summary.str().find("\"losses\": 0,", at), std::string::npos);
    EXPECT_EQ(summary.str().find("\"losses\": 0,", at), summary.str().find("\"losses\":", at))
        << "PRN " << prn << " lost";
    ++satellites;
  }
  EXPECT_GE(satellites, 8);
}
