// SPDX-License-Identifier: GPL-3.0-or-later
// The command-line options of `receive` that choose the coupling and its GNSS/INS settings (--coupling, --imu,
// --filter, --align, --fusion-config, --imu-time-origin, --imu-pps, --ut-measurement, --ut-serial, --ut-pipelined,
// --vector-carrier, --odometer), parsed into pipelines::ReceiveOptions, and the IMU file's reader. Errors are
// io::InputError naming the option or the file.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "ins/imu_csv.hpp"
#include "ins/nav_state.hpp"
#include "pipelines/receive_options.hpp"

namespace ultratrack::tools {

// The command-line text of the coupling options (parsed by apply_receive_coupling_args).
struct ReceiveFusionArgs {
  std::string imu, coupling = "scalar", filter, align, config, time_origin, ut_measurement, vector_carrier;
  std::string odometer;    // --odometer FILE (loose)
  std::string imu_pps;     // --imu-pps: the PPS record of the IMU's local clock
  bool ut_serial = false;  // --ut-serial: names the default (older command lines)
  // --ut-pipelined[=true|false]: the pipelined loop; =false is the serial default.
  bool ut_pipelined = false;
  const CLI::Option* ut_pipelined_option = nullptr;  // set by add_receive_fusion_options: was it given?
  // --nis-window N, --nis-probability P (vector, ultra-tight); not given: fusion::NisReleaseOptions' defaults.
  int nis_window = 0;
  double nis_probability = 0.0;
  const CLI::Option* nis_window_option = nullptr;
  const CLI::Option* nis_probability_option = nullptr;
  double ut_clock_loop_bw_hz = 5.0;  // --ut-clock-loop-bw (ultra-tight)
  const CLI::Option* ut_clock_loop_bw_option = nullptr;
};
void add_receive_fusion_options(CLI::App* cmd, ReceiveFusionArgs& args);

// Checks and parses the options into options (coupling, vector carrier and, for loose, tight and ultra-tight, the
// GNSS/INS settings; with --odometer the odometer file is read); with --coupling scalar or vector no GNSS/INS
// option may be given.
void apply_receive_coupling_args(const ReceiveFusionArgs& args, pipelines::ReceiveOptions& options);
// The IMU file: InputError naming it when missing, malformed, non-finite or shorter than two rows.
std::vector<ins::ImuIncrement> read_receive_imu(const std::string& file, const ins::ImuCsvOptions& options);
// With --imu-pps: the IMU's local stamps put on GPS time since the first PPS edge (pipelines/pps_time_sync.hpp),
// which becomes the IMU time origin (as --imu-time-origin TOW would); a PPS record that does not cover the IMU file
// is an InputError. Without it nothing changes.
void put_receive_imu_on_pps(const ReceiveFusionArgs& args, std::vector<ins::ImuIncrement>& imu,
                            pipelines::ReceiveOptions& options);

}  // namespace ultratrack::tools
