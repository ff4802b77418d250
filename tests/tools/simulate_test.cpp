// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack simulate` end to end: the files it writes, and an independent brute-force acquisition
// (tests/support) of the written samples that must find every satellite of satellites.csv at the stated
// Doppler, code phase and C/N0, with the nominal constellation and with a broadcast ephemeris (the shipped
// brdc3540_0000-0200.14n) at the issue's position.
#include <gtest/gtest.h>

#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "config/scenario_toml.hpp"
#include "signals/input_error.hpp"
#include "signals/sample_reader.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario_models.hpp"
#include "simulation_run.hpp"
#include "support/brute_force_acquisition.hpp"
#include "support/test_data.hpp"

namespace ultratrack::tools {
using namespace ultratrack::config;
namespace {

using namespace ultratrack::sim;

using signals::test_support::BruteForceAcquisition;

struct SatelliteRow {
  int prn;
  double elevation_deg, azimuth_deg, cn0_dbhz, doppler_hz, code_phase_chips;
};

std::vector<std::string> read_lines(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::vector<SatelliteRow> read_satellites(const std::filesystem::path& p) {
  const auto lines = read_lines(p);
  EXPECT_EQ(lines.at(0), "prn,elevation_deg,azimuth_deg,cn0_dbhz,doppler_hz,code_phase_chips");
  std::vector<SatelliteRow> rows;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::string l = lines[i];
    std::replace(l.begin(), l.end(), ',', ' ');
    std::istringstream ss(l);
    SatelliteRow r{};
    ss >> r.prn >> r.elevation_deg >> r.azimuth_deg >> r.cn0_dbhz >> r.doppler_hz >> r.code_phase_chips;
    EXPECT_FALSE(ss.fail()) << lines[i];
    rows.push_back(r);
  }
  return rows;
}

std::vector<std::complex<float>> read_samples(const std::filesystem::path& p, signals::SampleFormat f) {
  signals::SampleReader reader(p, f);
  std::vector<std::complex<float>> x(static_cast<std::size_t>(reader.total_samples()));
  EXPECT_EQ(reader.read(x), x.size());
  return x;
}

double wrap_chips(double d) { return d - 1023.0 * std::round(d / 1023.0); }

// Acquires every listed satellite independently and compares with the row.
void expect_acquired_as_stated(const std::vector<std::complex<float>>& x, double fs,
                               const std::vector<SatelliteRow>& rows) {
  BruteForceAcquisition acq(x, fs);
  for (const auto& row : rows) {
    SCOPED_TRACE("PRN " + std::to_string(row.prn));
    const auto r = acq.acquire(row.prn);
    ASSERT_TRUE(r.found) << "peak ratio " << r.peak_ratio;
    EXPECT_NEAR(r.doppler_hz, row.doppler_hz, 25.0);  // FLL estimate, noise of a few Hz
    EXPECT_NEAR(wrap_chips(r.code_phase_chips - row.code_phase_chips), 0.0, 0.05);
    EXPECT_NEAR(r.cn0_dbhz, row.cn0_dbhz, 1.5);  // floor includes other satellites' cross-correlation
    std::printf("PRN %2d: Doppler %8.1f / %8.1f Hz, code %8.3f / %8.3f chips, C/N0 %.1f / %.1f dB-Hz\n", row.prn,
                r.doppler_hz, row.doppler_hz, r.code_phase_chips, row.code_phase_chips, r.cn0_dbhz, row.cn0_dbhz);
  }
}

TEST(Simulate, WritesAllOutputsAndTheSignalIsAcquiredAsStated) {
  const auto dir = test::scratch_dir();
  const std::string text = R"(
[signal]
sample_rate_hz = 2.048e6
format = "i8"
duration_s = 0.13
cn0_dbhz = 45.0
cn0_dbhz_by_prn = { 1 = 42.0 }
seed = 7
[time]
gps_week = 2190
tow_s = 518400.0
[navigation]
constellation = "nominal"
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
clock_bias_m = 1500.0
clock_drift_mps = 90.0
[atmosphere]
ionosphere = true
troposphere = true
)";
  { std::ofstream(dir / "s.toml") << text; }
  const Scenario s = read_scenario(dir / "s.toml");
  const auto result = run_simulation(s, dir / "out");
  const auto out = dir / "out";
  for (const char* f :
       {"antenna0.i8.bin", "truth.csv", "satellites.csv", "satellite_truth.csv", "scenario.toml", "summary.json"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  for (const auto& e : std::filesystem::directory_iterator(out))
    EXPECT_NE(e.path().extension(), ".part") << "temporary file left: " << e.path();
  EXPECT_EQ(result.samples, 266240);
  EXPECT_EQ(std::filesystem::file_size(out / "antenna0.i8.bin"), 266240u * 2);

  // truth.csv: the header row of the issue, 10 Hz rows, the configured clock.
  const auto truth = read_lines(out / "truth.csv");
  EXPECT_EQ(truth.at(0),
            "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
            "clock_bias_m,clock_drift_mps");
  ASSERT_EQ(truth.size(), 3u);  // t = 0.0 and 0.1 s
  EXPECT_EQ(truth[1].rfind("0.000000000,2190,518400.000000000,", 0), 0u) << truth[1];
  EXPECT_NE(truth[1].find("35.2740160000,137.0137590000,100.0000"), std::string::npos) << truth[1];
  EXPECT_NE(truth[2].find(",1509.00000,90.000000"), std::string::npos) << truth[2];

  // The echo reads back as the same scenario.
  EXPECT_EQ(to_toml(read_scenario(out / "scenario.toml")), to_toml(s));

  // satellites.csv against an independent acquisition of the written samples. The receiver clock drift
  // of 90 m/s shifts every Doppler by -473 Hz, which the stated Doppler must include.
  const auto rows = read_satellites(out / "satellites.csv");
  ASSERT_GE(rows.size(), 5u);
  ASSERT_EQ(rows.size(), result.satellites.size());
  for (const auto& row : rows) EXPECT_GE(row.elevation_deg, 5.0);
  expect_acquired_as_stated(read_samples(out / "antenna0.i8.bin", signals::SampleFormat::i8), 2.048e6, rows);
}

// satellite_truth.csv states the signal at every truth row, not only at the first sample: the rows of 0.1 s later
// against an independent acquisition of the samples from there on (the truth the common loss-of-lock rule,
// pipelines/truth_lock_rule.hpp, judges channels against).
TEST(Simulate, SatelliteTruthStatesTheSignalAtLaterRows) {
  const auto dir = test::scratch_dir();
  Scenario s = parse_scenario(
      "[signal]\nsample_rate_hz = 2.048e6\nduration_s = 0.25\nseed = 3\n[time]\ngps_week = 2190\ntow_s = 518400.0\n"
      "[navigation]\nconstellation = \"nominal\"\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
      "clock_drift_mps = 90.0\n",
      dir / "s.toml");
  const auto result = run_simulation(s, dir / "out");
  const auto lines = read_lines(dir / "out" / "satellite_truth.csv");
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "sample,t_s,prn,cn0_dbhz,doppler_hz,code_phase_chips");
  std::vector<SatelliteRow> at_start, later;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const auto f = test::split_csv_line(lines[i]);
    ASSERT_EQ(f.size(), 6u) << lines[i];
    const SatelliteRow row{std::stoi(f[2]), 0.0, 0.0, std::stod(f[3]), std::stod(f[4]), std::stod(f[5])};
    if (f[0] == "0") at_start.push_back(row);
    if (f[0] == "204800") later.push_back(row);
  }
  // Rows at 0, 0.1 and 0.2 s; the first are satellites.csv's.
  EXPECT_EQ(lines.size(), 1 + 3 * result.satellites.size());
  ASSERT_EQ(at_start.size(), result.satellites.size());
  for (std::size_t i = 0; i < at_start.size(); ++i) {
    EXPECT_EQ(at_start[i].prn, result.satellites[i].prn);
    EXPECT_NEAR(at_start[i].doppler_hz, result.satellites[i].doppler_hz, 1e-4);
    EXPECT_NEAR(at_start[i].code_phase_chips, result.satellites[i].code_phase_chips, 1e-6);
  }
  ASSERT_EQ(later.size(), result.satellites.size());
  const auto x = read_samples(result.sample_files.at(0), signals::SampleFormat::i8);
  expect_acquired_as_stated(std::vector<std::complex<float>>(x.begin() + 204800, x.end()), 2.048e6, later);
}

TEST(Simulate, BroadcastEphemerisScenarioOfTheIssue) {
  const std::filesystem::path brdc = test::shipped_nav_file();
  const auto dir = test::scratch_dir();
  Scenario s = parse_scenario("[signal]\nsample_rate_hz = 2.048e6\nduration_s = 0.13\n", dir / "s.toml");
  s.constellation.clear();
  s.rinex = brdc.string();
  s.gps_week = test::shipped_nav_week;
  s.tow_s = test::shipped_nav_tow_s;
  const auto result = run_simulation(s, dir / "out");
  const auto rows = read_satellites(dir / "out" / "satellites.csv");
  std::set<int> prns;
  for (const auto& r : rows) prns.insert(r.prn);
  // Satellites above 10 deg at 2014-12-20 00:00 GPST from this position (gps-sdr-sim's printout for this file,
  // tests/signals/sky_brdc_test.cpp); all healthy.
  for (int prn : {1, 3, 6, 9, 10, 17, 20, 23, 28}) EXPECT_TRUE(prns.count(prn)) << "PRN " << prn;
  expect_acquired_as_stated(read_samples(result.sample_files.at(0), signals::SampleFormat::i8), 2.048e6, rows);
  // The file's unhealthy PRN 8 is below the horizon here. Seen from under it (its sub-satellite point at this
  // time, 3.0 S 126.3 W, from the same orbits: elevation 90 deg) it is left out, and transmitted with
  // include_unhealthy.
  s.llh_deg_m = {-3.0, -126.3, 0.0};
  s.duration_s = 0.01;
  const auto healthy_only = run_simulation(s, dir / "out_healthy");
  s.include_unhealthy = true;
  const auto with_unhealthy = run_simulation(s, dir / "out_unhealthy");
  bool has8 = false;
  for (const auto& v : healthy_only.satellites) EXPECT_NE(v.prn, 8);
  for (const auto& v : with_unhealthy.satellites) has8 = has8 || v.prn == 8;
  EXPECT_TRUE(has8);
  EXPECT_EQ(with_unhealthy.satellites.size(), healthy_only.satellites.size() + 1);
}

TEST(Simulate, SeveralAntennasGiveOneSynchronousFileEach) {
  const auto dir = test::scratch_dir();
  Scenario s = parse_scenario(
      "[signal]\nsample_rate_hz = 2e6\nduration_s = 0.02\nformat = \"i16\"\n"
      "[receiver]\nantenna_offsets_enu_m = [[0, 0, 0], [1.0, 0, 0], [0, 1.0, 0]]\n",
      dir / "s.toml");
  const auto result = run_simulation(s, dir / "out");
  ASSERT_EQ(result.sample_files.size(), 3u);
  for (int a = 0; a < 3; ++a) {
    const auto p = dir / "out" / ("antenna" + std::to_string(a) + ".i16.bin");
    EXPECT_TRUE(std::filesystem::exists(p));
    EXPECT_EQ(std::filesystem::file_size(p), 40000u * 4);
  }
  // Independent receiver noise per antenna: the streams differ.
  EXPECT_NE(read_samples(result.sample_files[0], signals::SampleFormat::i16),
            read_samples(result.sample_files[1], signals::SampleFormat::i16));
}

TEST(Simulate, TrajectoryFileDrivesTheReceiver) {
  const auto dir = test::scratch_dir();
  {
    std::ofstream f(dir / "motion.csv");
    f << std::setprecision(12) << "t_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps\n";
    for (int i = 0; i <= 3; ++i)
      f << 0.1 * i << "," << -3813409.3992 + 10.0 * 0.1 * i << ",3554350.1028,3662785.2375,10.0,0,0\n";
  }
  Scenario s = parse_scenario(
      "[signal]\nsample_rate_hz = 2e6\nduration_s = 0.3\n[receiver]\ntrajectory = \"motion.csv\"\n", dir / "s.toml");
  run_simulation(s, dir / "out");
  const auto truth = read_lines(dir / "out" / "truth.csv");
  ASSERT_EQ(truth.size(), 4u);  // t = 0, 0.1, 0.2 s (0.3 s is past the last sample)
  EXPECT_NE(truth[3].find("-3813407.3992,3554350.1028,3662785.2375"), std::string::npos) << truth[3];
  // A trajectory shorter than the scenario is an error naming the trajectory file.
  s.duration_s = 0.5;
  try {
    run_simulation(s, dir / "out2");
    ADD_FAILURE() << "no error";
  } catch (const signals::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("motion.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ultratrack::tools

namespace ultratrack::tools {
namespace {

using namespace ultratrack::sim;

// [[cn0_step]]: parsed, echoed, checked, and written to cn0_steps.csv with the sample-exact first sample
// (ceil(start_s fs): 0.0123456 s at 1 MHz is sample 12346); satellites.csv gives the level at sample 0.
TEST(Simulate, Cn0StepsParseEchoAndAreRecorded) {
  const std::string base = R"(
[signal]
sample_rate_hz = 1.0e6
format = "i8"
duration_s = 0.02
cn0_dbhz = 45.0
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
)";
  const std::string steps = R"(
[[cn0_step]]
start_s = 0.0
cn0_dbhz = 50.0
[[cn0_step]]
antenna = 0
start_s = 0.0123456
cn0_dbhz = 25.5
prns = [3, 40]
)";
  const auto error_of = [](const std::string& text) -> std::string {
    try {
      parse_scenario(text, "/data/s.toml");
    } catch (const signals::InputError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(error_of(base + steps).find("cn0_step.prns"), std::string::npos);  // PRN 40
  EXPECT_NE(error_of(base + "[[cn0_step]]\nstart_s = 1.0\n").find("cn0_step.cn0_dbhz"), std::string::npos);
  EXPECT_NE(error_of(base + "[[cn0_step]]\nstart_s = 1.0\ncn0_dbhz = 90.0\n").find("cn0_step.cn0_dbhz"),
            std::string::npos);
  EXPECT_NE(
      error_of(base + "[[cn0_step]]\nantenna = 1\nstart_s = 1.0\ncn0_dbhz = 30.0\n").find("antenna 1 does not exist"),
      std::string::npos);
  EXPECT_NE(
      error_of(base + "[[cn0_step]]\nstart_s = 1.0\ncn0_dbhz = 30.0\nduration_s = 2\n").find("cn0_step.duration_s"),
      std::string::npos);

  const std::string good_steps = R"(
[[cn0_step]]
start_s = 0.0
cn0_dbhz = 50.0
[[cn0_step]]
antenna = 0
start_s = 0.0123456
cn0_dbhz = 25.5
prns = [3, 5]
)";
  Scenario s = parse_scenario(base + good_steps, "/data/s.toml");
  ASSERT_EQ(s.cn0_steps.size(), 2u);
  EXPECT_TRUE(s.cn0_steps[0].prns.empty());
  EXPECT_EQ(s.cn0_steps[1].prns, (std::vector<int>{3, 5}));
  EXPECT_EQ(s.cn0_steps[1].cn0_dbhz, 25.5);
  const Scenario back = parse_scenario(to_toml(s), "/data/s.toml");
  ASSERT_EQ(back.cn0_steps.size(), 2u);
  EXPECT_EQ(back.cn0_steps[1].start_s, 0.0123456);
  EXPECT_EQ(back.cn0_steps[1].prns, (std::vector<int>{3, 5}));

  s.source.clear();
  const auto dir = test::scratch_dir() / "cn0_steps";
  const SimulationResult r = run_simulation(s, dir);
  ASSERT_FALSE(r.satellites.empty());
  for (const auto& v : r.satellites) EXPECT_EQ(v.cn0_dbhz, 50.0) << v.prn;  // the step at 0 s is in force at sample 0
  const auto lines = read_lines(dir / "cn0_steps.csv");
  ASSERT_GE(lines.size(), 4u);
  EXPECT_EQ(lines[0], "antenna,prn,start_s,first_sample,first_sample_s,cn0_dbhz");
  EXPECT_EQ(lines[lines.size() - 2], "0,3,0.0123456,12346,0.012346000,25.5");
  EXPECT_EQ(lines.back(), "0,5,0.0123456,12346,0.012346000,25.5");
  // The all-satellite step: one row per transmitted PRN (the nominal constellation, all healthy).
  EXPECT_EQ(lines.size() - 3u, load_navigation(s).ephemerides.size());
  EXPECT_EQ(lines[1].rfind("0,1,0,0,0.000000000,50", 0), 0u) << lines[1];
}

}  // namespace
}  // namespace ultratrack::tools
