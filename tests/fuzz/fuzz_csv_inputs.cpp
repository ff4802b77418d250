// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: every CSV a command reads: imu.csv, gnss.csv (fuse), attitude.csv (fuse --attitude), truth and
// nav CSVs (ins --init), solution.csv and truth.csv (compare), trajectory segment and motion files (scenarios),
// odometer.csv (fuse --odometer), pps.csv (align/fuse/receive --imu-pps: read and the clock fitted).
// The first byte picks the reader (modulo 11: bytes 0-9 pick the readers they picked before pps.csv came).
#include "fuzz_input.hpp"
#include "ins/imu_csv.hpp"
#include "ins/nav_csv.hpp"
#include "ins/odometer_csv.hpp"
#include "ins/trajectory.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "pipelines/pps_time_sync.hpp"
#include "pipelines/solution_compare.hpp"
#include "signals/receiver_motion.hpp"
#include "sim/truth_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  if (size < 1) return 0;
  const auto file = fuzz::as_file(data + 1, size - 1, "input.csv");
  fuzz::expect_input_error_or_success([&] {
    switch (data[0] % 11) {
      case 0:
        ins::read_imu_csv(file);
        break;
      case 1:
        pipelines::read_gnss_csv(file);
        break;
      case 2:
        pipelines::read_attitude_csv(file);
        break;
      case 3:
        sim::read_truth_csv(file);
        break;
      case 4:
        ins::read_nav_csv(file);
        break;
      case 5:
        pipelines::read_solution_csv(file);
        break;
      case 6:
        pipelines::read_simulation_truth_csv(file);
        break;
      case 7:
        ins::read_segments_csv(file, ins::TrajectorySpec{});
        break;
      case 9:
        ins::read_odometer_csv(file);
        break;
      case 10:
        pipelines::fit_pps_clock(pipelines::read_pps_csv(file), file.string());
        break;
      default:
        signals::read_trajectory_csv(file);
        break;
    }
  });
  return 0;
}
