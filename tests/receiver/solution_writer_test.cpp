// SPDX-License-Identifier: GPL-3.0-or-later
// Output writers: NMEA checksums against published sentences, complete-or-nothing files, RINEX layout.
#include "receiver/solution_writer.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "receiver/rinex_obs_writer.hpp"
#include "support/test_data.hpp"

using namespace ultratrack;

namespace {
std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

receiver::PvtSolution sample_fix() {
  receiver::PvtSolution f;
  f.valid = true;
  f.time = {2190, 518418.5};
  f.lat_rad = 35.5 * M_PI / 180.0;
  f.lon_rad = -137.25 * M_PI / 180.0;
  f.height_m = 100.0;
  f.used_prns = {5, 12, 25};
  f.satellites = {{5, 0.5, 1.0, 0.1, 45.0}, {12, 0.6, 2.0, 0.2, 44.0}, {25, 0.7, 3.0, -0.1, 43.0}};
  f.pdop = 2.0;
  f.hdop = 1.2;
  f.vdop = 1.6;
  return f;
}
}  // namespace

TEST(Nmea, ChecksumMatchesPublishedExamples) {
  // Widely published reference sentences with their checksums.
  EXPECT_EQ(receiver::nmea_sentence("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"),
            "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47");
  EXPECT_EQ(receiver::nmea_sentence("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"),
            "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A");
}

TEST(Nmea, WritesUtcTimeAndHemispheres) {
  const auto dir = test::scratch_dir();
  receiver::NmeaWriter w(dir / "fix.nmea", 18);
  w.write(sample_fix());
  w.finish();
  const std::string text = read_all(dir / "fix.nmea");
  // GPST 2022-01-01 00:00:18.5 is UTC 00:00:00.5; 35.5 N = 3530.000000, 137.25 W = 13715.000000.
  EXPECT_NE(text.find("$GPGGA,000000.50,3530.000000,N,13715.000000,W,1,03,1.2,100.000,M"), std::string::npos) << text;
  EXPECT_NE(text.find(",010122,"), std::string::npos);
  EXPECT_NE(text.find("$GPGSA,A,3,05,12,25,"), std::string::npos);
  EXPECT_NE(text.find("$GPGSV,1,1,03,05,29,057,45"), std::string::npos) << text;
}

TEST(AtomicOutput, UnfinishedWriterLeavesNoFile) {
  const auto dir = test::scratch_dir();
  {
    receiver::SolutionCsvWriter w(dir / "solution.csv");
    w.write(sample_fix());
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "solution.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "solution.csv.partial"));
  {
    receiver::SolutionCsvWriter w(dir / "solution.csv");
    w.write(sample_fix());
    w.finish();
  }
  const std::string text = read_all(dir / "solution.csv");
  EXPECT_EQ(text.rfind(receiver::kSolutionCsvHeader, 0), 0u);
  EXPECT_NE(text.find("2190,518418.5000,35.500000000,-137.250000000,100.0000"), std::string::npos) << text;
}

TEST(RinexObs, HeaderLabelsInColumns61To80AndEpochLayout) {
  const auto dir = test::scratch_dir();
  receiver::RinexObsWriter w(dir / "obs.rnx", {});
  receiver::ObservationEpoch e;
  e.receive_time = {2190, 518430.0};
  e.observations.push_back({7, 21000123.456, 110000000.25, -1234.5, 44.0, 3.0, false, true});
  e.observations.push_back({12, 23000123.456, 120000000.75, 2345.5, 38.0, 3.0, true, false});
  w.write(e);
  w.finish(Eigen::Vector3d(-3947762.0, 3364399.0, 3699428.0));
  const std::string text = read_all(dir / "obs.rnx");
  std::istringstream lines(text);
  std::string line;
  bool in_header = true;
  int epoch_lines = 0;
  while (std::getline(lines, line)) {
    if (in_header) {
      ASSERT_LE(line.size(), 80u);
      ASSERT_GE(line.size(), 61u) << line;
      if (line.substr(60).rfind("END OF HEADER", 0) == 0) in_header = false;
      continue;
    }
    if (line[0] == '>') {
      ++epoch_lines;
      EXPECT_EQ(line, "> 2022 01 01 00 00 30.0000000  0  2");
    }
  }
  EXPECT_FALSE(in_header);
  EXPECT_EQ(epoch_lines, 1);
  EXPECT_NE(text.find("     3.04           OBSERVATION DATA    G (GPS)             RINEX VERSION / TYPE"),
            std::string::npos);
  // PRN 12: lost lock (LLI bit 0) and half cycle unresolved (bit 1) -> LLI 3; SSI 6 for 38 dB-Hz.
  EXPECT_NE(text.find("G12  23000123.456 6 120000000.75036"), std::string::npos) << text;
  EXPECT_NE(text.find("  2022     1     1     0     0   30.0000000     GPS         TIME OF FIRST OBS"),
            std::string::npos);
}
