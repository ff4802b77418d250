// SPDX-License-Identifier: GPL-3.0-or-later
// End to end on the synthesiser's signal: `ultratrack simulate` (signals/if_synthesiser, nominal constellation,
// static receiver, 45 dB-Hz, 2.6 MHz i8) then `ultratrack receive`, checked against the scenario's truth.csv.
// The scenario starts 2 s before a frame start (tow 518398, week 2190), so subframes 1-3 leave the satellites at
// 518400-518418 s: the first fix cannot come before 18 s of transmit time + ~70 ms of travel after that frame start,
// i.e. 20.07 s into the file, plus at most one observation interval (0.1 s) and the 20 ms bit that completes SF3.
// Atmosphere off in both simulation and receiver: the errors measured are the receiver's own.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "commands.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

// Rows of a CSV file with a header, as numbers, picking named columns.
std::vector<std::vector<double>> columns(const fs::path& path, const std::vector<std::string>& names) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string h; std::getline(ss, h, ',');) header.push_back(h);
  }
  std::vector<int> index;
  for (const auto& n : names) {
    const auto it = std::find(header.begin(), header.end(), n);
    EXPECT_NE(it, header.end()) << n << " not in " << path;
    index.push_back(static_cast<int>(it - header.begin()));
  }
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    std::vector<double> row;
    for (int i : index) row.push_back(i < static_cast<int>(f.size()) && !f[i].empty() ? std::stod(f[i]) : NAN);
    rows.push_back(row);
  }
  return rows;
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return NAN;
  return std::stod(json.substr(at + key.size() + 3));
}

}  // namespace

// Tolerances: 3-D position RMS <= 1.5 m (issue 3; at 45 dB-Hz the DLL's thermal noise is ~0.3 m per pseudorange
// with 1 Hz / 20 ms, times PDOP ~2, smoothed by nothing); velocity RMS <= 0.1 m/s (PLL frequency noise at
// 45 dB-Hz, ~0.02 m/s per range rate, times PDOP); TTFF within [20.07, 20.3] s as derived above.
TEST(ReceiveSynthetic, StaticNominalFixesAtTheEarliestEphemerisAndWithinMetres) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto scenario = dir / "static.toml";
  std::ofstream(scenario) << R"([signal]
sample_rate_hz = 2.6e6
if_hz = 0.0
format = "i8"
duration_s = 26.0
cn0_dbhz = 45.0
seed = 7

[time]
gps_week = 2190
tow_s = 518398.0

[navigation]
constellation = "nominal"
elevation_mask_deg = 5.0

[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
clock_bias_m = 0.0
clock_drift_mps = 0.0

[atmosphere]
ionosphere = false
troposphere = false
)";
  const auto sim = dir / "sim";
  run("simulate", {"--scenario", scenario.string(), "--out", sim.string()});
  const auto out = dir / "rx";
  run("receive", {"--input", (sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.6e6", "--out",
                  out.string(), "--reference-week", "2190", "--ionosphere", "off", "--troposphere", "off"});

  const auto truth = columns(sim / "truth.csv", {"ecef_x_m", "ecef_y_m", "ecef_z_m"});
  ASSERT_FALSE(truth.empty());
  const Eigen::Vector3d r_true(truth[0][0], truth[0][1], truth[0][2]);
  const auto fixes = columns(out / "solution.csv",
                             {"ecef_x_m", "ecef_y_m", "ecef_z_m", "vel_e_mps", "vel_n_mps", "vel_u_mps", "num_sats"});
  ASSERT_GT(fixes.size(), 40u);  // ~6 s of fixes at 10 Hz
  double sum_r2 = 0.0, sum_v2 = 0.0;
  for (const auto& f : fixes) {
    sum_r2 += (Eigen::Vector3d(f[0], f[1], f[2]) - r_true).squaredNorm();
    sum_v2 += Eigen::Vector3d(f[3], f[4], f[5]).squaredNorm();
    EXPECT_GE(f[6], 4.0);
  }
  const double rms_r = std::sqrt(sum_r2 / static_cast<double>(fixes.size()));
  const double rms_v = std::sqrt(sum_v2 / static_cast<double>(fixes.size()));
  const std::string summary = read(out / "summary.json");
  const double ttff = json_number(summary, "ttff_s");
  std::printf("static 45 dB-Hz, 26 s: %zu fixes, 3-D RMS %.3f m, velocity RMS %.4f m/s, TTFF %.3f s\n", fixes.size(),
              rms_r, rms_v, ttff);
  EXPECT_LE(rms_r, 1.5);
  EXPECT_LE(rms_v, 0.1);
  EXPECT_GE(ttff, 20.07);
  EXPECT_LE(ttff, 20.3);
  for (const char* name : {"observations.rnx", "navigation.rnx", "solution.nmea", "solution.kml", "tracking.csv"})
    EXPECT_GT(fs::file_size(out / name), 0u) << name;
  EXPECT_NE(read(out / "navigation.rnx").find("RINEX VERSION / TYPE"), std::string::npos);

  // RTKLIB (Debian rtklib) reads both RINEX files and finds the same place: single point, raw (unsmoothed) code,
  // its own defaults otherwise, so within a few metres (issue 3); skipped when rnx2rtkp is absent.
  if (std::system("command -v rnx2rtkp >/dev/null 2>&1") != 0) return;
  const auto pos = dir / "rtklib.pos";
  const std::string cmd = "rnx2rtkp -p 0 -e -o " + pos.string() + " " + (out / "observations.rnx").string() + " " +
                          (out / "navigation.rnx").string() + " >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(pos);
  std::string line;
  int rows = 0;
  double rtklib_r2 = 0.0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '%') continue;
    std::stringstream ss(line);
    double week = 0, tow = 0, x = 0, y = 0, z = 0;
    ss >> week >> tow >> x >> y >> z;
    rtklib_r2 += (Eigen::Vector3d(x, y, z) - r_true).squaredNorm();
    ++rows;
  }
  ASSERT_GT(rows, 10);
  const double rtklib_rms = std::sqrt(rtklib_r2 / rows);
  std::printf("rnx2rtkp on our RINEX: %d epochs, 3-D RMS %.2f m\n", rows, rtklib_rms);
  EXPECT_LE(rtklib_rms, 10.0);
}

// An undated recording: without --reference-week (or --nav) the receiver only knows the build date's week,
// hundreds of weeks after the signal's 2190. The scenario starts at tow 518388, so the first whole subframe
// a channel decodes is subframe 5 (518394): its time tag has a TOW but not yet a week. Measurements must wait
// for subframe 1 (518400) instead of starting the receiver clock in the wrong week (which once rejected every
// later measurement). Subframes 1-3 end at 518418 + ~70 ms of travel = 30.07 s into the file.
TEST(ReceiveSynthetic, UndatedRecordingTakesTheWeekFromSubframeOne) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto scenario = dir / "undated.toml";
  std::ofstream(scenario) << R"([signal]
sample_rate_hz = 2.6e6
format = "i8"
duration_s = 31.0
cn0_dbhz = 45.0
seed = 11
[time]
gps_week = 2190
tow_s = 518388.0
[navigation]
constellation = "nominal"
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[atmosphere]
ionosphere = false
troposphere = false
)";
  const auto sim = dir / "sim";
  run("simulate", {"--scenario", scenario.string(), "--out", sim.string()});
  const auto out = dir / "rx";
  try {
    run("receive", {"--input", (sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.6e6", "--out",
                    out.string(), "--ionosphere", "off", "--troposphere", "off"});
  } catch (const ultratrack::tools::CommandExit& e) {
    FAIL() << "no fix from an undated recording (exit " << e.code << "): " << e.what();
  }
  const double ttff = json_number(read(out / "summary.json"), "ttff_s");
  EXPECT_GE(ttff, 30.07);
  EXPECT_LE(ttff, 30.3);
  EXPECT_GE(columns(out / "solution.csv", {"ecef_x_m"}).size(), 5u);
}
