// `ultratrack receive --coupling vector`: the vector tracking filter (fusion/vector_tracking.hpp) attached to the
// receiver engine through receiver::VectorLoop, and its logs in the output folder: vector.csv (one row per
// channel per vector epoch: predicted vs measured Doppler and code rate, code jump, innovations and their
// sigmas; with --vector-carrier pll the carrier states: discriminator, innovation, sigma, frequency residual, lock
// indicator, loop bandwidth, phase jump, and the replica's phase at the measured epoch's middle) and vector_state.csv (the filter's ECEF position/velocity, clock bias/drift and 1-sigmas).
// Units: s, m, m/s, Hz, chips/s, chips.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "fusion/vector_tracking.hpp"
#include "io/atomic_file.hpp"
#include "receiver/receiver_engine.hpp"

namespace ultratrack::tools {

// The filter's options for a receiver configuration (the PVT's atmosphere models, the channels' E-L spacing).
fusion::VectorTrackingOptions vector_tracking_options(const receiver::ReceiverOptions& options,
                                                     fusion::VectorCarrier carrier = fusion::VectorCarrier::kAidedPll);
// --vector-carrier's value: "aided-pll", "fll" or "pll" (InputError naming the option otherwise).
fusion::VectorCarrier parse_vector_carrier(const std::string& text);

class ReceiveVector {
 public:
  // Opens the two logs in dir (InputError when they cannot be created).
  ReceiveVector(const receiver::ReceiverOptions& options, const std::filesystem::path& dir,
                fusion::VectorCarrier carrier = fusion::VectorCarrier::kAidedPll);
  // Attach before the first process() call; the object must outlive the engine's use of it.
  void attach(receiver::ReceiverEngine& engine, double interval_s = 0.02);
  // Commits the logs.
  void finish();
  const fusion::VectorTrackingFilter& filter() const { return filter_; }
  // Vector epochs so far with at least one channel in vector mode, and channel-epochs in vector mode.
  long long vector_epochs() const { return vector_epochs_; }
  long long vector_channel_epochs() const { return vector_channel_epochs_; }
  // Channel-epochs commanded while coasting (faded: from the prediction alone).
  long long coasting_channel_epochs() const { return coasting_channel_epochs_; }
  // summary.json member: "vector": {carrier mode, epochs, channel-epochs in vector mode and coasting, filter
  // starts, resets, carrier-aiding steps of false PLL locks (frequency_resets), vector-PLL phase arcs and phase
  // locks lost (phase_arcs, phase_losses)}.
  std::string summary_json() const;

 private:
  void log(const fusion::VectorEpochLog& e);

  double fs_hz_;
  fusion::VectorCarrier carrier_;
  fusion::VectorTrackingFilter filter_;
  io::AtomicFile channels_, state_;
  long long vector_epochs_ = 0, vector_channel_epochs_ = 0, coasting_channel_epochs_ = 0;
};

}  // namespace ultratrack::tools
