// SPDX-License-Identifier: GPL-3.0-or-later
// Acquisition skips satellites below the horizon: a receiver with a rough position (here the simulator's
// truth) and the broadcast ephemerides of the whole constellation searches, once its clock is set, only the
// PRNs the orbits put above the horizon, plus at most one hidden PRN per hidden_prn_check_interval_s. Truth:
// the elevations of the 2014-12-20 broadcast orbits seen from Nagoya (the shipped brdc3540 file), from the
// ephemeris alone; the simulator transmits only the satellites above its 9 degree mask.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <complex>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "receiver/receiver_engine.hpp"
#include "run_command.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/satellite_state.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace ultratrack;

namespace {

struct SearchLog : receiver::ReceiverObserver {
  std::vector<std::pair<std::int64_t, std::vector<int>>> searches;  // snapshot first sample, PRNs searched
  std::int64_t first_epoch = -1;
  void on_acquisition(std::int64_t first, const std::vector<receiver::AcquisitionResult>& results) override {
    std::vector<int> prns;
    for (const auto& r : results) prns.push_back(r.prn);
    searches.emplace_back(first, prns);
  }
  void on_observations(const receiver::ObservationEpoch& e) override {
    if (first_epoch < 0) first_epoch = e.sample_index;
  }
};

}  // namespace

TEST(ReceiveVisibility, SearchesOnlyPredictedVisiblePrnsOnceTheClockIsSet) {
  const std::filesystem::path brdc = ultratrack::test::shipped_nav_file();
  const auto dir = ultratrack::test::scratch_dir();
  const auto scenario = dir / "visibility.toml";
  std::ofstream(scenario) << "[signal]\nsample_rate_hz = 2.6e6\nformat = \"i8\"\nduration_s = 16.0\ncn0_dbhz = 45.0\n"
                             "seed = 3\n[time]\ngps_week = 1823\ntow_s = 518398.0\n[navigation]\nrinex = \""
                          << brdc.string()
                          << "\"\nelevation_mask_deg = 9\n[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n";
  const auto sim = dir / "sim";
  ultratrack::test_support::run_command("simulate", {"--scenario", scenario.string(), "--out", sim.string()});
  // Truth position from the simulator's truth.csv (first row: x, y, z ECEF columns by name).
  std::ifstream truth(sim / "truth.csv");
  std::string header, row;
  std::getline(truth, header);
  std::getline(truth, row);
  auto cells = [](const std::string& line) {
    std::vector<std::string> out;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) out.push_back(cell);
    return out;
  };
  const std::vector<std::string> names = cells(header), values = cells(row);
  std::array<double, 3> r{};
  const char* keys[3] = {"ecef_x_m", "ecef_y_m", "ecef_z_m"};
  for (int k = 0; k < 3; ++k) {
    const auto it = std::find(names.begin(), names.end(), keys[k]);
    ASSERT_NE(it, names.end()) << keys[k];
    r[static_cast<std::size_t>(k)] = std::stod(values.at(static_cast<std::size_t>(it - names.begin())));
  }

  const double fs_hz = 2.6e6;
  receiver::ReceiverOptions options;
  options.fs_hz = fs_hz;
  options.reference_week = 1823;
  options.reference_week_is_signal_week = true;
  options.reacquisition_interval_s = 1.0;
  options.reacquisition_latency_s = 0.5;
  options.blind_prns_per_snapshot = 0;  // every predicted-visible missing PRN on every snapshot
  options.approximate_r_e_m = r;
  options.threads = 1;
  SearchLog log;
  receiver::ReceiverEngine engine(options, log);
  const signals::RinexNavData nav = signals::read_rinex_nav(brdc);
  engine.add_navigation(nav.ephemerides, nav.klobuchar, nav.utc);
  std::ifstream in(sim / "antenna0.i8.bin", std::ios::binary);
  ASSERT_TRUE(in.good());
  std::vector<std::int8_t> raw(2 * 130000);
  std::vector<std::complex<float>> block;
  std::int64_t first = 0;
  while (in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size())) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount()) / 2;
    block.resize(n);
    for (std::size_t i = 0; i < n; ++i) block[i] = {static_cast<float>(raw[2 * i]), static_cast<float>(raw[2 * i + 1])};
    engine.process(block, first);
    first += static_cast<std::int64_t>(n);
  }
  ASSERT_GE(log.first_epoch, 0) << "the clock was never set";
  ASSERT_FALSE(log.searches.empty());
  EXPECT_EQ(log.searches.front().second.size(), 32u);  // the cold start: no clock, everything

  const Eigen::Vector3d r_rx(r[0], r[1], r[2]);
  int hidden_searches = 0, predicted_snapshots = 0;
  for (const auto& [snapshot, prns] : log.searches) {
    if (snapshot < log.first_epoch) continue;  // before the clock: no prediction possible
    ++predicted_snapshots;
    const signals::GpsTime t{ultratrack::test::shipped_nav_week, 518398.0 + static_cast<double>(snapshot) / fs_hz};
    std::set<int> visible;
    for (const auto& e : nav.ephemerides) {
      if (std::abs(signals::seconds_between(t, e.toe())) > 7200.0) continue;
      const auto look = signals::look_angles(r_rx, signals::satellite_state(e, t).r_e_m);
      if (look.elevation_rad > -5.0 * signals::kPi / 180.0) visible.insert(e.prn);
    }
    ASSERT_GE(visible.size(), 8u);
    const std::vector<int> tracked = engine.tracked_prns();
    for (int prn : prns)
      if (!visible.count(prn)) ++hidden_searches;
    // Every visible PRN not tracked at the end was searched on this snapshot (the satellites the simulator
    // leaves out, between -5 and 9 degrees, are missing on every snapshot).
    for (int prn : visible) {
      if (std::find(tracked.begin(), tracked.end(), prn) == tracked.end()) {
        EXPECT_NE(std::find(prns.begin(), prns.end(), prn), prns.end()) << "PRN " << prn << " visible, not searched";
      }
    }
  }
  EXPECT_GE(predicted_snapshots, 3);
  // 16 s of signal: one check of a hidden PRN at most (one per 60 s).
  EXPECT_LE(hidden_searches, 1);
  EXPECT_GE(engine.channels_in_use(), 6);
}
