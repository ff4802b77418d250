// SPDX-License-Identifier: GPL-3.0-or-later
// `receive`'s progress display on stderr: a bar redrawn every 250 ms on a terminal, a plain line every 10 s of
// signal otherwise; nothing with --quiet.
#pragma once

#include <chrono>

#include "pipelines/receive_file.hpp"

namespace ultratrack::tools {

class ReceiveProgress {
 public:
  explicit ReceiveProgress(bool quiet);
  void update(const pipelines::ReceiveProgressEvent& event);

 private:
  bool quiet_, tty_;
  double next_line_s_ = 0.0;
  std::chrono::steady_clock::time_point last_{};
};

}  // namespace ultratrack::tools
