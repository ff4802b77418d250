// SPDX-License-Identifier: GPL-3.0-or-later
// The one SIGINT and SIGTERM handler of the program: while an InterruptGuard lives, Ctrl-C (or a scheduler's
// SIGTERM, as Slurm sends at a time limit) requests a stop on its std::stop_token instead of killing the process,
// so that a command's loop (a pipeline's, the simulator's) can end early and still finish every output. Guards may
// nest (a command run inside another): a signal stops them all. The previous handlers are restored when the last
// guard goes. The program exits 128 + the signal's number after such a stop (main.cpp), as a shell reports a process
// the signal ended, so that a script or scheduler never takes a stopped run for a complete one.
#pragma once

#include <stop_token>

namespace ultratrack::tools {

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  // Stop requested by SIGINT or SIGTERM (or by request_stop()).
  std::stop_token token() const { return source_.get_token(); }
  bool interrupted() const { return source_.stop_requested(); }
  void request_stop() { source_.request_stop(); }

 private:
  std::stop_source source_;
};

// The SIGINT or SIGTERM a guard caught during this process's life (the last one), 0 if none.
int interrupt_signal();

}  // namespace ultratrack::tools
