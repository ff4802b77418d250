#include "simulation_run.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "scenario_toml.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::tools {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_sigint(int) { g_interrupted = 1; }

}  // namespace

sim::SimulationResult run_simulation(const sim::Scenario& scenario, const std::filesystem::path& out_dir,
                                     std::FILE* progress, std::stop_token stop) {
  const auto print = [progress](const sim::SimulationProgress& p) {
    if (p.stage == sim::SimulationProgress::Stage::Imu) {
      fmt::print(stderr, "simulate: IMU {}%\n", p.percent);
      return;
    }
    if (!progress) return;
    fmt::print(progress, "simulate: {:5.1f} / {:.1f} s of signal ({:3d}%), {:.1f}x real time\n", p.done_s, p.total_s,
               p.percent, p.done_s / std::max(p.wall_s, 1e-9));
    std::fflush(progress);
  };
  return sim::simulate_to_folder(scenario, out_dir, to_toml(scenario), std::move(stop), print);
}

SigintStop::SigintStop() {
  g_interrupted = 0;
  previous_ = std::signal(SIGINT, on_sigint);
  watcher_ = std::jthread([this](std::stop_token own) {
    while (!own.stop_requested()) {
      if (g_interrupted) {
        source_.request_stop();
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
}

SigintStop::~SigintStop() {
  watcher_.request_stop();
  watcher_.join();
  std::signal(SIGINT, previous_ == SIG_ERR ? SIG_DFL : previous_);
}

}  // namespace ultratrack::tools
