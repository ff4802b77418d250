// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/acquisition_scheduler.hpp"

#include <algorithm>
#include <cmath>

#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver {
namespace {

AcquisitionOptions acquisition_options(const ReceiverOptions& o) {
  AcquisitionOptions a = o.acquisition;
  a.fs_hz = o.fs_hz;
  return a;
}

}  // namespace

AcquisitionScheduler::AcquisitionScheduler(const ReceiverOptions& options, WorkerPool& pool)
    : options_(options), pool_(pool), acquisition_(acquisition_options(options)) {
  prns_ = options_.prns;
  if (prns_.empty())
    for (int prn = 1; prn <= 32; ++prn) prns_.push_back(prn);
  snapshot_.resize(acquisition_.samples_needed());
}

AcquisitionScheduler::~AcquisitionScheduler() {
  if (search_.pending) {
    try {
      pool_.wait(search_);  // the task reads snapshot_ and acquisition_: let it finish first
    } catch (...) {
    }
  }
}

void AcquisitionScheduler::begin_snapshot(std::int64_t sample) {
  snapshot_active_ = true;
  snapshot_have_ = 0;
  snapshot_first_ = sample;
}

void AcquisitionScheduler::add_to_snapshot(std::span<const std::complex<float>> part) {
  std::copy(part.begin(), part.end(), snapshot_.begin() + static_cast<std::ptrdiff_t>(snapshot_have_));
  snapshot_have_ += part.size();
}

void AcquisitionScheduler::channel_lost(int prn, std::int64_t sample) {
  lost_at_[static_cast<std::size_t>(prn)] = sample;
  ever_lost_[static_cast<std::size_t>(prn)] = true;
}

// Whether a PRN is above assisted_elevation_min_deg at r_rx, and its predicted Doppler when the last fix (velocity,
// clock drift) is known. nullopt with *below_horizon false: no orbit known, or no fix.
std::optional<DopplerWindow> AcquisitionScheduler::assistance(int prn, const signals::GpsTime& t,
                                                              const Eigen::Vector3d& r_rx,
                                                              const std::optional<PvtSolution>& last_fix,
                                                              const NavigationStore& navigation,
                                                              bool* below_horizon) const {
  *below_horizon = false;
  const auto eph = navigation.orbit_of(prn, t);
  if (!eph) return std::nullopt;
  const auto sat = signals::satellite_state(*eph, signals::add_seconds(t, -0.075));
  const auto look = signals::look_angles(r_rx, sat.r_e_m);
  if (look.elevation_rad < options_.assisted_elevation_min_deg * signals::kPi / 180.0) {
    *below_horizon = true;
    return std::nullopt;
  }
  if (!last_fix) return std::nullopt;
  const Eigen::Vector3d los = (sat.r_e_m - r_rx).normalized();
  const double range_rate = los.dot(sat.v_e_mps - last_fix->v_e_mps);
  const double c = signals::kSpeedOfLight_mps;
  const double doppler = -(range_rate + last_fix->clock_drift_mps - c * sat.clock_drift_sps) / signals::kL1Wavelength_m;
  return DopplerWindow{doppler, options_.assisted_doppler_half_width_hz};
}

void AcquisitionScheduler::AcquisitionTask::run() {
  results.clear();
  for (const auto& [prn, window] : assisted) results.push_back(acquisition->search(samples, prn, window));
  if (!blind.empty()) {
    auto more = acquisition->search(samples, blind, pool);
    results.insert(results.end(), more.begin(), more.end());
  }
}

// The snapshot is complete at end_sample: decide what to search (from this thread's state only) and start it.
void AcquisitionScheduler::start(std::int64_t end_sample, const std::vector<int>& missing, int channels_in_use,
                                 const std::optional<ReceiverClock>& clock, const std::optional<PvtSolution>& last_fix,
                                 const NavigationStore& navigation, float* i16_gain) {
  snapshot_active_ = false;
  search_.acquisition = &acquisition_;
  search_.samples = std::span<const std::complex<float>>(snapshot_.data(), snapshot_.size());
  search_.assisted.clear();
  search_.blind.clear();
  // Predictions need the time (the receiver clock) and a position (the last fix, else the supplied rough one).
  std::optional<Eigen::Vector3d> where;
  if (last_fix)
    where = last_fix->r_e_m;
  else if (options_.approximate_r_e_m)
    where = Eigen::Vector3d((*options_.approximate_r_e_m)[0], (*options_.approximate_r_e_m)[1],
                            (*options_.approximate_r_e_m)[2]);
  const bool can_predict = where && clock;
  std::vector<int> blind, hidden, unknown;  // unknown: blind for want of an orbit (or of position and time)
  for (int prn : missing) {
    if (!can_predict) {
      blind.push_back(prn);
      unknown.push_back(prn);
      continue;
    }
    bool below = false;
    const signals::GpsTime t = clock->time_at(snapshot_first_);
    const auto window = assistance(prn, t, *where, last_fix, navigation, &below);
    if (below) {
      hidden.push_back(prn);
      continue;
    }
    if (window) {
      search_.assisted.emplace_back(prn, *window);
    } else {
      blind.push_back(prn);
      if (!navigation.orbit_of(prn, t)) unknown.push_back(prn);
    }
  }
  const bool cold = channels_in_use == 0;
  if (cold && options_.integer_correlator && *i16_gain == 0.0f) {
    // Fixed once, from samples fixed by the input alone (the first complete snapshot), whatever the blocks:
    // the noise rms per component goes to 2048, so Gaussian peaks (6 sigma) stay below 16384, where the
    // integer wipe-off cannot saturate, and rounding to int16 adds noise 66 dB below the input's.
    double power = 0.0;
    for (const auto& x : snapshot_) power += std::norm(x);
    const double rms = std::sqrt(power / (2.0 * static_cast<double>(snapshot_.size())));
    if (rms > 0.0 && std::isfinite(rms)) *i16_gain = static_cast<float>(2048.0 / rms);
  }
  // Round robin over the PRN list: the next `limit` PRNs of `from` after the cursor.
  auto round_robin = [this](const std::vector<int>& from, std::size_t limit, std::size_t& cursor) {
    if (limit == 0 || from.size() <= limit) {
      search_.blind.insert(search_.blind.end(), from.begin(), from.end());
      return;
    }
    for (std::size_t k = 0, taken = 0; k < prns_.size() && taken < limit; ++k) {
      const std::size_t i = (cursor + k) % prns_.size();
      if (std::find(from.begin(), from.end(), prns_[i]) == from.end()) continue;
      search_.blind.push_back(prns_[i]);
      ++taken;
      cursor = (i + 1) % prns_.size();
    }
  };
  const auto limit = static_cast<std::size_t>(options_.blind_prns_per_snapshot);
  if (cold) {
    search_.blind = blind;
  } else if (options_.blind_revisit_s > 0.0 && !unknown.empty() && (last_fix || channels_in_use >= 4)) {
    // Low duty cycle for the PRNs nothing is known about: a satellite that rises or re-appears. Those lost
    // lately (a blockage) every time; the others round robin, as many as keep each within blind_revisit_s.
    const std::int64_t window = std::llround(options_.blind_revisit_s * options_.fs_hz);
    std::vector<int> recent, rest;
    for (int prn : unknown) {
      const auto p = static_cast<std::size_t>(prn);
      (ever_lost_[p] && lost_at_[p] > snapshot_first_ - window ? recent : rest).push_back(prn);
    }
    std::erase_if(blind, [&](int prn) { return std::find(unknown.begin(), unknown.end(), prn) != unknown.end(); });
    round_robin(blind, limit, blind_cursor_);  // predicted above the horizon: as before
    search_.blind.insert(search_.blind.end(), recent.begin(), recent.end());
    // Snapshot to snapshot: the snapshot, the latency, then the interval (from the apply sample on).
    const double period_s = static_cast<double>(snapshot_.size()) / options_.fs_hz + options_.reacquisition_latency_s +
                            options_.reacquisition_interval_s;
    const auto need = static_cast<std::size_t>(
        std::max(1.0, std::ceil(static_cast<double>(rest.size()) * period_s / options_.blind_revisit_s)));
    round_robin(rest, limit == 0 ? need : std::min(limit, need), unknown_cursor_);
  } else {
    round_robin(blind, limit, blind_cursor_);
  }
  // Now and then one PRN predicted below the horizon, in case the prediction (or the almanac) is wrong.
  if (!hidden.empty() && snapshot_first_ >= next_hidden_check_) {
    for (std::size_t k = 0; k < prns_.size(); ++k) {
      const std::size_t i = (hidden_cursor_ + k) % prns_.size();
      if (std::find(hidden.begin(), hidden.end(), prns_[i]) == hidden.end()) continue;
      search_.blind.push_back(prns_[i]);
      hidden_cursor_ = (i + 1) % prns_.size();
      break;
    }
    next_hidden_check_ = snapshot_first_ + std::llround(options_.hidden_prn_check_interval_s * options_.fs_hz);
  }
  // Nothing tracks during a cold start, so nothing to overlap: the satellites join at once.
  search_.apply_at = cold ? end_sample : end_sample + std::llround(options_.reacquisition_latency_s * options_.fs_hz);
  search_.pending = true;
  if (cold) {
    // Nothing to overlap with: the search runs now, spread over the whole pool (its result does not depend on
    // the number of threads). finish_acquisition's wait then returns at once.
    search_.pool = &pool_;
    search_.run();
  } else {
    search_.pool = nullptr;  // beside the channels, on one worker
    pool_.start(search_);
  }
}

const std::vector<AcquisitionResult>& AcquisitionScheduler::finish(std::int64_t start_sample) {
  pool_.wait(search_);
  search_.pending = false;
  next_reacquisition_ = start_sample + std::llround(options_.reacquisition_interval_s * options_.fs_hz);
  return search_.results;
}

}  // namespace ultratrack::receiver
