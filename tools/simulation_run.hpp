// `ultratrack simulate`'s run of a scenario into a folder (sim/simulation_files.hpp lists the files):
// sim::simulate_to_folder with scenario.toml = to_toml(scenario), progress lines on a stream, and the Ctrl-C
// stop of the command line (SigintStop).
#pragma once

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <stop_token>
#include <thread>

#include "sim/simulation.hpp"

namespace ultratrack::tools {

// progress: where to print progress lines (nullptr: silent; long IMU runs still report on stderr).
sim::SimulationResult run_simulation(const sim::Scenario& scenario, const std::filesystem::path& out_dir,
                                     std::FILE* progress = nullptr, std::stop_token stop = {});

// Ctrl-C as a stop request while it lives: the handler only sets a flag (async-signal-safe); a watcher thread
// turns the flag into stop_source().request_stop(). The previous handler is restored at the end.
// (To be replaced by tools/interrupt_guard.hpp, the one SIGINT guard of the commands.)
class SigintStop {
 public:
  SigintStop();
  ~SigintStop();
  SigintStop(const SigintStop&) = delete;
  SigintStop& operator=(const SigintStop&) = delete;
  std::stop_token token() const { return source_.get_token(); }

 private:
  void (*previous_)(int) = SIG_DFL;
  std::stop_source source_;
  std::jthread watcher_;
};

}  // namespace ultratrack::tools
