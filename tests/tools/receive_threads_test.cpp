// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive --threads N` writes the same outputs byte for byte for every N: solution, RINEX, NMEA,
// KML, tracking.csv and summary.json, apart from the wall-clock fields (summary.json's wall_time_s and
// realtime_factor, the RINEX files' creation date). The scenario (10 satellites, 2.6 MHz i8, 21 s from 2 s
// before a frame start) reaches a first fix and runs blind re-acquisitions in the background every 2 s.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

// The file without the lines that carry wall-clock time.
std::string without_wall_clock(const fs::path& p) {
  std::ifstream in(p);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.find("\"wall_time_s\"") != std::string::npos || line.find("\"realtime_factor\"") != std::string::npos ||
        line.find("PGM / RUN BY / DATE") != std::string::npos)
      continue;
    out += line + "\n";
  }
  return out;
}

}  // namespace

TEST(ReceiveThreads, OutputsAreByteForByteTheSameWithOneTwoAndThreeThreads) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto scenario = dir / "threads.toml";
  std::ofstream(scenario) << R"([signal]
sample_rate_hz = 2.6e6
format = "i8"
duration_s = 21.0
cn0_dbhz = 45.0
seed = 5
[time]
gps_week = 2190
tow_s = 518398.0
[navigation]
constellation = "nominal"
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
)";
  const auto config = dir / "receive.toml";
  std::ofstream(config) << "[receiver]\nreacquisition_interval_s = 2.0\nblind_prns_per_snapshot = 5\n";
  const auto sim = dir / "sim";
  run("simulate", {"--scenario", scenario.string(), "--out", sim.string()});
  const std::vector<std::string> files = {"solution.csv",  "tracking.csv", "observations.rnx", "navigation.rnx",
                                          "solution.nmea", "solution.kml", "summary.json"};
  std::vector<std::string> reference;
  for (int threads = 1; threads <= 3; ++threads) {
    const auto out = dir / ("rx" + std::to_string(threads));
    run("receive",
        {"--input", (sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string(),
         "--reference-week", "2190", "--config", config.string(), "--threads", std::to_string(threads)});
    ASSERT_GT(fs::file_size(out / "solution.csv"), 1000u) << "no fixes";
    for (std::size_t i = 0; i < files.size(); ++i) {
      const std::string text = without_wall_clock(out / files[i]);
      if (threads == 1) {
        reference.push_back(text);
        EXPECT_FALSE(text.empty()) << files[i];
      } else {
        EXPECT_TRUE(text == reference[i]) << files[i] << " differs with " << threads << " threads";
      }
    }
  }
}
