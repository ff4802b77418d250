// SPDX-License-Identifier: GPL-3.0-or-later
// The engine's port to a vector loop (receiver/vector_loop.hpp): every interval (in samples) the loop gets every
// channel's state and latest measurements in slot order and its commands go back to the channels; pipelined,
// the epoch's inputs are copied (the engine changes the ephemerides, Klobuchar, last fix and the channels while
// the loop runs), the loop runs as the first job of the next block's parallel correlation, and its commands
// reach the channels at the next vector epoch. Units: samples, seconds.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "receiver/epoch_solver.hpp"
#include "receiver/navigation_store.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_channel.hpp"
#include "receiver/vector_loop.hpp"

namespace ultratrack::receiver {

class VectorLoopPort final {
 public:
  // See ReceiverEngine::set_vector_loop: throws std::invalid_argument for an interval outside [0.001, 1] s. The
  // first vector epoch is one interval after from_sample; nullptr puts the channels back to scalar.
  void set(VectorLoop* loop, double interval_s, bool pipelined, double fs_hz, std::int64_t from_sample,
           std::vector<std::unique_ptr<ReceiverChannel>>& channels);
  // See ReceiverEngine::finish_vector_loop.
  void finish();
  bool attached() const { return loop_ != nullptr; }
  // The next vector epoch after sample (moved past it when sample reached it: the start, gaps).
  std::int64_t next_epoch_after(std::int64_t sample);
  std::int64_t next_epoch() const { return next_; }
  // The vector epoch at sample (== the next epoch): the loop's turn, then the next epoch one interval on.
  void epoch(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels, const EpochSolver& solver,
             const NavigationStore& navigation);
  // A pipelined update is waiting for its inputs' block: run_pipelined() is the block's first parallel job.
  bool queued() const { return pipelined_.queued; }
  // The pipelined loop's update on its copied inputs (touches nothing else).
  void run_pipelined();

 private:
  // The vector epoch's inputs into in/epoch (epoch.channels, ephemerides etc. still to be pointed at storage).
  void collect_inputs(std::int64_t sample, const std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                      const EpochSolver& solver, std::vector<VectorChannelInput>& in, VectorEpochInput& epoch);
  void apply_pipelined(std::vector<std::unique_ptr<ReceiverChannel>>& channels);  // its commands to the channels
                                                                                  // that are still the ones it saw

  VectorLoop* loop_ = nullptr;
  double fs_hz_ = 0.0;
  std::int64_t step_ = 0, next_ = 0;
  std::vector<VectorChannelInput> in_;
  std::vector<VectorChannelCommand> out_;
  // Pipelined loop: one epoch's inputs, copied, and its commands until the next vector epoch applies them.
  struct PipelinedVector {
    bool queued = false;    // inputs captured, update not yet run
    bool answered = false;  // update run, commands not yet applied
    VectorEpochInput epoch;
    std::vector<VectorChannelInput> in;
    std::vector<VectorChannelCommand> out;
    std::vector<signals::Ephemeris> ephemerides;
    signals::KlobucharParameters iono;
    std::optional<PvtSolution> last_fix;
  };
  bool pipelined_mode_ = false;
  PipelinedVector pipelined_;
};

}  // namespace ultratrack::receiver
