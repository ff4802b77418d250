// SPDX-License-Identifier: GPL-3.0-or-later
// When and what the receiver searches: a snapshot of the first samples (and of later ones for re-acquisition),
// the PRNs to search on it (assisted by an ephemeris or almanac and the last fix: a Doppler window; blind when
// nothing is known; predicted below the horizon only now and then; those with no orbit known at a low duty
// cycle once 4 are in channels: ReceiverOptions::blind_revisit_s), the search itself (inline at the cold start,
// else in the background on one worker, its satellites joining at a fixed later sample) and the next
// re-acquisition's time. The engine allocates the detected satellites to channels. Units: samples, seconds, Hz.
#pragma once

#include <Eigen/Core>
#include <array>
#include <complex>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "receiver/acquisition.hpp"
#include "receiver/navigation_store.hpp"
#include "receiver/pvt.hpp"
#include "receiver/receiver_clock.hpp"
#include "receiver/receiver_options.hpp"
#include "receiver/worker_pool.hpp"

namespace ultratrack::receiver {

class AcquisitionScheduler final {
 public:
  // options valid; the pool must outlive the scheduler (its destructor waits for a background search).
  AcquisitionScheduler(const ReceiverOptions& options, WorkerPool& pool);
  ~AcquisitionScheduler();
  AcquisitionScheduler(const AcquisitionScheduler&) = delete;
  AcquisitionScheduler& operator=(const AcquisitionScheduler&) = delete;

  // The PRNs to look for (ReceiverOptions::prns, else 1-32), in search order.
  const std::vector<int>& prns() const { return prns_; }

  // The snapshot: started at a sample, filled from the blocks (contiguous), complete at snapshot_size() samples.
  void begin_snapshot(std::int64_t sample);
  bool snapshot_active() const { return snapshot_active_; }
  std::int64_t snapshot_first() const { return snapshot_first_; }
  // Samples the active snapshot still needs.
  std::int64_t snapshot_missing() const { return static_cast<std::int64_t>(snapshot_.size() - snapshot_have_); }
  void add_to_snapshot(std::span<const std::complex<float>> part);
  bool snapshot_complete() const { return snapshot_active_ && snapshot_have_ == snapshot_.size(); }

  // The snapshot is complete at end_sample: decide what to search among `missing` (the PRNs in no channel) from
  // the caller thread's state (clock, last fix, orbits; channels_in_use 0: the cold start) and start it. At the
  // cold start with the integer correlator, *i16_gain (0: not fixed yet) is fixed from the snapshot.
  void start(std::int64_t end_sample, const std::vector<int>& missing, int channels_in_use,
             const std::optional<ReceiverClock>& clock, const std::optional<PvtSolution>& last_fix,
             const NavigationStore& navigation, float* i16_gain);
  // A search started and not finished; its satellites join at apply_at().
  bool pending() const { return search_.pending; }
  std::int64_t apply_at() const { return search_.apply_at; }
  // Waits for the search and returns its results; the next re-acquisition from start_sample on.
  const std::vector<AcquisitionResult>& finish(std::int64_t start_sample);
  // A new snapshot may start at sample (the re-acquisition interval has passed).
  bool reacquisition_due(std::int64_t sample) const { return sample >= next_reacquisition_; }
  // A PRN's channel was released at sample (lost lock): searched every time for a while (blind_revisit_s).
  void channel_lost(int prn, std::int64_t sample);

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

  std::optional<DopplerWindow> assistance(int prn, const signals::GpsTime& t, const Eigen::Vector3d& r_rx,
                                          const std::optional<PvtSolution>& last_fix, const NavigationStore& navigation,
                                          bool* below_horizon) const;

  ReceiverOptions options_;
  WorkerPool& pool_;
  Acquisition acquisition_;
  AcquisitionTask search_;
  std::size_t blind_cursor_ = 0;    // round robin over prns_ for blind re-acquisitions
  std::size_t unknown_cursor_ = 0;  // the same for PRNs with no orbit known at the low duty cycle (blind_revisit_s)
  std::vector<int> prns_;
  std::array<std::int64_t, 33> lost_at_{};  // sample at which a PRN's channel was last released (lost lock)
  std::array<bool, 33> ever_lost_{};
  std::size_t hidden_cursor_ = 0;       // round robin over prns_ for checks of PRNs predicted below the horizon
  std::int64_t next_hidden_check_ = 0;  // sample from which the next such check may run
  std::int64_t next_reacquisition_ = 0;

  std::vector<std::complex<float>> snapshot_;
  std::size_t snapshot_have_ = 0;
  bool snapshot_active_ = false;
  std::int64_t snapshot_first_ = 0;
};

}  // namespace ultratrack::receiver
