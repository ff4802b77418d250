// SPDX-License-Identifier: GPL-3.0-or-later
// One recording received into an output folder: the whole of `ultratrack receive` below its command line, for
// programs, tests and bindings. Opens the sample file, checks that it holds enough signal for one acquisition, runs
// pipelines::Receiver over it (50 ms blocks, a stop token, a callback per block) and writes every output into
// `out`: solution.csv, NMEA, KML, RINEX obs + nav, tracking.csv and summary.json (receiver/receiver_outputs.hpp)
// and the coupling's logs (pipelines/receive_csv_files.hpp). Times are seconds of signal.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <stop_token>
#include <string>
#include <vector>

#include "ins/nav_state.hpp"
#include "pipelines/receive_options.hpp"
#include "pipelines/receiver_pipeline.hpp"
#include "receiver/sample_source.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::pipelines {

struct ReceiveFileJob {
  std::filesystem::path input;
  signals::SampleFormat format = signals::SampleFormat::i8;
  receiver::SampleSourceOptions source;  // fs_hz, if_hz, 2-bit layout, I/Q conventions, start_sample
  double duration_s = 0.0;               // seconds of signal to process after the start sample; 0: to the end
  ReceiveOptions options;                // options.receiver.fs_hz must equal source.fs_hz
  signals::RinexNavData navigation;      // hot start (may be empty)
  std::vector<ins::ImuIncrement> imu;    // for the couplings that use an IMU
  std::filesystem::path out;             // created when missing
};

// What a progress display needs, after every 50 ms block and once more when the run has ended (final).
struct ReceiveProgressEvent {
  const receiver::ReceiverEngine& engine;
  double total_s;  // seconds of signal the run will process at most
  bool final;
};
using ReceiveProgressCallback = std::function<void(const ReceiveProgressEvent&)>;

struct ReceiveFileResult {
  ReceiveSummary summary;
  double wall_s = 0.0;  // wall-clock time of the run
};

// The GPS week a recording is dated by when options do not say: the nav file's first ephemeris (then the signal's
// week is known), else `fallback_week` (e.g. the build date: the 10-bit week number is resolved within +-512).
void date_recording(receiver::ReceiverOptions& options, const signals::RinexNavData& navigation, int fallback_week);

// Runs the job. Throws signals::InputError naming the file: unreadable or malformed samples, fewer samples than one
// acquisition needs, no satellite found in the whole signal, or none tracked while another 2-bit packing would
// find them (the message names its flags: pipelines/format_diagnosis.hpp; no outputs written in these cases),
// options that do not fit together (checked before anything is written).
ReceiveFileResult receive_file(ReceiveFileJob job, std::stop_token stop = {},
                               const ReceiveProgressCallback& progress = {});

}  // namespace ultratrack::pipelines
