// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack demo`: the built-in default scenario (scenarios/default.toml, compiled in) end to end, as far
// as the receiver goes: simulate it, acquire the satellites and compare with the simulator's truth, receive it
// (receiver/receiver_engine.hpp) and print the fix error against the true position. Writes into --out (default
// ./ultratrack-demo); a re-run overwrites it.
#include <fmt/core.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stop_token>
#include <string>
#include <vector>

#include "commands.hpp"
#include "config/scenario_toml.hpp"
#include "demo_scenario.hpp"
#include "interrupt_guard.hpp"
#include "io/input_error.hpp"
#include "receiver/acquisition.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/receiver_outputs.hpp"
#include "receiver/sample_source.hpp"
#include "simulation_run.hpp"

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;

struct DemoArgs {
  std::string out_dir = "ultratrack-demo";
  double duration_s = 0.0;  // 0: the scenario's own duration
  bool keep_samples = false;
};

// Acquires the first 10 ms of the simulated file and compares every satellite with satellites.csv.
void acquire_and_compare(const fs::path& samples, const sim::Scenario& scenario, const sim::SimulationResult& sim) {
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = scenario.sample_rate_hz;
  source_options.if_hz = scenario.if_hz;
  receiver::AcquisitionOptions options;
  options.fs_hz = scenario.sample_rate_hz;
  options.noncoherent = 10;
  receiver::SampleSource source(samples, scenario.format, source_options);
  receiver::Acquisition acquisition(options);
  std::vector<std::complex<float>> block(acquisition.samples_needed());
  source.read(block);
  std::vector<int> prns(32);
  for (int i = 0; i < 32; ++i) prns[i] = i + 1;
  const auto results = acquisition.search(block, prns);

  fmt::print("\nacquisition ({} x {} ms) against the simulator's truth:\n", options.noncoherent, options.coherent_ms);
  fmt::print("  PRN  el deg  Doppler true / found (Hz)   code true / found (chips)   C/N0 true / est (dB-Hz)\n");
  int found = 0;
  for (const auto& truth : sim.satellites) {
    const auto it = std::find_if(results.begin(), results.end(),
                                 [&](const receiver::AcquisitionResult& r) { return r.prn == truth.prn; });
    if (it == results.end() || !it->detected) {
      fmt::print("  {:3d} {:6.1f}  not detected\n", truth.prn, truth.elevation_rad * 180.0 / M_PI);
      continue;
    }
    ++found;
    fmt::print("  {:3d} {:6.1f}  {:9.1f} / {:9.1f}        {:8.3f} / {:8.3f}           {:4.1f} / {:4.1f}\n", truth.prn,
               truth.elevation_rad * 180.0 / M_PI, truth.doppler_hz, it->doppler_hz, truth.code_phase_chips,
               it->code_phase_chips, truth.cn0_dbhz, it->cn0_dbhz);
  }
  int false_alarms = 0;
  for (const auto& r : results) {
    const bool simulated = std::any_of(sim.satellites.begin(), sim.satellites.end(),
                                       [&](const signals::SatelliteView& v) { return v.prn == r.prn; });
    if (r.detected && !simulated) ++false_alarms;
  }
  fmt::print("  found {} of {} simulated satellites; {} detections of PRNs that are not in the signal\n", found,
             sim.satellites.size(), false_alarms);
}

// Receives the simulated file with the receiver's defaults for this scenario and compares the fixes with the
// scenario's static position. A stop request (Ctrl-C, SIGTERM) ends the run early; its outputs are finished.
void receive_and_compare(const fs::path& samples, const sim::Scenario& scenario, const fs::path& out,
                         std::stop_token stop) {
  receiver::SampleSourceOptions source_options;
  source_options.fs_hz = scenario.sample_rate_hz;
  source_options.if_hz = scenario.if_hz;
  receiver::ReceiverOptions options;
  options.fs_hz = scenario.sample_rate_hz;
  options.reference_week = scenario.gps_week;
  options.reference_week_is_signal_week = true;
  options.pvt.troposphere = scenario.troposphere;
  options.pvt.ionosphere = scenario.ionosphere;
  receiver::SampleSource source(samples, scenario.format, source_options);
  receiver::ReceiverOutputs outputs(out, options.fs_hz, options.observation_interval_s);
  receiver::ReceiverEngine engine(options, outputs);
  std::vector<std::complex<float>> block(static_cast<std::size_t>(std::llround(0.05 * options.fs_hz)));
  const auto start = std::chrono::steady_clock::now();
  bool interrupted = false;
  for (;;) {
    if (stop.stop_requested()) {
      interrupted = true;
      break;
    }
    const receiver::SampleBlock got = source.read(block);
    if (got.count == 0) break;
    engine.process(std::span<const std::complex<float>>(block.data(), got.count), got.first_sample);
  }
  receiver::RunDescription run;
  run.input = samples.string();
  run.format = signals::to_string(scenario.format);
  run.fs_hz = options.fs_hz;
  run.if_hz = scenario.if_hz;
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.interrupted = interrupted;
  outputs.finish(engine, run);
  const auto& stats = engine.stats();
  fmt::print("  {:.1f} s of signal in {:.1f} s ({:.1f}x real time); {} ephemerides decoded; {} fixes\n",
             receiver::processed_seconds(engine), run.wall_time_s,
             receiver::processed_seconds(engine) / std::max(run.wall_time_s, 1e-9), engine.decoded_ephemerides().size(),
             stats.fixes);
  if (stats.fixes == 0 && !interrupted) {
    fmt::print("  no fix: the signal ended before subframes 1-3 of four satellites were received\n");
    return;
  }
  if (stats.fixes == 0) return;
  const auto& earth = GeographicLib::Geocentric::WGS84();
  double x = 0, y = 0, z = 0;
  earth.Forward(scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2], x, y, z);
  const Eigen::Vector3d truth(x, y, z);
  const Eigen::Vector3d mean = stats.sum_r_e_m / stats.fixes;
  fmt::print("  first fix after {:.2f} s of signal; mean fix {:.2f} m from the true position (3-D)\n",
             receiver::ttff_seconds(engine), (mean - truth).norm());
  if (scenario.ionosphere && !engine.ionosphere().known().valid)
    fmt::print(
        "  (the simulated ionosphere is corrected with a default Klobuchar set: the broadcast parameters come\n"
        "   only every 12.5 min, in subframe 4 page 18; give them with `receive --nav`)\n");
}

void run_demo(const DemoArgs& args) {
  sim::Scenario scenario = config::parse_scenario(kDemoScenarioToml, "built-in demo scenario (scenarios/default.toml)");
  if (args.duration_s > 0.0) scenario.duration_s = args.duration_s;
  const fs::path out(args.out_dir);
  fs::create_directories(out);
  fmt::print(
      "ultratrack demo: a static receiver at {:.6f} N {:.6f} E, {:.0f} m, GPS week {} TOW {:.0f} s,\n"
      "  the built-in nominal 24-satellite constellation, {:.0f} s of {} samples at {:.1f} MHz, {:.0f} dB-Hz\n",
      scenario.llh_deg_m[0], scenario.llh_deg_m[1], scenario.llh_deg_m[2], scenario.gps_week, scenario.tow_s,
      scenario.duration_s, signals::to_string(scenario.format), scenario.sample_rate_hz / 1e6, scenario.cn0_dbhz);

  fmt::print("\n1. simulate -> {}\n", (out / "simulation").string());
  const InterruptGuard interrupt;
  const sim::SimulationResult sim =
      run_simulation(scenario, out / "simulation", isatty(fileno(stderr)) ? stderr : nullptr, interrupt.token());
  fmt::print("  {:.1f} s of signal in {:.1f} s ({:.1f}x real time), {} satellites in view\n", sim.signal_s, sim.wall_s,
             sim.signal_s / std::max(sim.wall_s, 1e-9), sim.satellites.size());

  if (interrupt.interrupted()) {  // the simulation's outputs are complete up to the stop; nothing more is run
    fmt::print("\nstopped (the simulation's outputs end where it stopped)\n");
    return;
  }

  fmt::print("\n2. acquire");
  acquire_and_compare(sim.sample_files.front(), scenario, sim);

  fmt::print("\n3. receive -> {}\n", (out / "receiver").string());
  receive_and_compare(sim.sample_files.front(), scenario, out / "receiver", interrupt.token());
  if (interrupt.interrupted()) {
    fmt::print("\nstopped (the receiver's outputs end where it stopped; the sample file is kept)\n");
    return;
  }

  if (!args.keep_samples) {
    for (const auto& f : sim.sample_files) fs::remove(f);
    fmt::print("\n(sample file removed; --keep-samples keeps it)\n");
  }
  fmt::print("\noutputs in {}\n", out.string());
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run the built-in default scenario end to end and print a summary");
  auto args = std::make_shared<DemoArgs>();
  cmd->add_option("--out", args->out_dir, "Output folder (created; a re-run overwrites)");
  cmd->add_option("--duration", args->duration_s, "Seconds of signal (default: the scenario's)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--keep-samples", args->keep_samples, "Keep the simulated IF sample file");
  cmd->callback([args] { run_demo(*args); });
}

}  // namespace ultratrack::tools
