// SPDX-License-Identifier: GPL-3.0-or-later
// Vector coupling: the vector tracking filter (fusion/vector_tracking.hpp) attached to the receiver engine through
// receiver::VectorLoop, its epochs handed to a ReceiveSink (vector.csv, vector_state.csv) and counted for the
// summary. Units: s, m, m/s, Hz, chips.
#pragma once

#include <string>

#include "fusion/vector_tracking.hpp"
#include "pipelines/receive_sinks.hpp"
#include "receiver/receiver_engine.hpp"

namespace ultratrack::pipelines {

// The filter's options for a receiver configuration (the PVT's atmosphere models, the channels' E-L spacing).
fusion::VectorTrackingOptions vector_tracking_options(const receiver::ReceiverOptions& options,
                                                      fusion::VectorCarrier carrier = fusion::VectorCarrier::kAidedPll,
                                                      const fusion::NisReleaseOptions& nis = {});

class VectorLoopDriver {
 public:
  // sink: receives every vector epoch (must outlive this).
  VectorLoopDriver(const receiver::ReceiverOptions& options, ReceiveSink& sink,
                   fusion::VectorCarrier carrier = fusion::VectorCarrier::kAidedPll,
                   const fusion::NisReleaseOptions& nis = {});
  // Attach before the first process() call; the object must outlive the engine's use of it.
  void attach(receiver::ReceiverEngine& engine, double interval_s = 0.02);
  const fusion::VectorTrackingFilter& filter() const { return filter_; }
  // Vector epochs so far with at least one channel in vector mode, and channel-epochs in vector mode.
  long long vector_epochs() const { return vector_epochs_; }
  long long vector_channel_epochs() const { return vector_channel_epochs_; }
  // Channel-epochs commanded while coasting (faded: from the prediction alone).
  long long coasting_channel_epochs() const { return coasting_channel_epochs_; }
  // summary.json member: "vector": {carrier mode, epochs, channel-epochs in vector mode and coasting, filter
  // starts, resets, carrier-aiding steps of false PLL locks (frequency_resets), vector-PLL phase arcs and phase
  // locks lost (phase_arcs, phase_losses), the NIS test's window and probability, the releases per reason and
  // their log (fusion::ReleaseLog)}.
  std::string summary_json() const;
  std::string report() const;  // one line for stdout

 private:
  void log(const fusion::VectorEpochLog& e);

  fusion::VectorCarrier carrier_;
  fusion::VectorTrackingFilter filter_;
  ReceiveSink& sink_;
  long long vector_epochs_ = 0, vector_channel_epochs_ = 0, coasting_channel_epochs_ = 0;
};

}  // namespace ultratrack::pipelines
