// Simulation scenarios: the TOML file that `ultratrack simulate` runs (and other tools write to drive it),
// parsed strictly with toml++: every key known and of the right type, or an InputError naming the file,
// the line and the key. Units as in the key names; relative paths resolve against the scenario's folder.
//
//   [signal]      sample_rate_hz = 2.6e6  if_hz = 0.0  format = "i8"  duration_s = 60.0  cn0_dbhz = 45.0
//                 seed = 1  cn0_dbhz_by_prn = { 5 = 40.0 }  nav_data = true  noise = true
//   [time]        gps_week = 2190  tow_s = 518400.0            (true GPS time of the first sample)
//   [navigation]  rinex = "brdc0010.22n"  or  constellation = "nominal"
//                 elevation_mask_deg = 5.0  include_unhealthy = false
//   [receiver]    llh_deg_m = [35.274016, 137.013759, 100.0]  or  trajectory = "motion.csv"
//                 antenna_offsets_enu_m = [[0, 0, 0], [1.0, 0, 0]]   (static receiver: one file per antenna)
//                 clock_bias_m = 0.0  clock_drift_mps = 0.0
//                 clock_bias_noise_m_per_sqrt_s = 0.0  clock_drift_noise_mps_per_sqrt_s = 0.0
//   [atmosphere]  ionosphere = true  troposphere = false
//   [output]      truth_rate_hz = 10.0
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "signals/sample_format.hpp"

namespace ultratrack::tools {

struct Scenario {
  std::filesystem::path source;  // the scenario file ("" for a built-in one); relative paths resolve against it

  // [signal]
  double sample_rate_hz = 2.6e6;
  double if_hz = 0.0;
  signals::SampleFormat format = signals::SampleFormat::i8;
  double duration_s = 60.0;
  double cn0_dbhz = 45.0;
  std::uint64_t seed = 1;
  std::map<int, double> cn0_dbhz_by_prn;
  bool nav_data = true;
  bool noise = true;

  // [time]
  int gps_week = 2190;
  double tow_s = 518400.0;

  // [navigation]: exactly one of rinex / constellation ("nominal" when neither is given)
  std::string rinex;
  std::string constellation = "nominal";
  double elevation_mask_deg = 5.0;
  bool include_unhealthy = false;

  // [receiver]: a static position (with optional extra antennas) or a trajectory file
  std::array<double, 3> llh_deg_m = {35.274016, 137.013759, 100.0};
  std::string trajectory;
  std::vector<std::array<double, 3>> antenna_offsets_enu_m = {{0.0, 0.0, 0.0}};
  double clock_bias_m = 0.0;
  double clock_drift_mps = 0.0;
  double clock_bias_noise_m_per_sqrt_s = 0.0;
  double clock_drift_noise_mps_per_sqrt_s = 0.0;

  // [atmosphere]
  bool ionosphere = true;
  bool troposphere = false;

  // [output]
  double truth_rate_hz = 10.0;
};

// Parses scenario text; `source` names it in errors and anchors relative paths. Throws InputError.
Scenario parse_scenario(std::string_view text, const std::filesystem::path& source);
// Reads and parses a scenario file. Throws InputError (missing file, syntax, unknown key, wrong type, range).
Scenario read_scenario(const std::filesystem::path& path);

// The scenario as TOML with every key written (defaults filled in, paths made absolute): reading it back
// gives the same scenario.
std::string to_toml(const Scenario& scenario);

// A path from the scenario, resolved against the scenario file's folder when relative.
std::filesystem::path resolve_path(const Scenario& scenario, const std::string& path);

}  // namespace ultratrack::tools
