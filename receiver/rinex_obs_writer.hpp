// SPDX-License-Identifier: GPL-3.0-or-later
// RINEX 3.04 GPS observation files (C1C pseudorange m, L1C carrier phase cycles, D1C Doppler Hz,
// S1C C/N0 dB-Hz) from ObservationEpochs. Epoch times are receiver-clock times, as RINEX requires.
// The body is streamed to a side file and the header (which needs the first epoch and the approximate
// position) is written in front of it by finish(); nothing appears under the final name before that.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/atomic_file.hpp"
#include "receiver/observables.hpp"

namespace ultratrack::receiver {

struct RinexObsHeaderInfo {
  std::string marker_name = "ULTRATRACK";
  std::string receiver_type = "ULTRATRACK SDR";
  double interval_s = 0.1;
};

class RinexObsWriter {
 public:
  RinexObsWriter(const std::filesystem::path& path, RinexObsHeaderInfo info);
  void write(const ObservationEpoch& epoch);
  // COMMENT lines of the header (each cut to 60 characters), e.g. which ionosphere model was used from when.
  void set_comments(std::vector<std::string> lines) { comments_ = std::move(lines); }
  // approx_r_e_m: the mean fix, written into APPROX POSITION XYZ (zeros when unknown).
  void finish(const Eigen::Vector3d& approx_r_e_m);
  int epochs_written() const { return epochs_; }

 private:
  std::filesystem::path path_;
  RinexObsHeaderInfo info_;
  io::AtomicFile body_;
  std::optional<signals::GpsTime> first_epoch_;
  int epochs_ = 0;
  std::vector<std::string> comments_;
};

}  // namespace ultratrack::receiver
