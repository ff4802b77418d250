// SPDX-License-Identifier: GPL-3.0-or-later
// End-to-end tests through the library: a scenario file simulated in process (config/ reads it, sim/ writes the
// files) and its IF samples received by pipelines::receive_file into an output folder, with the few settings the
// tests vary. Header-only; for test executables that link pipelines and config.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "config/scenario_toml.hpp"
#include "pipelines/receive_file.hpp"
#include "receiver/nav_bit_source.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::test {

// simulate --scenario toml --out out, in process (out/scenario.toml is the scenario with every key, as simulate
// writes it).
inline sim::SimulationResult simulate_scenario(const std::filesystem::path& toml, const std::filesystem::path& out) {
  const sim::Scenario scenario = config::read_scenario(toml);
  return sim::simulate_to_folder(scenario, out, config::to_toml(scenario));
}

struct SimulatedReceive {
  std::filesystem::path input;               // an i8 file of the simulator
  std::optional<std::filesystem::path> nav;  // hot start
  std::filesystem::path out;
  double fs_hz = 2.0e6;
  pipelines::Coupling coupling = pipelines::Coupling::kScalar;
  bool troposphere = true;
  int threads = 0;  // all cores
  receiver::NavBitSource nav_bits = receiver::NavBitSource::kDecoded;
  fusion::VectorCarrier vector_carrier = fusion::VectorCarrier::kAidedPll;  // kVector
  // The tracking loops' oscillator class (receiver::set_tracking_oscillator); nullptr: the receiver's default (a
  // TCXO). The simulator's default clock is perfect ("ideal").
  const char* oscillator = nullptr;
};

inline pipelines::ReceiveSummary receive_simulated(const SimulatedReceive& r) {
  pipelines::ReceiveFileJob job;
  job.input = r.input;
  job.out = r.out;
  job.source.fs_hz = job.options.receiver.fs_hz = r.fs_hz;
  job.options.coupling = r.coupling;
  job.options.receiver.pvt.troposphere = r.troposphere;
  job.options.receiver.threads = r.threads;
  job.options.receiver.nav_bits = r.nav_bits;
  job.options.vector_carrier = r.vector_carrier;
  if (r.oscillator && !receiver::set_tracking_oscillator(job.options.receiver.tracking, r.oscillator))
    throw std::invalid_argument(std::string("unknown oscillator ") + r.oscillator);
  if (r.nav) job.navigation = signals::read_rinex_nav(*r.nav);
  pipelines::date_recording(job.options.receiver, job.navigation, 0);
  return pipelines::receive_file(std::move(job)).summary;
}

}  // namespace ultratrack::test
