// The scalar receiver on a moving antenna (issue 3's dynamic check, shortened for CI): `ultratrack simulate`
// drives the antenna round a circle of radius 100 m at 30 km/h (centripetal 0.69 m/s^2, line-of-sight
// accelerations up to that, i.e. Doppler rates to 3.6 Hz/s) with brdc0010.22n; `ultratrack receive` starts hot
// (--nav) on 2.0 MHz i8 (1.96 samples per chip: a non-integer rate) and the fixes are compared with the truth by
// tools/solution_compare. The full 300 s run at 2.6 MHz is in docs/validation.md.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "solution_compare.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  CLI::App app;
  ultratrack::tools::add_simulate_command(app);
  ultratrack::tools::add_receive_command(app);
  args.insert(args.begin(), command);
  args.push_back("--quiet");
  std::reverse(args.begin(), args.end());
  app.parse(args);
}

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
  ULTRATRACK_REQUIRE_SHARED_FILE(brdc, "brdc0010.22n");
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "circle.csv") << "duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg\n"
                                       "25.0,0.0,4.774648,0.0,0.0\n";  // v / R = 8.3333 / 100 rad/s
  std::ofstream(dir / "circle.toml") << "[signal]\nsample_rate_hz = 2.0e6\nformat = \"i8\"\nduration_s = 25.0\n"
                                        "cn0_dbhz = 45.0\nseed = 2\n"
                                        "[time]\ngps_week = 2190\ntow_s = 518772.0\n"
                                        "[navigation]\nrinex = \""
                                     << brdc.generic_string()
                                     << "\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
                                        "[atmosphere]\nionosphere = true\ntroposphere = false\n"
                                        "[trajectory]\nfile = \"circle.csv\"\nspeed_mps = 8.333333333\n"
                                        "heading_deg = 0.0\n";
  const auto sim = dir / "sim", rx = dir / "rx";
  run("simulate", {"--scenario", (dir / "circle.toml").string(), "--out", sim.string()});
  run("receive", {"--input", (sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.0e6", "--nav",
                  brdc.string(), "--troposphere", "off", "--out", rx.string()});
  fs::remove(sim / "antenna0.i8.bin");

  using namespace ultratrack::tools;
  const SolutionComparison c =
      compare_solution(read_solution_csv(rx / "solution.csv"), read_simulation_truth_csv(sim / "truth.csv"));
  const double ttff = json_number(rx / "summary.json", "ttff_s");
  std::printf("circle 100 m, 30 km/h, 25 s hot: TTFF %.2f s, %d fixes, 3-D RMS %.3f m (max %.3f), velocity RMS "
              "%.4f m/s\n", ttff, c.fixes, c.rms_3d_m, c.max_3d_m, c.rms_velocity_mps);
  EXPECT_GE(ttff, 6.07);
  EXPECT_LE(ttff, 18.2);
  EXPECT_GE(c.fixes, 60);  // at least 6 s of 10 Hz fixes
  EXPECT_LE(c.rms_3d_m, 2.0);
  EXPECT_LE(c.rms_velocity_mps, 0.3);
}
