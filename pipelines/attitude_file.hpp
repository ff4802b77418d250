// SPDX-License-Identifier: GPL-3.0-or-later
// Several recordings of one antenna array received into an output folder: the whole of `ultratrack attitude`
// below its command line, for programs, tests and bindings. The files (one per antenna, master first, recorded on
// one clock) are read sample-synchronously (receiver/multi_sample_source.hpp) in 50 ms blocks; the scalar receiver
// tracks each satellite on the master and correlates every antenna against its replica, and
// receiver::AttitudeOutputs solves and writes attitude.csv, antenna_phases.csv, summary.json and position/.
// Times are seconds of signal.
#pragma once

#include <filesystem>
#include <functional>
#include <stop_token>
#include <string>
#include <vector>

#include "receiver/attitude_outputs.hpp"
#include "receiver/attitude_solver.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/receiver_options.hpp"
#include "receiver/sample_source.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::pipelines {

struct AttitudeFileJob {
  std::vector<std::filesystem::path> inputs;  // one per antenna of solver.array, master first
  signals::SampleFormat format = signals::SampleFormat::i8;
  receiver::SampleSourceOptions source;  // fs_hz, if_hz
  // fs_hz = source.fs_hz; num_antennas is set from inputs; reference_week 0: the navigation's (date_recording).
  receiver::ReceiverOptions options;
  receiver::AttitudeSolverOptions solver;  // the array (lever arms) and the solver's settings
  std::vector<double> line_bias_cycles;    // per antenna
  signals::RinexNavData navigation;        // hot start (may be empty)
  double duration_s = 0.0;                 // seconds of signal to process; 0: to the end
  std::filesystem::path out;               // created when missing
};

struct AttitudeFileResult {
  receiver::AttitudeStats stats;
  double processed_s = 0.0;  // seconds of signal
  double wall_s = 0.0;
  int threads = 1;
  bool interrupted = false;  // stopped by the stop token before the end
};

// After every 50 ms block: the engine and the outputs' running statistics.
using AttitudeProgressCallback =
    std::function<void(const receiver::ReceiverEngine& engine, const receiver::AttitudeStats& stats)>;

// Runs the job. Throws signals::InputError naming the file or the setting: unreadable or malformed samples, a
// file count other than the array's antennas, neither a reference week nor navigation data to date the recording,
// options that do not validate. No attitude is not an error (the
// result's stats say so; the files are written).
AttitudeFileResult attitude_file(AttitudeFileJob job, std::stop_token stop = {},
                                 const AttitudeProgressCallback& progress = {});

}  // namespace ultratrack::pipelines
