// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/epoch_solver.hpp"

#include <algorithm>
#include <cmath>

#include "receiver/antenna_phase_tracker.hpp"
#include "receiver/loop_filters.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {

EpochSolver::EpochSolver(const ReceiverOptions& options)
    : options_(options),
      smoothing_(
          std::max(1, static_cast<int>(std::lround(options_.smoothing_window_s / options_.observation_interval_s)))) {
  epoch_.observations.reserve(32);
  measured_.reserve(32);
  pvt_input_.reserve(32);
}

void EpochSolver::observation_epoch(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                                    const NavigationStore& navigation, ReceiverStats& run_stats,
                                    ReceiverObserver& observer) {
  ++epoch_index_;
  measured_.clear();
  for (auto& channel : channels)
    if (channel)
      if (auto m = channel->measure()) measured_.push_back(*m);
  if (measured_.empty()) return;
  if (!clock_) {
    // The latest transmit time plus a nominal travel time: the clock starts within ~20 ms of GPS time.
    auto latest = std::max_element(measured_.begin(), measured_.end(), [](const auto& a, const auto& b) {
      return signals::seconds_between(a.tag_time, b.tag_time) + a.since_tag_s - b.since_tag_s < 0.0;
    });
    clock_.emplace(signals::add_seconds(latest->tag_time, latest->since_tag_s + options_.initial_travel_time_s), sample,
                   options_.fs_hz);
  }
  const double since_base = clock_->seconds_since_base(sample);
  epoch_.receive_time = clock_->time_at(sample);
  epoch_.sample_index = sample;
  epoch_.observations.clear();
  for (const ChannelMeasurement& m : measured_) {
    const double travel = signals::seconds_between(clock_->base(), m.tag_time) + since_base - m.since_tag_s;
    // Travel times are 64-90 ms; a clock off by up to ~30 ms before the first fix widens that. Anything
    // outside is a wrong time tag (e.g. a bad week or a bit slip), never a measurement.
    if (!(travel > 0.02 && travel < 0.2)) continue;
    Observation o;
    o.prn = m.prn;
    o.pseudorange_m = signals::kSpeedOfLight_mps * travel;
    o.carrier_phase_cycles = m.carrier_phase_cycles;
    o.doppler_hz = m.doppler_hz;
    o.cn0_dbhz = m.cn0_dbhz;
    o.lock_time_s = m.lock_time_s;
    o.loss_of_lock = m.new_track || m.phase_unlocked;
    o.half_cycle_resolved = true;  // measure() needs frame sync, which fixes the polarity
    epoch_.observations.push_back(o);
    // The code noise expected at this C/N0 (the DLL after bit sync, 20 ms: the larger squaring loss) sets the
    // Hatch filter's jump test (carrier_smoothing.hpp).
    const ScalarTrackingOptions& to = options_.tracking;
    const double code_sigma_m =
        std::isfinite(o.cn0_dbhz) && o.cn0_dbhz > 0.0
            ? dll_thermal_jitter_chips(to.dll_bw_coherent_hz, std::min(1.0, 2.0 * to.early_late_offset_chips), 0.02,
                                       o.cn0_dbhz) *
                  signals::kSpeedOfLight_mps / signals::kCaChipRate_hz
            : 0.0;
    const double smoothed =
        smoothing_.update(o.prn, epoch_index_, o.pseudorange_m, o.carrier_phase_cycles, o.loss_of_lock, code_sigma_m);
    smoothed_m_[static_cast<std::size_t>(o.prn)] = options_.smoothing_window_s > 0.0 ? smoothed : o.pseudorange_m;
    auto& stats = run_stats.satellites[static_cast<std::size_t>(m.prn)];
    ++stats.observations;
    stats.cn0_sum_dbhz += m.cn0_dbhz;
  }
  if (epoch_.observations.empty()) return;
  ++run_stats.observation_epochs;
  observer.on_observations(epoch_);
  solve(epoch_, navigation, run_stats, observer);
  if (options_.num_antennas > 1) antenna_phases(sample, channels, navigation, observer);
}

// Every antenna's phase for the satellites of this epoch, with the line of sight from this epoch's fix.
void EpochSolver::antenna_phases(std::int64_t sample, std::vector<std::unique_ptr<ReceiverChannel>>& channels,
                                 const NavigationStore& navigation, ReceiverObserver& observer) {
  if (!last_fix_ || std::abs(signals::seconds_between(last_fix_->time, epoch_.receive_time)) > 0.05) return;
  antenna_epoch_.receive_time = epoch_.receive_time;
  antenna_epoch_.sample_index = sample;
  antenna_epoch_.master_position_e = last_fix_->r_e_m;
  antenna_epoch_.satellites.clear();
  for (const Observation& o : epoch_.observations) {
    auto channel =
        std::find_if(channels.begin(), channels.end(), [&](const auto& c) { return c && c->prn() == o.prn; });
    if (channel == channels.end() || !(*channel)->antenna_phases()) continue;
    const auto eph =
        signals::select_ephemeris(navigation.ephemerides(), o.prn, epoch_.receive_time, {.include_unhealthy = true});
    if (!eph) continue;
    antenna_epoch_.satellites.push_back(make_antenna_observation(
        *(*channel)->antenna_phases(), o.prn, o.carrier_phase_cycles, o.cn0_dbhz, o.loss_of_lock, o.pseudorange_m, *eph,
        epoch_.receive_time, last_fix_->clock_bias_m, last_fix_->r_e_m, sample, options_.fs_hz));
  }
  observer.on_antenna_phases(antenna_epoch_);
}

void EpochSolver::solve(const ObservationEpoch& epoch, const NavigationStore& navigation, ReceiverStats& run_stats,
                        ReceiverObserver& observer) {
  pvt_input_.clear();
  for (const Observation& o : epoch.observations) {
    const auto eph =
        signals::select_ephemeris(navigation.ephemerides(), o.prn, epoch.receive_time, {.include_unhealthy = true});
    if (!eph) continue;
    SatelliteMeasurement m;
    m.prn = o.prn;
    m.pseudorange_m = smoothed_m_[static_cast<std::size_t>(o.prn)];
    m.doppler_hz = o.doppler_hz;
    m.has_doppler = true;
    m.cn0_dbhz = o.cn0_dbhz;
    m.ephemeris = *eph;
    pvt_input_.push_back(m);
  }
  if (pvt_input_.size() < 4) return;
  PvtOptions pvt = options_.pvt;
  pvt.ionosphere = pvt.ionosphere && navigation.klobuchar().valid;
  const Eigen::Vector3d initial = last_fix_ ? last_fix_->r_e_m : Eigen::Vector3d::Zero();
  PvtSolution fix = solve_pvt(pvt_input_, epoch.receive_time, navigation.klobuchar(), pvt, initial);
  if (!fix.valid) {
    if (fix.gdop > pvt.max_gdop) ++run_stats.fixes_rejected_gdop;
    return;
  }
  if (!run_stats.first_fix_sample) run_stats.first_fix_sample = epoch.sample_index;
  ++run_stats.fixes;
  run_stats.sum_r_e_m += fix.r_e_m;
  run_stats.sum_lat_rad += fix.lat_rad;
  run_stats.sum_lon_rad += fix.lon_rad;
  run_stats.sum_height_m += fix.height_m;
  for (int prn : fix.used_prns) ++run_stats.satellites[static_cast<std::size_t>(prn)].used_in_fixes;
  observer.on_fix(fix, epoch);
  // Keep the receiver clock within clock_jump_threshold_s of GPS time: a jump, as RINEX allows (the
  // pseudoranges of later epochs drop by c * bias; carrier phases are unaffected).
  fix_clock_corrections_s_ = clock_corrections_s_;
  const double bias_s = fix.clock_bias_m / signals::kSpeedOfLight_mps;
  if (std::abs(bias_s) > options_.clock_jump_threshold_s) {
    clock_->correct(bias_s);
    clock_corrections_s_ += bias_s;
    smoothing_.clock_jump(bias_s);
    ++run_stats.clock_jumps;
  }
  last_fix_ = std::move(fix);
}

}  // namespace ultratrack::receiver
