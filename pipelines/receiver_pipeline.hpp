// SPDX-License-Identifier: GPL-3.0-or-later
// pipelines::Receiver: the receiver with every coupling behind one object. It owns the receiver engine and, by
// ReceiveOptions::coupling, the loop that closes the channels: none (scalar), the vector filter
// (pipelines/vector_loop_driver.hpp), the GNSS/INS integration on the way (pipelines/gnss_ins_coupler.hpp: loose,
// tight) or the tight pull-in followed by the ultra-tight loop (pipelines/ultratight_loop.hpp). The receiver's
// epochs go to a receiver::ReceiverObserver (receiver/receiver_outputs.hpp writes solution.csv and the rest), the
// pipeline's own to a ReceiveSink (pipelines/receive_csv_files.hpp writes nav.csv, vector.csv, ultratight.csv).
// Feed samples with process() (or run() over a sample file), then call finish() once.
#pragma once

#include <complex>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stop_token>
#include <string>
#include <vector>

#include "ins/nav_state.hpp"
#include "pipelines/receive_options.hpp"
#include "pipelines/receive_sinks.hpp"
#include "receiver/receiver_engine.hpp"
#include "receiver/sample_source.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::pipelines {

// What a run did (after finish()).
struct ReceiveSummary {
  Coupling coupling = Coupling::kScalar;
  double processed_s = 0.0;  // seconds of signal processed
  bool interrupted = false;  // run() stopped by its stop token before the end
  int threads = 1;
  bool satellites_found = false;  // at least one acquisition
  int satellites_tracked = 0, satellites_used = 0, fixes = 0;
  std::size_t ephemerides_decoded = 0;
  double ttff_s = -1.0;  // seconds of signal to the first fix; negative without one
  double mean_lat_deg = 0.0, mean_lon_deg = 0.0, mean_height_m = 0.0;  // of the fixes (fixes > 0)
  // kVector: epochs with channels in vector mode, channel-epochs in vector mode and coasting, filter starts and
  // resets.
  long long vector_epochs = 0, vector_channel_epochs = 0, coasting_channel_epochs = 0;
  int vector_filter_starts = 0, vector_filter_resets = 0;
  // kLoose, kTight, kUltraTight: whether the integration started (and why not), navigation rows sent to the sink.
  bool navigation_started = false;
  std::string navigation_not_started;
  long long navigation_rows = 0;
  NavSigma final_sigma;
  // kUltraTight: whether the loop took the channels over, and channel-epochs it commanded.
  bool handed_over = false;
  long long ultratight_channel_epochs = 0;
  // The coupling's members of summary.json ("vector", "fusion", "ultratight"; empty for scalar) and lines for stdout.
  std::string summary_json;
  std::vector<std::string> report;
};

class Receiver {
 public:
  // options: must be valid (ReceiveOptions::IsValid; std::invalid_argument otherwise). imu: the IMU increments for
  // kLoose, kTight and kUltraTight (at least two rows), ignored otherwise. navigation: ephemerides and ionosphere
  // known before the run (hot start; may be empty). observer and sink must outlive this object.
  Receiver(const ReceiveOptions& options, std::vector<ins::ImuIncrement> imu, const signals::RinexNavData& navigation,
           receiver::ReceiverObserver& observer, ReceiveSink& sink);
  ~Receiver();
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  // samples[0..n) whose first sample has receiver index first_sample (contiguous blocks). The second form also
  // takes the block as planar int16 at i16_gain (receiver::SamplePrefetcher converts it off this thread).
  void process(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  void process(std::span<const std::complex<float>> samples, std::int64_t first_sample, receiver::PlanarI16 i16,
               float i16_gain);
  // Reads up to `count` samples of source in 50 ms blocks (the next one read ahead when the engine has more than
  // one thread) and processes them, until the end, the count, or a stop request; on_block after every block.
  // Rethrows the reader's signals::InputError.
  void run(receiver::SampleSource& source, std::int64_t count, std::stop_token stop,
           const std::function<void(const receiver::ReceiverEngine&)>& on_block = {});
  // Ends the run: the vector loop's last update, the INS run to the last processed sample. Call once, after the
  // last process()/run(); the observer's own end (e.g. receiver::ReceiverOutputs::finish) comes after it.
  ReceiveSummary finish();

  const receiver::ReceiverEngine& engine() const;
  const ReceiveOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ultratrack::pipelines
