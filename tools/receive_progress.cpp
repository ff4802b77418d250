// SPDX-License-Identifier: GPL-3.0-or-later
#include "receive_progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "receiver/receiver_summary.hpp"

namespace ultratrack::tools {

ReceiveProgress::ReceiveProgress(bool quiet) : quiet_(quiet), tty_(isatty(fileno(stderr)) != 0) {}

void ReceiveProgress::update(const pipelines::ReceiveProgressEvent& event) {
  if (quiet_) return;
  const receiver::ReceiverEngine& engine = event.engine;
  const bool final = event.final;
  const double total_s = event.total_s;
  const double t = receiver::processed_seconds(engine);
  const auto now = std::chrono::steady_clock::now();
  if (!final) {
    if (tty_ && now - last_ < std::chrono::milliseconds(250)) return;
    if (!tty_ && t < next_line_s_) return;
  }
  last_ = now;
  next_line_s_ = t + 10.0;
  const auto& fix = engine.last_fix();
  const std::string status = fix ? fmt::format("fix {:.6f} {:.6f} {:.1f} m ({} sats)", fix->lat_rad * 57.29577951308232,
                                               fix->lon_rad * 57.29577951308232, fix->height_m, fix->used_prns.size())
                                 : "no fix";
  const int tracked = engine.channels_in_use(), synced = engine.channels_synchronised();
  if (tty_) {
    const double fraction = total_s > 0.0 ? std::min(1.0, t / total_s) : 0.0;
    const int width = 30, filled = static_cast<int>(fraction * width);
    fmt::print(stderr, "\r[{}{}] {:6.1f}/{:.1f} s  tracking {:2d} (synced {:2d})  {}   ", std::string(filled, '#'),
               std::string(width - filled, '.'), t, total_s, tracked, synced, status);
    if (final) fmt::print(stderr, "\n");
  } else {
    fmt::print(stderr, "receive: {:.1f}/{:.1f} s, tracking {} (synced {}), {}\n", t, total_s, tracked, synced, status);
  }
}

}  // namespace ultratrack::tools
