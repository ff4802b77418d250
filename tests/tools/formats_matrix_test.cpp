// SPDX-License-Identifier: GPL-3.0-or-later
// Other generators' and front ends' rates and formats work with flags only (issue 3): `ultratrack simulate`
// writes short files at 2.6 / 4 MHz i8, i16 and i2, 16 MHz i16, 12 MHz r8 at IF 3 MHz, 38.192 MHz r8 at
// IF 9.548 MHz and 16.368 MHz r2 at IF 4.092 MHz (the MAX2769's classic setting); `ultratrack receive` must
// acquire and track every simulated satellite with the simulated Doppler and C/N0. A 2-bit file is also
// received to position fixes with a hot start (--nav from the same nominal constellation), checked against
// truth.csv. docs/validation.md has the long-run table (20 s each, fixes) that this keeps alive in CI.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "commands.hpp"
#include "config/scenario_toml.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/rinex_nav.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

// A CSV with a header as rows of named text fields.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) header.push_back(h);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::map<std::string, std::string> row;
    std::stringstream ss(line);
    std::size_t i = 0;
    for (std::string f; std::getline(ss, f, ',') && i < header.size(); ++i) row[header[i]] = f;
    rows.push_back(std::move(row));
  }
  return rows;
}

std::string scenario(double fs_hz, double if_hz, const std::string& format, double duration_s, double tow_s,
                     const std::string& extra = "") {
  std::ostringstream s;
  s << "[signal]\nsample_rate_hz = " << fs_hz << "\nif_hz = " << if_hz << "\nformat = \"" << format
    << "\"\nduration_s = " << duration_s << "\ncn0_dbhz = 45.0\nseed = 3\n"
    << extra << "\n[time]\ngps_week = 2190\ntow_s = " << tow_s
    << "\n[navigation]\nconstellation = \"nominal\"\nelevation_mask_deg = 5.0\n"
       "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
       "[atmosphere]\nionosphere = false\ntroposphere = false\n";
  return s.str();
}

struct Case {
  const char* name;
  double fs_hz, if_hz;
  const char* format;
  std::string scenario_extra;
  std::vector<std::string> flags;
  double cn0_loss_db;  // expected implementation loss of the format (2-bit: 0.55 dB)
};

}  // namespace

// 0.6 s per case: acquisition (10 x 1 ms) then ~0.5 s of tracking. Every satellite in satellites.csv must be
// acquired and still tracked at the end, its Doppler within 15 Hz of the truth at the start (the truth moves
// < 1 Hz/s; the FLL/PLL settle to a few Hz within 0.5 s) and its C/N0 within 3 dB of 45 dB-Hz less the
// format's loss (the 1 ms C/N0 estimator's spread over 0.5 s is ~1 dB).
TEST(FormatsMatrix, EveryRateAndFormatTracksEverySimulatedSatellite) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::vector<Case> cases = {
      {"i8_2p6", 2.6e6, 0.0, "i8", "", {}, 0.0},
      {"i16_2p6", 2.6e6, 0.0, "i16", "", {}, 0.0},
      {"i8_4", 4e6, 0.0, "i8", "", {}, 0.0},
      {"i16_4", 4e6, 0.0, "i16", "", {}, 0.0},
      {"i2_4", 4e6, 0.0, "i2", "", {}, 0.55},
      {"i2_4_sm_msb",
       4e6,
       0.0,
       "i2",
       "two_bit_coding = \"sign-magnitude\"\ntwo_bit_order = \"msb-first\"\n",
       {"--2bit-coding", "sign-magnitude", "--2bit-order", "msb-first"},
       0.55},
      {"i16_16", 16e6, 0.0, "i16", "", {}, 0.0},
      {"r8_12", 12e6, 3e6, "r8", "", {}, 0.0},
      {"r8_38", 38.192e6, 9.548e6, "r8", "", {}, 0.0},
      {"r2_16", 16.368e6, 4.092e6, "r2", "", {}, 0.55},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const auto sim = dir / c.name;
    const auto toml = dir / (std::string(c.name) + ".toml");
    std::ofstream(toml) << scenario(c.fs_hz, c.if_hz, c.format, 0.6, 518400.0, c.scenario_extra);
    run("simulate", {"--scenario", toml.string(), "--out", sim.string()});
    const auto truth = read_csv(sim / "satellites.csv");
    ASSERT_GE(truth.size(), 6u);
    std::string prns;
    for (const auto& t : truth) prns += (prns.empty() ? "" : ",") + t.at("prn");
    std::ostringstream fs_text, if_text;
    fs_text << c.fs_hz;
    if_text << c.if_hz;
    std::vector<std::string> args = {"--input",  (sim / ("antenna0." + std::string(c.format) + ".bin")).string(),
                                     "--format", c.format,
                                     "--fs",     fs_text.str(),
                                     "--if",     if_text.str(),
                                     "--prn",    prns,
                                     "--out",    (sim / "rx").string()};
    args.insert(args.end(), c.flags.begin(), c.flags.end());
    try {
      run("receive", args);
    } catch (const ultratrack::tools::CommandExit& e) {
      EXPECT_EQ(e.code, 3) << e.what();  // tracked, but too short for a fix: outputs complete
    }
    std::map<int, std::map<std::string, std::string>> last;
    for (const auto& row : read_csv(sim / "rx" / "tracking.csv")) last[std::stoi(row.at("prn"))] = row;
    for (const auto& t : truth) {
      const int prn = std::stoi(t.at("prn"));
      SCOPED_TRACE("PRN " + t.at("prn"));
      ASSERT_TRUE(last.count(prn)) << "never tracked";
      const auto& end = last.at(prn);
      EXPECT_GE(std::stod(end.at("time_s")), 0.55);
      EXPECT_NE(end.at("state"), "lost");
      EXPECT_NEAR(std::stod(end.at("doppler_hz")), std::stod(t.at("doppler_hz")), 15.0);
      EXPECT_NEAR(std::stod(end.at("cn0_dbhz")), 45.0 - c.cn0_loss_db, 3.0);
    }
  }
}

// Hot start on a 2-bit file: 4 MHz i2 from 3 s before a subframe start; frame sync takes two preambles
// (3 s and 9 s into the file), so the time of week is known at ~9.1 s; with --nav the fix needs nothing else. 3-D RMS
// against truth after the first fix
// <= 3 m: the 1.5 m for 60 s at 45 dB-Hz, here from the first seconds of tracking (DLL still
// settling, ~7 satellites) with the 0.55 dB 2-bit loss.
TEST(FormatsMatrix, TwoBitFileFixesWithAHotStart) {
  const auto dir = ultratrack::test::scratch_dir();
  const double tow_s = 518403.0;
  const auto toml = dir / "i2.toml";
  std::ofstream(toml) << scenario(4e6, 0.0, "i2", 12.0, tow_s);
  run("simulate", {"--scenario", toml.string(), "--out", (dir / "sim").string()});
  const auto c = ultratrack::signals::nominal_constellation({2190, tow_s});
  ultratrack::signals::RinexNavData nav;
  nav.ephemerides = c.ephemerides;
  nav.klobuchar = c.klobuchar;
  nav.utc = c.utc;
  ultratrack::signals::write_rinex_nav_304(dir / "nominal.rnx", nav);
  run("receive",
      {"--input", (dir / "sim" / "antenna0.i2.bin").string(), "--format", "i2", "--fs", "4e6", "--nav",
       (dir / "nominal.rnx").string(), "--ionosphere", "off", "--troposphere", "off", "--out", (dir / "rx").string()});
  const auto truth = read_csv(dir / "sim" / "truth.csv");
  ASSERT_FALSE(truth.empty());
  const Eigen::Vector3d r_true(std::stod(truth[0].at("ecef_x_m")), std::stod(truth[0].at("ecef_y_m")),
                               std::stod(truth[0].at("ecef_z_m")));
  const auto fixes = read_csv(dir / "rx" / "solution.csv");
  ASSERT_GE(fixes.size(), 25u);  // >= 2.5 s of fixes at 10 Hz
  double sum2 = 0.0;
  for (const auto& f : fixes)
    sum2 += (Eigen::Vector3d(std::stod(f.at("ecef_x_m")), std::stod(f.at("ecef_y_m")), std::stod(f.at("ecef_z_m"))) -
             r_true)
                .squaredNorm();
  const double rms = std::sqrt(sum2 / static_cast<double>(fixes.size()));
  std::printf("i2 4 MHz hot start: %zu fixes, 3-D RMS %.2f m\n", fixes.size(), rms);
  EXPECT_LE(rms, 3.0);
}

// The scenario keys of the 2-bit packing: parsed, echoed by to_toml (so that scenario.toml re-runs the same
// file), and an unknown name is an InputError naming the key.
TEST(FormatsMatrix, ScenarioTwoBitKeysParseAndEcho) {
  using ultratrack::config::parse_scenario;
  const auto s = parse_scenario(
      "[signal]\nformat = \"r2\"\nif_hz = 4.092e6\nsample_rate_hz = 16.368e6\n"
      "two_bit_coding = \"offset-binary\"\ntwo_bit_order = \"msb-first\"\n",
      "/tmp/a/s.toml");
  EXPECT_EQ(s.format, ultratrack::signals::SampleFormat::r2);
  EXPECT_EQ(s.two_bit.coding, ultratrack::signals::TwoBitCoding::offset_binary);
  EXPECT_EQ(s.two_bit.order, ultratrack::signals::BitOrder::msb_first);
  const auto back = parse_scenario(ultratrack::config::to_toml(s), "/tmp/b/echo.toml");
  EXPECT_EQ(back.two_bit.coding, s.two_bit.coding);
  EXPECT_EQ(back.two_bit.order, s.two_bit.order);
  try {
    parse_scenario("[signal]\nformat = \"i2\"\ntwo_bit_coding = \"gray\"\n", "/tmp/a/bad.toml");
    FAIL() << "unknown coding accepted";
  } catch (const ultratrack::signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("signal.two_bit_coding"), std::string::npos) << e.what();
  }
}
