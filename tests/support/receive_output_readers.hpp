// SPDX-License-Identifier: GPL-3.0-or-later
// Readers of the receive outputs that several tools tests check against the truth: the coasting windows of
// tracking.csv, the vector filter's position error (vector_state.csv) against a static truth.csv, and the loss of
// lock indicators of observations.rnx's last epoch.
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "support/test_data.hpp"

namespace ultratrack::test {

// Per PRN, its coasting windows: the times (s) of the first and last rows of each run of "coasting" rows.
inline std::map<int, std::vector<std::pair<double, double>>> coasting_windows(
    const std::filesystem::path& tracking_csv) {
  std::map<int, std::vector<std::pair<double, double>>> windows;
  std::ifstream in(tracking_csv);
  std::string line;
  std::getline(in, line);
  std::map<int, bool> in_window;
  while (std::getline(in, line)) {
    const auto f = split_csv_line(line);
    const int prn = std::stoi(f[0]);
    const double t = std::stod(f[2]);
    const bool coasting = f[9] == "coasting";
    if (coasting && !in_window[prn]) windows[prn].push_back({t, t});
    if (coasting) windows[prn].back().second = t;
    in_window[prn] = coasting;
  }
  return windows;
}

struct PositionErrorRms {
  double rms_3d_m = NAN;
  int epochs = 0;
};

// The vector filter's ECEF position (vector_state.csv) from from_s on against the first row of a static truth.csv.
inline PositionErrorRms static_filter_position_rms(const std::filesystem::path& vector_state_csv,
                                                   const std::filesystem::path& truth_csv, double from_s) {
  std::ifstream truth_in(truth_csv);
  std::string line;
  std::getline(truth_in, line);
  std::getline(truth_in, line);
  const auto t0 = split_csv_line(line);
  const double tx = std::stod(t0[3]), ty = std::stod(t0[4]), tz = std::stod(t0[5]);
  std::ifstream state(vector_state_csv);
  std::getline(state, line);
  double sum2 = 0.0;
  PositionErrorRms r;
  while (std::getline(state, line)) {
    const auto f = split_csv_line(line);
    if (std::stod(f[1]) < from_s) continue;
    const double dx = std::stod(f[4]) - tx, dy = std::stod(f[5]) - ty, dz = std::stod(f[6]) - tz;
    sum2 += dx * dx + dy * dy + dz * dz;
    ++r.epochs;
  }
  if (r.epochs > 0) r.rms_3d_m = std::sqrt(sum2 / r.epochs);
  return r;
}

// observations.rnx (RINEX 3, one row per satellite, C1C then L1C), its last epoch: each satellite's L1C loss of
// lock indicator (the 15th character of the phase's 16-character field; the row's first field is the 3-character
// satellite and C1C's 16).
inline std::vector<char> last_epoch_lli(const std::filesystem::path& rinex) {
  std::ifstream obs(rinex);
  std::vector<char> lli;
  bool header = true;
  for (std::string line; std::getline(obs, line);) {
    if (header)
      header = line.find("END OF HEADER") == std::string::npos;
    else if (line.rfind(">", 0) == 0)
      lli.clear();
    else if (line.size() >= 35)
      lli.push_back(line[19 + 14]);
  }
  return lli;
}

}  // namespace ultratrack::test
