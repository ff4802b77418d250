// SPDX-License-Identifier: GPL-3.0-or-later
// The library from outside the tree: 10 s of the built-in constellation simulated into a folder (sim/), then received
// from that file with a hot start (pipelines/receive_file.hpp); prints the mean fix and its distance from the truth.
#include <GeographicLib/LocalCartesian.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "pipelines/receive_file.hpp"
#include "sim/navigation_source.hpp"
#include "sim/simulation_files.hpp"

using namespace ultratrack;

int main() {
  sim::Scenario scenario;  // a static receiver, nominal constellation, 45 dB-Hz, i8 at 2.6 MHz
  scenario.duration_s = 10.0;
  scenario.tow_s = 518398.0;  // subframes (and their time of week) begin 2 s and 8 s into the signal
  const auto dir = std::filesystem::temp_directory_path() / "ultratrack_consumer";
  sim::simulate_to_folder(scenario, dir, "");
  pipelines::ReceiveFileJob job;
  job.input = dir / "antenna0.i8.bin";
  job.out = dir / "receiver";
  job.source.fs_hz = job.options.receiver.fs_hz = scenario.sample_rate_hz;
  job.options.receiver.pvt.troposphere = scenario.troposphere;         // correct what the scenario simulates
  job.navigation = sim::to_rinex_nav(sim::load_navigation(scenario));  // as a nav file of the day would give it
  pipelines::date_recording(job.options.receiver, job.navigation, scenario.gps_week);
  const pipelines::ReceiveSummary fix = pipelines::receive_file(job).summary;
  double e, n, u;
  GeographicLib::LocalCartesian(scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2])
      .Forward(fix.mean_lat_deg, fix.mean_lon_deg, fix.mean_height_m, e, n, u);
  std::printf("fix: %.7f %.7f %.1f m (%d fixes, first at %.1f s), %.2f m from the truth\n", fix.mean_lat_deg,
              fix.mean_lon_deg, fix.mean_height_m, fix.fixes, fix.ttff_s, std::hypot(e, n, u));
  return fix.fixes > 0 ? 0 : 1;
}
