// SPDX-License-Identifier: GPL-3.0-or-later
// Scenario files: the issue's keys parse to the stated values; unknown keys, wrong types and conflicting
// keys are InputErrors naming the file, the key and the line; the echo (to_toml) reads back the same.
#include <gtest/gtest.h>

#include <numbers>
#include <string>

#include "config/scenario_toml.hpp"
#include "signals/input_error.hpp"
#include "sim/scenario_models.hpp"

namespace ultratrack::tools {
using namespace ultratrack::config;
namespace {

using namespace ultratrack::sim;

const char* kIssueExample = R"(
[signal]
sample_rate_hz = 2.6e6
if_hz = 0.0
format = "i8"
duration_s = 60.0
cn0_dbhz = 45.0
seed = 1
[time]
gps_week = 2190
tow_s = 518400.0
[navigation]
rinex = "brdc0010.22n"          # relative to the scenario file
[receiver]
llh_deg_m = [35.274016, 137.013759, 100.0]
[atmosphere]
ionosphere = true
troposphere = false
)";

std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "/data/s.toml");
  } catch (const signals::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Scenario, ParsesTheIssueExample) {
  const Scenario s = parse_scenario(kIssueExample, "/data/run/s.toml");
  EXPECT_EQ(s.sample_rate_hz, 2.6e6);
  EXPECT_EQ(s.format, signals::SampleFormat::i8);
  EXPECT_EQ(s.duration_s, 60.0);
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.gps_week, 2190);
  EXPECT_EQ(s.tow_s, 518400.0);
  EXPECT_EQ(s.rinex, "brdc0010.22n");
  EXPECT_TRUE(s.constellation.empty());
  EXPECT_EQ(s.llh_deg_m[0], 35.274016);
  EXPECT_TRUE(s.ionosphere);
  EXPECT_FALSE(s.troposphere);
  EXPECT_EQ(resolve_path(s, s.rinex), std::filesystem::path("/data/run/brdc0010.22n"));
  EXPECT_EQ(resolve_path(s, "/abs/x.csv"), std::filesystem::path("/abs/x.csv"));
}

TEST(Scenario, DefaultsWithoutNavigationUseTheNominalConstellation) {
  const Scenario s = parse_scenario("[signal]\nduration_s = 2\n", "s.toml");
  EXPECT_EQ(s.constellation, "nominal");
  EXPECT_EQ(s.duration_s, 2.0);  // integers are accepted for numbers
  EXPECT_EQ(s.sample_rate_hz, 2.6e6);
  EXPECT_EQ(s.cn0_dbhz, 45.0);
}

TEST(Scenario, UnknownKeysWrongTypesAndConflictsNameFileKeyAndLine) {
  auto e = error_of("[signal]\nsample_rate = 4e6\n");
  EXPECT_NE(e.find("/data/s.toml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("signal.sample_rate"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  e = error_of("[signal]\nformat = 8\n");
  EXPECT_NE(e.find("signal.format"), std::string::npos) << e;
  EXPECT_NE(e.find("expected a string"), std::string::npos) << e;
  e = error_of("[signal]\nformat = \"u4\"\n");
  EXPECT_NE(e.find("unknown sample format"), std::string::npos) << e;
  e = error_of("[time]\ngps_week = 2190.5\n");
  EXPECT_NE(e.find("time.gps_week"), std::string::npos) << e;
  e = error_of("[receiver]\nllh_deg_m = [1, 2]\n");
  EXPECT_NE(e.find("receiver.llh_deg_m"), std::string::npos) << e;
  e = error_of("[recever]\nx = 1\n");
  EXPECT_NE(e.find("unknown section"), std::string::npos) << e;
  e = error_of("[navigation]\nrinex = \"a.n\"\nconstellation = \"nominal\"\n");
  EXPECT_NE(e.find("not both"), std::string::npos) << e;
  e = error_of("[receiver]\nllh_deg_m = [1, 2, 3]\ntrajectory = \"m.csv\"\n");
  EXPECT_NE(e.find("not both"), std::string::npos) << e;
  e = error_of("[signal]\nformat = \"r8\"\n");
  EXPECT_NE(e.find("needs an IF"), std::string::npos) << e;
  e = error_of("[signal]\nduration_s = -1\n");
  EXPECT_NE(e.find("signal.duration_s"), std::string::npos) << e;
  e = error_of("[signal]\ncn0_dbhz_by_prn = { 40 = 45.0 }\n");
  EXPECT_NE(e.find("PRN must be 1..32"), std::string::npos) << e;
  e = error_of("[signal\nx = 1\n");
  EXPECT_NE(e.find("/data/s.toml:1"), std::string::npos) << e;  // a syntax error, with its line
}

// A named oscillator sets the clock's two random walks: a 26 MHz TCXO at -135 dBc/Hz (1 kHz) has h0 =
// 2 (1e3)^2 10^-13.5 / (26e6)^2 = 9.355e-23, so c sqrt(h0 / 2) = 0.002050 m/sqrt(s); Brown & Hwang's h-2 2e-20
// gives c sqrt(2 pi^2 h-2) = 0.1884 m/s/sqrt(s).
TEST(Scenario, OscillatorSetsTheClockRandomWalks) {
  const Scenario s = parse_scenario("[receiver]\noscillator = \"tcxo\"\n", "/data/s.toml");
  EXPECT_NEAR(s.clock_bias_noise_m_per_sqrt_s, 0.002050, 0.000001);
  EXPECT_NEAR(s.clock_drift_noise_mps_per_sqrt_s, 0.18837, 0.00001);
  // "ideal": no noise at all (a campaign axis beside tcxo and ocxo).
  const Scenario ideal = parse_scenario("[receiver]\noscillator = \"ideal\"\n", "/data/s.toml");
  EXPECT_EQ(ideal.clock_bias_noise_m_per_sqrt_s, 0.0);
  EXPECT_EQ(ideal.clock_drift_noise_mps_per_sqrt_s, 0.0);
  auto e = error_of("[receiver]\noscillator = \"rubidium\"\n");
  EXPECT_NE(e.find("receiver.oscillator"), std::string::npos) << e;
  EXPECT_NE(e.find("ideal, tcxo, ocxo"), std::string::npos) << e;
  e = error_of("[receiver]\noscillator = \"ocxo\"\nclock_bias_noise_m_per_sqrt_s = 0.1\n");
  EXPECT_NE(e.find("not both"), std::string::npos) << e;
}

// Other generators' conventions parse, echo only when set, and reject values outside their meaning.
TEST(Scenario, OtherGeneratorConventionsParseAndEcho) {
  const Scenario s = parse_scenario(
      "[signal]\nparameter_update_s = 0.1\n[navigation]\nfield_rounding = \"toward_zero\"\npages = \"random\"\n",
      "/data/s.toml");
  EXPECT_DOUBLE_EQ(s.parameter_update_s, 0.1);
  EXPECT_EQ(s.nav_field_rounding, signals::FieldRounding::kTowardZero);
  EXPECT_TRUE(s.nav_random_pages);
  const Scenario back = parse_scenario(to_toml(s), "/data/s.toml");
  EXPECT_DOUBLE_EQ(back.parameter_update_s, 0.1);
  EXPECT_EQ(back.nav_field_rounding, signals::FieldRounding::kTowardZero);
  EXPECT_TRUE(back.nav_random_pages);
  const std::string plain = to_toml(parse_scenario("[signal]\nduration_s = 2\n", "/data/s.toml"));
  EXPECT_EQ(plain.find("parameter_update_s"), std::string::npos);
  EXPECT_EQ(plain.find("field_rounding"), std::string::npos);
  auto e = error_of("[signal]\nparameter_update_s = 0.0005\n");
  EXPECT_NE(e.find("signal.parameter_update_s"), std::string::npos) << e;
  e = error_of("[signal]\nparameter_update_s = 0.0015\n");
  EXPECT_NE(e.find("whole number of milliseconds"), std::string::npos) << e;
  e = error_of("[navigation]\nfield_rounding = \"up\"\n");
  EXPECT_NE(e.find("navigation.field_rounding"), std::string::npos) << e;
  e = error_of("[navigation]\npages = \"none\"\n");
  EXPECT_NE(e.find("navigation.pages"), std::string::npos) << e;
}

TEST(Scenario, EchoReadsBackTheSameScenario) {
  Scenario s = parse_scenario(R"(
[signal]
format = "r16"
if_hz = 1.5e6
sample_rate_hz = 5e6
cn0_dbhz_by_prn = { 5 = 40.5, 12 = 38.0 }
seed = 77
[receiver]
llh_deg_m = [-33.9, 151.2, 42.25]
antenna_offsets_enu_m = [[0, 0, 0], [1.5, 0, 0.1]]
clock_drift_mps = 12.5
[atmosphere]
troposphere = true
)",
                              "/tmp/a/s.toml");
  const std::string text = to_toml(s);
  const Scenario back = parse_scenario(text, "/tmp/b/echo.toml");
  EXPECT_EQ(to_toml(back), text);
  EXPECT_EQ(back.format, signals::SampleFormat::r16);
  EXPECT_EQ(back.if_hz, 1.5e6);
  EXPECT_EQ(back.cn0_dbhz_by_prn, s.cn0_dbhz_by_prn);
  EXPECT_EQ(back.seed, 77u);
  EXPECT_EQ(back.llh_deg_m, s.llh_deg_m);
  EXPECT_EQ(back.antenna_offsets_enu_m, s.antenna_offsets_enu_m);
  EXPECT_EQ(back.clock_drift_mps, 12.5);
  EXPECT_TRUE(back.troposphere);
  EXPECT_EQ(back.constellation, "nominal");
}

}  // namespace
}  // namespace ultratrack::tools

namespace ultratrack::tools {
namespace {

using namespace ultratrack::sim;

const char* kAttitudeScenario = R"(
[signal]
duration_s = 30.0
[receiver]
llh_deg_m = [35.0, 137.0, 100.0]
attitude_deg = [2.0, -3.0, 35.0]
[trajectory]
profile = "static"
duration_s = 30.0
[[antenna]]
lever_arm_body_m = [0.0, 0.0, 0.0]
phase_noise_m = 0.003
[[antenna]]
lever_arm_body_m = [1.0, 0.0, 0.0]
line_bias_cycles = 0.23
[[cycle_slip]]
antenna = 1
prn = 15
time_s = 20.0
cycles = 3.0
[[blockage]]
antenna = 1
start_s = 25.0
duration_s = 5.0
)";

TEST(Scenario, AntennaImpairmentsSlipsAndBlockagesParseAndEcho) {
  const Scenario s = parse_scenario(kAttitudeScenario, "/data/a.toml");
  ASSERT_EQ(s.antenna_impairments.size(), 2u);
  EXPECT_EQ(s.antenna_impairments[0].phase_noise_m, 0.003);
  EXPECT_EQ(s.antenna_impairments[1].line_bias_cycles, 0.23);
  ASSERT_EQ(s.cycle_slips.size(), 1u);
  EXPECT_EQ(s.cycle_slips[0].prn, 15);
  EXPECT_EQ(s.cycle_slips[0].cycles, 3.0);
  EXPECT_EQ(s.cycle_slips[0].fade_s, 0.1);  // the default
  ASSERT_EQ(s.blockages.size(), 1u);
  EXPECT_EQ(s.blockages[0].duration_s, 5.0);
  const Scenario back = parse_scenario(to_toml(s), "/data/a.toml");
  ASSERT_EQ(back.cycle_slips.size(), 1u);
  EXPECT_EQ(back.cycle_slips[0].time_s, 20.0);
  EXPECT_EQ(back.blockages[0].start_s, 25.0);
  EXPECT_EQ(back.antenna_impairments[1].line_bias_cycles, 0.23);
}

TEST(Scenario, EventsOnMissingAntennasOrWithUnknownKeysAreErrors) {
  std::string text = kAttitudeScenario;
  EXPECT_NE(
      error_of(text + "[[blockage]]\nantenna = 2\nstart_s = 1.0\nduration_s = 1.0\n").find("antenna 2 does not exist"),
      std::string::npos);
  EXPECT_NE(error_of(text + "[[cycle_slip]]\nantenna = 0\nprn = 3\ntime_s = 1.0\n").find("cycle_slip.cycles"),
            std::string::npos);
  EXPECT_NE(
      error_of(text + "[[blockage]]\nantenna = 0\nstart_s = 1.0\nduration_s = 1.0\nprn = 4\n").find("blockage.prn"),
      std::string::npos);
}

// [[vibration]]: tones parse (degrees to radians), echo back, reach the trajectory spec, and bad ones are errors.
TEST(Scenario, VibrationTonesParseEchoAndAreChecked) {
  const std::string base =
      "[signal]\nduration_s = 30.0\n[receiver]\nllh_deg_m = [35.0, 137.0, 100.0]\n"
      "[trajectory]\nprofile = \"static\"\nduration_s = 30.0\n";
  const std::string tones =
      "[[vibration]]\nfrequency_hz = 12.0\naccel_amplitude_mps2 = [0.5, 0.0, 1.5]\nangle_amplitude_deg = [0.1, 0.0, "
      "0.0]\n[[vibration]]\nfrequency_hz = 30.0\nangle_amplitude_deg = [0.0, 0.02, 0.0]\nphase_deg = 90.0\n";
  const Scenario s = parse_scenario(base + tones, "/data/v.toml");
  ASSERT_EQ(s.vibrations.size(), 2u);
  EXPECT_DOUBLE_EQ(s.vibrations[0].frequency_hz, 12.0);
  EXPECT_DOUBLE_EQ(s.vibrations[0].accel_amplitude_n_mps2[2], 1.5);
  EXPECT_NEAR(s.vibrations[0].angle_amplitude_rad[0], 0.1 * std::numbers::pi / 180.0, 1e-15);
  EXPECT_NEAR(s.vibrations[1].phase_rad, std::numbers::pi / 2.0, 1e-15);
  const Scenario back = parse_scenario(to_toml(s), "/data/v.toml");
  ASSERT_EQ(back.vibrations.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(back.vibrations[i].frequency_hz, s.vibrations[i].frequency_hz);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(back.vibrations[i].accel_amplitude_n_mps2[k], s.vibrations[i].accel_amplitude_n_mps2[k], 1e-15);
      EXPECT_NEAR(back.vibrations[i].angle_amplitude_rad[k], s.vibrations[i].angle_amplitude_rad[k], 1e-15);
    }
    EXPECT_NEAR(back.vibrations[i].phase_rad, s.vibrations[i].phase_rad, 1e-15);
  }
  EXPECT_EQ(sim::trajectory_spec(s).vibrations.size(), 2u);
  EXPECT_EQ(to_toml(parse_scenario(base, "/data/v.toml")).find("vibration"), std::string::npos);
  auto e = error_of(base + "[[vibration]]\naccel_amplitude_mps2 = [0.0, 0.0, 1.0]\n");
  EXPECT_NE(e.find("vibration.frequency_hz"), std::string::npos) << e;
  e = error_of(base + "[[vibration]]\nfrequency_hz = 0.0\naccel_amplitude_mps2 = [0.0, 0.0, 1.0]\n");
  EXPECT_NE(e.find("(0, 500] Hz"), std::string::npos) << e;
  e = error_of(base + "[[vibration]]\nfrequency_hz = 10.0\n");
  EXPECT_NE(e.find("needs accel_amplitude_mps2 or angle_amplitude_deg"), std::string::npos) << e;
  e = error_of(base + "[[vibration]]\nfrequency_hz = 10.0\nangle_amplitude_deg = [20.0, 0.0, 0.0]\n");
  EXPECT_NE(e.find("+-10 deg"), std::string::npos) << e;
  e = error_of(base + "[[vibration]]\nfrequency_hz = 10.0\namplitude = 1.0\n");
  EXPECT_NE(e.find("vibration.amplitude"), std::string::npos) << e;
  e = error_of("[signal]\nduration_s = 30.0\n[[vibration]]\nfrequency_hz = 10.0\naccel_amplitude_mps2 = [0, 0, 1.0]\n");
  EXPECT_NE(e.find("needs a [trajectory]"), std::string::npos) << e;
}

}  // namespace
}  // namespace ultratrack::tools
