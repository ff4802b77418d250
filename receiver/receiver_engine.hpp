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
// Units: samples, seconds, metres, Hz.
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
#include "receiver/antenna_phase.hpp"
#include "receiver/carrier_smoothing.hpp"
#include "receiver/ionosphere_model.hpp"
#include "receiver/observables.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_channel.hpp"
#include "receiver/receiver_clock.hpp"
#include "receiver/receiver_options.hpp"
#include "receiver/vector_loop.hpp"
#include "receiver/worker_pool.hpp"
#include "signals/almanac.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::receiver {

// Receives what the engine produces, synchronously, from process(), on the thread that calls process().
// Default: ignore.
class ReceiverObserver {
 public:
  virtual ~ReceiverObserver() = default;
  virtual void on_tracking(const TrackingRecord&) {}
  virtual void on_acquisition(std::int64_t /*snapshot_first_sample*/, const std::vector<AcquisitionResult>&) {}
  virtual void on_observations(const ObservationEpoch&) {}
  virtual void on_fix(const PvtSolution&, const ObservationEpoch&) {}
  // Multi-antenna receivers (num_antennas > 1): every antenna's phase per satellite, after each epoch's fix.
  virtual void on_antenna_phases(const AntennaPhaseEpoch&) {}
};

// Per-satellite counts over the run (index = PRN).
struct SatelliteStats {
  int acquisitions = 0;          // times detected and given a channel
  int losses = 0;                // times its channel lost lock and was released
  double tracked_s = 0.0;        // time phase-locked
  double cn0_sum_dbhz = 0.0;     // over observation epochs
  double tracking_cn0_sum_dbhz = 0.0;  // over tracking records with an estimate (every 20 ms)
  int tracking_cn0_count = 0;
  int observations = 0;          // observation epochs with a pseudorange
  int used_in_fixes = 0;
  bool frame_synced = false;
  bool ephemeris_decoded = false;
};

struct ReceiverStats {
  std::int64_t first_sample = 0;        // first sample processed
  std::int64_t samples_processed = 0;
  std::optional<std::int64_t> first_fix_sample;
  int fixes = 0;
  int observation_epochs = 0;
  int clock_jumps = 0;
  Eigen::Vector3d sum_r_e_m = Eigen::Vector3d::Zero();  // for the mean fix
  double sum_lat_rad = 0.0, sum_lon_rad = 0.0, sum_height_m = 0.0;
  std::array<SatelliteStats, 33> satellites{};
};

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
  const std::optional<PvtSolution>& last_fix() const { return last_fix_; }
  int channels_in_use() const;
  int channels_synchronised() const;
  int threads() const { return pool_.threads(); }
  // The integer correlator's gain from sample scale to int16: 0 until the cold start's snapshot fixes it.
  float i16_gain() const { return i16_gain_; }
  // Ephemerides decoded from the signal (each new set once), and the broadcast Klobuchar/UTC parameters.
  const std::vector<signals::Ephemeris>& decoded_ephemerides() const { return decoded_; }
  // The Klobuchar parameters in use: a default set until the nav file's or the broadcast ones are known
  // (receiver/ionosphere_model.hpp); ionosphere() also tells which, since when, and the known ones alone.
  const signals::KlobucharParameters& klobuchar() const { return ionosphere_.parameters(); }
  const IonosphereModel& ionosphere() const { return ionosphere_; }
  const signals::UtcParameters& utc() const { return utc_; }
  // The latest almanac decoded from any channel, per PRN (index = PRN).
  const std::array<std::optional<signals::Almanac>, 33>& almanacs() const { return almanacs_; }
  const ReceiverOptions& options() const { return options_; }
  // Time phase-locked on a PRN so far (released channels and the one tracking it now).
  double tracked_time_s(int prn) const;
  // PRNs in channels now, and of those the synchronised ones (for progress displays).
  std::vector<int> tracked_prns() const;

 private:
  // A re-acquisition search: what to search, decided on the caller's thread when the snapshot is complete,
  // run by the pool, applied at apply_at.
  struct AcquisitionTask final : BackgroundTask {
    Acquisition* acquisition = nullptr;
    WorkerPool* pool = nullptr;  // set for a search run inline on the caller's thread (the cold start)
    std::span<const std::complex<float>> samples;
    std::vector<std::pair<int, DopplerWindow>> assisted;
    std::vector<int> blind;
    std::vector<AcquisitionResult> results;
    std::int64_t apply_at = 0;
    bool pending = false;
    void run() override;
  };

  void process_master(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  void antenna_phases(std::int64_t sample);
  void begin_snapshot(std::int64_t sample);
  void start_acquisition(std::int64_t end_sample);
  void finish_acquisition(std::int64_t start_sample);
  std::vector<int> missing_prns() const;
  std::optional<signals::Ephemeris> orbit_of(int prn, const signals::GpsTime& t) const;
  std::optional<DopplerWindow> assistance(int prn, const signals::GpsTime& t, const Eigen::Vector3d& r_rx,
                                          bool* below_horizon) const;
  void feed_channels(std::span<const std::complex<float>> samples, std::int64_t first_sample);
  void feed_channel(int slot);
  void collect_navigation(ReceiverChannel& channel);
  void release_lost_channels(std::int64_t sample);
  void observation_epoch(std::int64_t sample);
  void solve(const ObservationEpoch& epoch);
  void vector_epoch(std::int64_t sample);
  // The vector epoch's inputs into in/epoch (epoch.channels, ephemerides etc. still to be pointed at storage).
  void collect_vector_inputs(std::int64_t sample, std::vector<VectorChannelInput>& in, VectorEpochInput& epoch);
  void run_pipelined_vector();    // the pipelined loop's update on its copied inputs
  void apply_pipelined_vector();  // its commands to the channels that are still the ones it saw

  ReceiverOptions options_;
  ReceiverObserver& observer_;
  Acquisition acquisition_;
  std::vector<std::unique_ptr<ReceiverChannel>> channels_;  // nullptr = free
  std::vector<std::vector<TrackingRecord>> records_;        // per channel slot, one block's records (reused)
  SampleBlockView view_;                                     // the block the channels are fed
  WorkerPool pool_;
  AcquisitionTask search_;
  std::size_t blind_cursor_ = 0;  // round robin over prns_ for blind re-acquisitions
  std::size_t unknown_cursor_ = 0;  // the same for PRNs with no orbit known at the low duty cycle (blind_revisit_s)
  std::vector<int> prns_;
  std::array<std::int64_t, 33> lost_at_{};  // sample at which a PRN's channel was last released (lost lock)
  std::array<bool, 33> ever_lost_{};
  std::size_t hidden_cursor_ = 0;        // round robin over prns_ for checks of PRNs predicted below the horizon
  std::int64_t next_hidden_check_ = 0;   // sample from which the next such check may run

  bool started_ = false;
  std::int64_t next_sample_ = 0;  // expected first sample of the next block
  std::int64_t observation_step_ = 0, next_observation_ = 0;
  std::int64_t next_reacquisition_ = 0;
  int record_periods_ = 20;

  std::vector<std::complex<float>> snapshot_;
  std::size_t snapshot_have_ = 0;
  bool snapshot_active_ = false;
  std::int64_t snapshot_first_ = 0;

  std::optional<ReceiverClock> clock_;
  std::vector<signals::Ephemeris> ephemerides_;  // all known: supplied + decoded
  std::vector<signals::Ephemeris> decoded_;
  std::array<std::optional<signals::Almanac>, 33> almanacs_{};
  IonosphereModel ionosphere_;  // Klobuchar in use (default, nav file, broadcast)
  std::shared_ptr<const SuppliedNavigation> supplied_navigation_;  // the nav file's sets: known bits (issue 7)
  signals::UtcParameters utc_;
  std::optional<PvtSolution> last_fix_;
  CarrierSmoothing smoothing_;
  std::array<double, 33> smoothed_m_{};  // this epoch's smoothed pseudorange per PRN
  std::int64_t epoch_index_ = 0;  // observation epochs since the start (for the smoothing's gap test)

  ObservationEpoch epoch_;                    // reused every epoch
  std::vector<ChannelMeasurement> measured_;  // reused
  std::vector<SatelliteMeasurement> pvt_input_;
  ReceiverStats stats_;
  // Multi-antenna: the other antennas' samples of the block being processed, and the phases of each epoch.
  std::array<const std::complex<float>*, kMaxAntennas> antenna_block_{};
  std::int64_t antenna_block_first_ = 0;
  // Integer correlator: the gain to int16 (0 until the cold start's snapshot fixes it) and the int16 copy of
  // the part being fed (I then Q per antenna; grown once to the largest part).
  float i16_gain_ = 0.0f;
  std::vector<std::int16_t> i16_block_;
  PlanarI16 given_i16_{};            // the current block's int16 copy from the caller, if usable
  std::int64_t given_i16_first_ = 0;
  float given_i16_gain_ = 0.0f;
  void convert_part_to_i16(int n);
  AntennaPhaseEpoch antenna_epoch_;
  // Vector tracking (set_vector_loop).
  VectorLoop* vector_loop_ = nullptr;
  std::int64_t vector_step_ = 0, next_vector_ = 0;
  double clock_corrections_s_ = 0.0;
  double fix_clock_corrections_s_ = 0.0;  // clock_corrections_s_ when last_fix_ was solved
  std::vector<VectorChannelInput> vector_in_;
  std::vector<VectorChannelCommand> vector_out_;
  // Pipelined loop: one epoch's inputs, copied (the engine changes ephemerides_, ionosphere_, last_fix_ and the channels
  // while the loop runs), and its commands until the next vector epoch applies them.
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
  bool vector_pipelined_ = false;
  PipelinedVector pipelined_;
};

}  // namespace ultratrack::receiver
