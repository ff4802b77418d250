// SPDX-License-Identifier: GPL-3.0-or-later
// The scalar receiver as a processing object: fed with contiguous blocks of complex baseband samples (any
// size), it acquires satellites on a snapshot of the first samples (assisted by ephemeris and the last fix once
// they exist; satellites predicted below the horizon by an ephemeris or a decoded almanac are searched only
// rarely; those with no orbit known at a low duty cycle once 4 are in channels: ReceiverOptions::blind_revisit_s),
// allocates them to tracking channels (ReceiverChannel), re-acquires missing satellites on fresh snapshots,
// forms observables at common receive epochs (every observation_interval_s, in samples), and solves PVT from
// them with the decoded (or supplied) ephemerides. Results go to a ReceiverObserver as they happen.
// Threads (receiver/worker_pool.hpp): the channels of each block run in parallel, each sample read once and
// shared; a re-acquisition searches in the background and its satellites join at a fixed later sample. Every
// observer call is made on the caller's thread in a fixed order, so the results are the same for any number
// of threads.
// The receiver clock is a GpsTime tied to a sample index (ReceiverClock); pseudorange = c (t_rx - t_tx).
// Parts: AcquisitionScheduler (snapshots, what to search, re-acquisition), NavigationStore (ephemerides,
// almanacs, Klobuchar/UTC), EpochSolver (observables, PVT, clock jumps), VectorLoopPort (the vector loop's turn);
// the engine owns the channels and feeds them. Units: samples, seconds, metres, Hz.
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/acquisition_scheduler.hpp"
#include "receiver/antenna_phase.hpp"
#include "receiver/epoch_solver.hpp"
#include "receiver/navigation_store.hpp"
#include "receiver/observables.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_channel.hpp"
#include "receiver/receiver_clock.hpp"
#include "receiver/receiver_options.hpp"
#include "receiver/receiver_results.hpp"
#include "receiver/vector_loop.hpp"
#include "receiver/vector_loop_port.hpp"
#include "receiver/worker_pool.hpp"
#include "signals/almanac.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::receiver {

class ReceiverEngine {
 public:
  // options must validate (std::invalid_argument otherwise). The observer must outlive the engine.
  ReceiverEngine(const ReceiverOptions& options, ReceiverObserver& observer);
  ~ReceiverEngine();

  // Hot start: ephemerides (and Klobuchar/UTC when valid) known before decoding any.
  void add_navigation(const std::vector<signals::Ephemeris>& ephemerides, const signals::KlobucharParameters& iono,
                      const signals::UtcParameters& utc);

  // Processes samples[0..n) whose first sample has receiver index first_sample. Blocks should be contiguous;
  // a gap is bridged by the channels (dead reckoning) and restarts a pending acquisition snapshot.
  void process(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  // The same with the block also given as planar int16 times i16_gain (receiver/sample_prefetcher.hpp converts
  // it off this thread): used instead of the engine's own conversion when i16_gain equals i16_gain() (the same
  // values: the same conversion), ignored otherwise. One antenna only.
  void process(std::span<const std::complex<float>> samples, std::int64_t first_sample, PlanarI16 i16, float i16_gain);
  // num_antennas > 1: one span per antenna, all the same size and on the same sample indices; antenna 0 (the
  // master) is the one acquired on. Throws std::invalid_argument when the spans do not match the options.
  void process(std::span<const std::span<const std::complex<float>>> antennas, std::int64_t first_sample);

  // Vector tracking: from now on, every interval_s (rounded to samples; 0.001..1 s) the loop is called on the
  // caller's thread, after the channels' parallel work, with every channel (receiver/vector_loop.hpp); nullptr
  // detaches it (channels go back to scalar). The loop must outlive its use. Throws std::invalid_argument for a
  // bad interval.
  // pipelined: the epoch's inputs are copied at the vector epoch s and the loop runs as the first job of the next
  // block's parallel correlation (on the caller thread, beside the workers: off the critical path with 2 threads);
  // its commands reach the channels at the next vector epoch s + interval (VectorEpochInput::command_sample), one
  // channel epoch later than unpipelined. --threads 1 runs the job in turn: the same results for any thread count.
  void set_vector_loop(VectorLoop* loop, double interval_s = 0.02, bool pipelined = false);
  // End of the stream: runs a pipelined loop's update of the last vector epoch if it has not run (its commands
  // go nowhere). Nothing otherwise.
  void finish_vector_loop();

  const ReceiverStats& stats() const { return stats_; }
  const std::optional<PvtSolution>& last_fix() const { return solver_.last_fix(); }
  int channels_in_use() const;
  int channels_synchronised() const;
  int threads() const { return pool_.threads(); }
  // The integer correlator's gain from sample scale to int16: 0 until the cold start's snapshot fixes it.
  float i16_gain() const { return i16_gain_; }
  // Ephemerides decoded from the signal (each new set once), and the broadcast Klobuchar/UTC parameters.
  const std::vector<signals::Ephemeris>& decoded_ephemerides() const { return navigation_.decoded(); }
  // The Klobuchar parameters in use: a default set until the nav file's or the broadcast ones are known
  // (receiver/ionosphere_model.hpp); ionosphere() also tells which, since when, and the known ones alone.
  const signals::KlobucharParameters& klobuchar() const { return navigation_.klobuchar(); }
  const IonosphereModel& ionosphere() const { return navigation_.ionosphere(); }
  const signals::UtcParameters& utc() const { return navigation_.utc(); }
  // The latest almanac decoded from any channel, per PRN (index = PRN).
  const std::array<std::optional<signals::Almanac>, 33>& almanacs() const { return navigation_.almanacs(); }
  const ReceiverOptions& options() const { return options_; }
  // Time phase-locked on a PRN so far (released channels and the one tracking it now).
  double tracked_time_s(int prn) const;
  // Data wipe-off on a PRN so far (released channels and the one tracking it now).
  NavBitCounts nav_bit_counts(int prn) const;
  // PRNs in channels now, and of those the synchronised ones (for progress displays).
  std::vector<int> tracked_prns() const;

 private:
  void process_master(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  void start_acquisition(std::int64_t end_sample);
  void finish_acquisition(std::int64_t start_sample);
  std::vector<int> missing_prns() const;
  void feed_channels(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  void feed_channel(int slot);
  void release_lost_channels(std::int64_t sample);
  void convert_part_to_i16(int n);

  ReceiverOptions options_;
  ReceiverObserver& observer_;
  std::vector<std::unique_ptr<ReceiverChannel>> channels_;  // nullptr = free
  std::vector<std::vector<TrackingRecord>> records_;        // per channel slot, one block's records (reused)
  SampleBlockView view_;                                    // the block the channels are fed
  WorkerPool pool_;
  AcquisitionScheduler acquisition_;  // after pool_: its destructor waits for a background search
  NavigationStore navigation_;
  EpochSolver solver_;
  VectorLoopPort vector_;

  bool started_ = false;
  std::int64_t next_sample_ = 0;  // expected first sample of the next block
  std::int64_t observation_step_ = 0, next_observation_ = 0;
  int record_periods_ = 20;
  ReceiverStats stats_;
  // Multi-antenna: the other antennas' samples of the block being processed.
  std::array<const std::complex<float>*, kMaxAntennas> antenna_block_{};
  std::int64_t antenna_block_first_ = 0;
  // Integer correlator: the gain to int16 (0 until the cold start's snapshot fixes it) and the int16 copy of
  // the part being fed (I then Q per antenna; grown once to the largest part).
  float i16_gain_ = 0.0f;
  std::vector<std::int16_t> i16_block_;
  PlanarI16 given_i16_{};  // the current block's int16 copy from the caller, if usable
  std::int64_t given_i16_first_ = 0;
  float given_i16_gain_ = 0.0f;
};

}  // namespace ultratrack::receiver
