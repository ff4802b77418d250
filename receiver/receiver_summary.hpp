// SPDX-License-Identifier: GPL-3.0-or-later
// summary.json of a receiver run: what was processed (input description, duration, wall time, realtime factor),
// time to first fix (seconds of signal from the first processed sample), satellites acquired / tracked / used,
// fixes, the mean position (LLH, degrees and metres) and per-satellite statistics. Written as an AtomicFile.
#pragma once

#include <filesystem>
#include <string>

#include "receiver/receiver_engine.hpp"

namespace ultratrack::receiver {

struct RunDescription {
  std::string input;   // file path
  std::string format;  // sample format name
  double fs_hz = 0.0, if_hz = 0.0;
  double skip_s = 0.0;  // signal skipped at the file's start
  double wall_time_s = 0.0;
  bool interrupted = false;         // stopped by SIGINT before the end
  std::string coupling = "scalar";  // how the loops are closed: scalar, vector, loose, tight
  std::string extra_json;           // further top-level members, formatted ("\"name\": value"), written last
};

// Seconds of signal processed by the engine.
double processed_seconds(const ReceiverEngine& engine);
// Time to first fix in seconds of signal from the first processed sample, or a negative value without a fix.
double ttff_seconds(const ReceiverEngine& engine);

void write_summary_json(const std::filesystem::path& path, const ReceiverEngine& engine, const RunDescription& run);

}  // namespace ultratrack::receiver
