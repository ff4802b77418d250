// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive` through CLI11 as main() runs it: bad input gives an InputError (exit 2) and leaves no
// output files; a --config with an unknown key names the file and the key; real recordings (skipped when
// ../shared/data is absent) are acquired and tracked to their end with C/N0 reported.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "command_exit.hpp"
#include "commands.hpp"
#include "config/receive_config_toml.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using ultratrack::signals::InputError;
using ultratrack::tools::CommandExit;

namespace {

void run(std::vector<std::string> args) { ultratrack::test_support::run_command("receive", std::move(args)); }

int files_in(const fs::path& dir) {
  if (!fs::exists(dir)) return 0;
  return static_cast<int>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Last tracking.csv row time and state per PRN.
struct TrackEnd {
  double last_time_s = 0.0;
  bool ever_lost = false;
  double cn0_dbhz = 0.0;
};
std::map<int, TrackEnd> tracking_ends(const fs::path& csv) {
  std::map<int, TrackEnd> out;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    if (f.size() < 13) continue;
    auto& e = out[std::stoi(f[0])];
    e.last_time_s = std::stod(f[2]);
    e.ever_lost = e.ever_lost || f[9] == "lost";
    if (f[6] != "nan") e.cn0_dbhz = std::stod(f[6]);
  }
  return out;
}

}  // namespace

TEST(ReceiveCommand, BadInputIsAnInputErrorAndLeavesNoOutputs) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string empty = (dir / "empty.i8").string();
  { std::ofstream(empty, std::ios::binary); }
  const std::string truncated = (dir / "truncated.i8").string();
  { std::ofstream(truncated, std::ios::binary) << std::string(2 * 26000 + 1, '\1'); }  // half a final sample
  const std::string noise = (dir / "noise.i8").string();
  {
    std::mt19937 rng(5);
    std::normal_distribution<double> g(0.0, 20.0);
    std::string bytes(2 * 520000, '\0');  // 0.2 s at 2.6 MHz
    for (auto& b : bytes) b = static_cast<char>(std::clamp(std::lround(g(rng)), -127L, 127L));
    std::ofstream(noise, std::ios::binary) << bytes;
  }
  const auto out = dir / "out";
  EXPECT_THROW(run({"--input", empty, "--format", "i8", "--fs", "2.6e6", "--out", out.string()}), InputError);
  EXPECT_THROW(run({"--input", truncated, "--format", "i8", "--fs", "2.6e6", "--out", out.string()}), InputError);
  EXPECT_THROW(run({"--input", noise, "--format", "i9", "--fs", "2.6e6", "--out", out.string()}), InputError);
  EXPECT_THROW(run({"--input", noise, "--format", "i8", "--fs", "2.6MHz", "--out", out.string()}), InputError);
  EXPECT_THROW(
      run({"--input", noise, "--format", "i8", "--fs", "2.6e6", "--troposphere", "maybe", "--out", out.string()}),
      InputError);
  EXPECT_THROW(
      run({"--input", noise, "--format", "i8", "--fs", "2.6e6", "--oscillator", "rubidium", "--out", out.string()}),
      InputError);
  EXPECT_EQ(files_in(out), 0);
  // White noise (or a wrong rate): no satellite in the searched PRNs -> InputError, and no outputs.
  try {
    run({"--input", noise, "--format", "i8", "--fs", "2.6e6", "--prn", "1-8", "--out", out.string()});
    FAIL() << "no error for a file without satellites";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no GPS L1 C/A satellite"), std::string::npos) << e.what();
  }
  EXPECT_EQ(files_in(out), 0);
}

TEST(ReceiveConfig, UnknownKeysAndBadTypesNameTheFileAndKey) {
  const auto dir = ultratrack::test::scratch_dir();
  ultratrack::receiver::ReceiverOptions o;
  const auto good = dir / "good.toml";
  std::ofstream(good) << "[receiver]\nchannels = 8\nprns = [1, 5, 9]\n[acquisition]\nnoncoherent = 4\n"
                         "[tracking]\npll_bw_hz = 12.5\n[pvt]\nelevation_mask_deg = 15.0\ntroposphere = false\n";
  ultratrack::config::apply_receive_config(good, o);
  EXPECT_EQ(o.channels, 8);
  EXPECT_EQ(o.prns, (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(o.acquisition.noncoherent, 4);
  EXPECT_DOUBLE_EQ(o.tracking.pll_bw_hz, 12.5);
  EXPECT_NEAR(o.pvt.elevation_mask_rad, 15.0 * M_PI / 180.0, 1e-12);
  EXPECT_FALSE(o.pvt.troposphere);

  const auto bad_key = dir / "bad_key.toml";
  std::ofstream(bad_key) << "[tracking]\npll_bandwidth = 10.0\n";
  try {
    ultratrack::config::apply_receive_config(bad_key, o);
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad_key.toml"), std::string::npos) << what;
    EXPECT_NE(what.find("tracking.pll_bandwidth"), std::string::npos) << what;
  }
  const auto bad_type = dir / "bad_type.toml";
  std::ofstream(bad_type) << "[receiver]\nchannels = \"twelve\"\n";
  EXPECT_THROW(ultratrack::config::apply_receive_config(bad_type, o), InputError);
  const auto bad_section = dir / "bad_section.toml";
  std::ofstream(bad_section) << "[receivr]\nchannels = 4\n";
  EXPECT_THROW(ultratrack::config::apply_receive_config(bad_section, o), InputError);
  // The front end's oscillator for the tracking loops: a named class or explicit coefficients; "ideal" (or the
  // older "none") a perfect clock.
  const auto ideal = dir / "ideal.toml";
  std::ofstream(ideal) << "[tracking]\noscillator = \"ideal\"\n";
  ultratrack::config::apply_receive_config(ideal, o);
  EXPECT_EQ(o.tracking.oscillator_h0, 0.0);
  EXPECT_EQ(o.tracking.oscillator_h_minus2, 0.0);
  const auto tcxo = dir / "tcxo.toml";
  std::ofstream(tcxo) << "[tracking]\noscillator = \"tcxo\"\n";
  ultratrack::config::apply_receive_config(tcxo, o);
  EXPECT_NEAR(o.tracking.oscillator_h0, 9.355e-23, 0.001e-23);
  EXPECT_DOUBLE_EQ(o.tracking.oscillator_h_minus2, 2e-20);
  const auto bad_oscillator = dir / "bad_oscillator.toml";
  std::ofstream(bad_oscillator) << "[tracking]\noscillator = \"rubidium\"\n";
  try {
    ultratrack::config::apply_receive_config(bad_oscillator, o);
    FAIL() << "unknown oscillator accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"tcxo\", \"ocxo\" or \"ideal\""), std::string::npos) << e.what();
  }
}

namespace {

// A short real recording: no fix is possible (exit 3 as CommandExit), but every listed satellite must be
// acquired, keep its channel to the end of the file (a tracking.csv row in the last 40 ms, never "lost") and
// report a C/N0 between 30 and 55 dB-Hz (front-end recordings of open sky: 35-50 dB-Hz).
// The C/N0 window (default 0.2 s) is set to 40 ms so that 0.1 s files report one.
void expect_tracked(const fs::path& file, std::vector<std::string> args, const std::vector<int>& prns,
                    double length_s) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto out = dir / "out";
  std::ofstream(dir / "short.toml") << "[tracking]\ncn0_window_s = 0.04\n";
  args.insert(args.end(), {"--input", file.string(), "--out", out.string(), "--config", (dir / "short.toml").string()});
  try {
    run(args);
    FAIL() << "a fix from a short file?";
  } catch (const CommandExit& e) {
    EXPECT_EQ(e.code, 3);
  }
  const std::string summary = read(out / "summary.json");
  EXPECT_NE(summary.find("\"fix\": false"), std::string::npos);
  const auto ends = tracking_ends(out / "tracking.csv");
  for (int prn : prns) {
    ASSERT_EQ(ends.count(prn), 1u) << "PRN " << prn << " not tracked\n" << summary;
    const TrackEnd& e = ends.at(prn);
    EXPECT_GT(e.last_time_s, length_s - 0.04) << prn;
    EXPECT_FALSE(e.ever_lost) << prn;
    EXPECT_GT(e.cn0_dbhz, 30.0) << prn;
    EXPECT_LT(e.cn0_dbhz, 55.0) << prn;
  }
  for (const char* name : {"solution.csv", "observations.rnx", "navigation.rnx", "solution.nmea", "solution.kml"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
}

}  // namespace

TEST(ReceiveCommand, TracksPocketSdr4MHzIq) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  expect_tracked(path, {"--format", "i8", "--fs", "4e6", "--q-negate", "--prn", "1-32"}, {16, 26, 29, 31, 32}, 0.5);
}

TEST(ReceiveCommand, TracksPocketSdr12MHzRealIf) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_12MHz_real_if3MHz.bin");
  expect_tracked(path, {"--format", "r8", "--fs", "12e6", "--if", "3e6"}, {2, 5, 11, 13, 15, 18, 20, 30}, 0.1);
}

TEST(ReceiveCommand, TracksUgsdr38MHzRealIf) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "ugsdr_L1_38p192MHz_real_if9p55MHz.bin");
  expect_tracked(path, {"--format", "r8", "--fs", "38.192e6", "--if", "9.548e6"}, {3, 6, 9, 15, 18, 21, 22, 26, 29},
                 0.1);
}

TEST(ReceiveCommand, WrongRateFindsNoSatellite) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "pocketsdr_L1_4MHz_iq_2bit.bin");
  const auto out = ultratrack::test::scratch_dir() / "out";
  EXPECT_THROW(run({"--input", path.string(), "--format", "i8", "--fs", "2.6e6", "--q-negate", "--prn",
                    "16,26,29,31,32", "--out", out.string()}),
               InputError);
  EXPECT_EQ(files_in(out), 0);
}
