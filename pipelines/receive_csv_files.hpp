// SPDX-License-Identifier: GPL-3.0-or-later
// The receive pipeline's CSV logs in an output folder (a ReceiveSink, as receiver/receiver_outputs.hpp is the
// receiver's observer): nav.csv (pipelines/fused_nav_csv.hpp) with loose, tight or ultra-tight coupling;
// vector.csv (one row per channel per vector epoch: predicted vs measured Doppler and code rate, code jump,
// innovations and their sigmas, the vector PLL's carrier states) and vector_state.csv (the filter's ECEF position,
// velocity, clock bias/drift and 1-sigmas) with vector coupling; ultratight.csv (per vector epoch and channel,
// keyed like tracking.csv by sample/time/prn) with ultra-tight coupling. Files are written to <name>.partial and
// renamed by commit(). Units: s, m, m/s, Hz, chips, cycles.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>

#include "io/atomic_file.hpp"
#include "pipelines/coupling.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/receive_sinks.hpp"

namespace ultratrack::pipelines {

class ReceiveCsvFiles final : public ReceiveSink {
 public:
  // Opens the coupling's files in dir (io::InputError when they cannot be created). fs_hz: the sample rate
  // (vector.csv's time column).
  ReceiveCsvFiles(const std::filesystem::path& dir, Coupling coupling, double fs_hz);
  void on_navigation(const ins::NavState& nav, const NavSigma& sigma) override;
  void on_vector_epoch(const fusion::VectorEpochLog& epoch) override;
  void on_ultratight_epoch(const UltraTightEpochLog& epoch) override;
  void commit();

 private:
  double fs_hz_;
  std::optional<FusedNavCsvWriter> nav_;
  std::optional<io::AtomicFile> vector_channels_, vector_state_, ultratight_;
};

}  // namespace ultratrack::pipelines
