#include "receiver/receiver_engine.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "receiver/antenna_phase_tracker.hpp"
#include "receiver/loop_filters.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver {
namespace {

const ReceiverOptions& checked(const ReceiverOptions& o) {
  const std::string why = o.validate();
  if (!why.empty()) throw std::invalid_argument("ReceiverEngine: " + why);
  return o;
}

AcquisitionOptions acquisition_options(const ReceiverOptions& o) {
  AcquisitionOptions a = o.acquisition;
  a.fs_hz = o.fs_hz;
  return a;
}

bool same_set(const signals::Ephemeris& a, const signals::Ephemeris& b) {
  return a.prn == b.prn && a.iode == b.iode && a.iodc == b.iodc && a.week == b.week && a.toe_s == b.toe_s;
}

}  // namespace

ReceiverEngine::ReceiverEngine(const ReceiverOptions& options, ReceiverObserver& observer)
    : options_(checked(options)),
      observer_(observer),
      acquisition_(acquisition_options(options_)),
      pool_(options_.threads),
      smoothing_(std::max(1, static_cast<int>(std::lround(options_.smoothing_window_s / options_.observation_interval_s)))) {
  channels_.resize(static_cast<std::size_t>(options_.channels));
  prns_ = options_.prns;
  if (prns_.empty())
    for (int prn = 1; prn <= 32; ++prn) prns_.push_back(prn);
  observation_step_ = std::max<std::int64_t>(1, std::llround(options_.observation_interval_s * options_.fs_hz));
  record_periods_ = std::max(1, static_cast<int>(std::lround(options_.tracking_record_interval_s * 1e3)));
  snapshot_.resize(acquisition_.samples_needed());
  records_.resize(channels_.size());
  for (auto& r : records_) r.reserve(64);
  epoch_.observations.reserve(32);
  measured_.reserve(32);
  pvt_input_.reserve(32);
}

ReceiverEngine::~ReceiverEngine() {
  if (search_.pending) {
    try {
      pool_.wait(search_);  // the task reads snapshot_ and acquisition_: let it finish first
    } catch (...) {
    }
  }
}

void ReceiverEngine::add_navigation(const std::vector<signals::Ephemeris>& ephemerides,
                                    const signals::KlobucharParameters& iono, const signals::UtcParameters& utc) {
  ephemerides_.insert(ephemerides_.end(), ephemerides.begin(), ephemerides.end());
  ionosphere_.set(iono, IonosphereSource::kNavigationFile, std::nullopt);
  if (utc.valid) utc_ = utc;
  supplied_navigation_ = std::make_shared<const SuppliedNavigation>(SuppliedNavigation{ephemerides_, iono, utc});
}

int ReceiverEngine::channels_in_use() const {
  return static_cast<int>(std::count_if(channels_.begin(), channels_.end(), [](const auto& c) { return c != nullptr; }));
}

int ReceiverEngine::channels_synchronised() const {
  return static_cast<int>(
      std::count_if(channels_.begin(), channels_.end(), [](const auto& c) { return c && c->synchronised(); }));
}

double ReceiverEngine::tracked_time_s(int prn) const {
  double t = stats_.satellites[static_cast<std::size_t>(prn)].tracked_s;
  for (const auto& c : channels_)
    if (c && c->prn() == prn) t += c->tracked_time_s();
  return t;
}

std::vector<int> ReceiverEngine::tracked_prns() const {
  std::vector<int> out;
  for (const auto& c : channels_)
    if (c) out.push_back(c->prn());
  return out;
}

void ReceiverEngine::begin_snapshot(std::int64_t sample) {
  snapshot_active_ = true;
  snapshot_have_ = 0;
  snapshot_first_ = sample;
}

std::vector<int> ReceiverEngine::missing_prns() const {
  std::vector<int> out;
  for (int prn : prns_) {
    const bool tracked =
        std::any_of(channels_.begin(), channels_.end(), [prn](const auto& c) { return c && c->prn() == prn; });
    if (!tracked) out.push_back(prn);
  }
  return out;
}

// The orbit known for a PRN at t: its broadcast ephemeris, else its decoded almanac (within a week of toa).
std::optional<signals::Ephemeris> ReceiverEngine::orbit_of(int prn, const signals::GpsTime& t) const {
  if (auto eph = signals::select_ephemeris(ephemerides_, prn, t, {.include_unhealthy = true})) return *eph;
  const auto& a = almanacs_[static_cast<std::size_t>(prn)];
  if (a && std::abs(signals::seconds_between(t, signals::GpsTime{a->week, a->toa_s})) < signals::kSecondsPerWeek)
    return signals::almanac_orbit(*a);
  return std::nullopt;
}

// Whether a PRN is above assisted_elevation_min_deg at r_rx, and its predicted Doppler when the last fix (velocity,
// clock drift) is known. nullopt with *below_horizon false: no orbit known, or no fix.
std::optional<DopplerWindow> ReceiverEngine::assistance(int prn, const signals::GpsTime& t, const Eigen::Vector3d& r_rx,
                                                        bool* below_horizon) const {
  *below_horizon = false;
  const auto eph = orbit_of(prn, t);
  if (!eph) return std::nullopt;
  const auto sat = signals::satellite_state(*eph, signals::add_seconds(t, -0.075));
  const auto look = signals::look_angles(r_rx, sat.r_e_m);
  if (look.elevation_rad < options_.assisted_elevation_min_deg * signals::kPi / 180.0) {
    *below_horizon = true;
    return std::nullopt;
  }
  if (!last_fix_) return std::nullopt;
  const Eigen::Vector3d los = (sat.r_e_m - r_rx).normalized();
  const double range_rate = los.dot(sat.v_e_mps - last_fix_->v_e_mps);
  const double c = signals::kSpeedOfLight_mps;
  const double doppler = -(range_rate + last_fix_->clock_drift_mps - c * sat.clock_drift_sps) / signals::kL1Wavelength_m;
  return DopplerWindow{doppler, options_.assisted_doppler_half_width_hz};
}

void ReceiverEngine::AcquisitionTask::run() {
  results.clear();
  for (const auto& [prn, window] : assisted) results.push_back(acquisition->search(samples, prn, window));
  if (!blind.empty()) {
    auto more = acquisition->search(samples, blind, pool);
    results.insert(results.end(), more.begin(), more.end());
  }
}

// The snapshot is complete at end_sample: decide what to search (from this thread's state only) and start it.
void ReceiverEngine::start_acquisition(std::int64_t end_sample) {
  snapshot_active_ = false;
  search_.acquisition = &acquisition_;
  search_.samples = std::span<const std::complex<float>>(snapshot_.data(), snapshot_.size());
  search_.assisted.clear();
  search_.blind.clear();
  // Predictions need the time (the receiver clock) and a position (the last fix, else the supplied rough one).
  std::optional<Eigen::Vector3d> where;
  if (last_fix_)
    where = last_fix_->r_e_m;
  else if (options_.approximate_r_e_m)
    where = Eigen::Vector3d((*options_.approximate_r_e_m)[0], (*options_.approximate_r_e_m)[1],
                            (*options_.approximate_r_e_m)[2]);
  const bool can_predict = where && clock_;
  std::vector<int> blind, hidden, unknown;  // unknown: blind for want of an orbit (or of position and time)
  for (int prn : missing_prns()) {
    if (!can_predict) {
      blind.push_back(prn);
      unknown.push_back(prn);
      continue;
    }
    bool below = false;
    const signals::GpsTime t = clock_->time_at(snapshot_first_);
    const auto window = assistance(prn, t, *where, &below);
    if (below) {
      hidden.push_back(prn);
      continue;
    }
    if (window) {
      search_.assisted.emplace_back(prn, *window);
    } else {
      blind.push_back(prn);
      if (!orbit_of(prn, t)) unknown.push_back(prn);
    }
  }
  const bool cold = channels_in_use() == 0;
  if (cold && options_.integer_correlator && i16_gain_ == 0.0f) {
    // Fixed once, from samples fixed by the input alone (the first complete snapshot), whatever the blocks:
    // the noise rms per component goes to 2048, so Gaussian peaks (6 sigma) stay below 16384, where the
    // integer wipe-off cannot saturate, and rounding to int16 adds noise 66 dB below the input's.
    double power = 0.0;
    for (const auto& x : snapshot_) power += std::norm(x);
    const double rms = std::sqrt(power / (2.0 * static_cast<double>(snapshot_.size())));
    if (rms > 0.0 && std::isfinite(rms)) i16_gain_ = static_cast<float>(2048.0 / rms);
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
  } else if (options_.blind_revisit_s > 0.0 && !unknown.empty() && (last_fix_ || channels_in_use() >= 4)) {
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

void ReceiverEngine::finish_acquisition(std::int64_t start_sample) {
  pool_.wait(search_);
  search_.pending = false;
  next_reacquisition_ = start_sample + std::llround(options_.reacquisition_interval_s * options_.fs_hz);
  const std::vector<AcquisitionResult>& results = search_.results;
  observer_.on_acquisition(snapshot_first_, results);
  std::vector<const AcquisitionResult*> detected;
  for (const auto& r : results)
    if (r.detected) detected.push_back(&r);
  std::sort(detected.begin(), detected.end(), [](auto* a, auto* b) { return a->metric > b->metric; });
  for (const AcquisitionResult* r : detected) {
    auto free = std::find(channels_.begin(), channels_.end(), nullptr);
    if (free == channels_.end()) break;
    const ChannelStart start = channel_start_from_acquisition(*r, snapshot_first_, start_sample, options_.fs_hz);
    *free = std::make_unique<ReceiverChannel>(r->prn, start, options_.fs_hz, options_.tracking, options_.reference_week,
                                              options_.reference_week_is_signal_week, record_periods_,
                                              options_.num_antennas);
    (*free)->supply_navigation(supplied_navigation_);
    ++stats_.satellites[static_cast<std::size_t>(r->prn)].acquisitions;
  }
}

void ReceiverEngine::feed_channel(int slot) {
  auto& channel = channels_[static_cast<std::size_t>(slot)];
  auto& records = records_[static_cast<std::size_t>(slot)];
  records.clear();
  if (!channel) return;
  channel->feed(view_, [&records](const TrackingRecord& r) { records.push_back(r); });
}

void ReceiverEngine::feed_channels(std::span<const std::complex<float>> samples, std::int64_t first_sample) {
  view_.first_sample = first_sample;
  view_.num_samples = static_cast<int>(samples.size());
  view_.num_antennas = options_.num_antennas;
  view_.antenna[0] = samples.data();
  for (int a = 1; a < options_.num_antennas; ++a)
    view_.antenna[static_cast<std::size_t>(a)] = antenna_block_[static_cast<std::size_t>(a)] + (first_sample - antenna_block_first_);
  view_.i16_gain = i16_gain_;
  if (i16_gain_ > 0.0f) {
    if (given_i16_.re && given_i16_gain_ == i16_gain_) {
      const std::int64_t offset = first_sample - given_i16_first_;
      view_.antenna_i16[0] = {given_i16_.re + offset, given_i16_.im + offset};
    } else {
      convert_part_to_i16(view_.num_samples);
    }
  }
  // Channels are independent given the block: each job touches only its own channel and record buffer. A
  // pipelined vector loop's update is job 0 (the caller takes it first): it reads only its copied inputs.
  const int loop_job = pipelined_.queued ? 1 : 0;
  auto job = [this, loop_job](int i) {
    if (i < loop_job)
      run_pipelined_vector();
    else
      feed_channel(i - loop_job);
  };
  pool_.parallel_for(static_cast<int>(channels_.size()) + loop_job, job);
  // Everything shared, in channel order, on this thread: the same sequence as one thread feeding them in turn.
  for (std::size_t slot = 0; slot < channels_.size(); ++slot) {
    if (!channels_[slot]) continue;
    for (const TrackingRecord& r : records_[slot]) {
      if (!std::isnan(r.cn0_dbhz) && r.state != TrackingState::kLost) {
        auto& stats = stats_.satellites[static_cast<std::size_t>(r.prn)];
        stats.tracking_cn0_sum_dbhz += r.cn0_dbhz;
        ++stats.tracking_cn0_count;
      }
      observer_.on_tracking(r);
    }
    collect_navigation(*channels_[slot]);
  }
}

// Once per part, on this thread, shared read-only by every channel (5 Gsamples/s: ~1 % of a channel's work).
void ReceiverEngine::convert_part_to_i16(int n) {
  const auto need = static_cast<std::size_t>(2 * n * options_.num_antennas);
  if (i16_block_.size() < need) i16_block_.resize(need);  // only while parts grow
  for (int a = 0; a < options_.num_antennas; ++a) {
    std::int16_t* re = i16_block_.data() + static_cast<std::ptrdiff_t>(2 * a * n);
    std::int16_t* im = re + n;
    convert_to_planar_i16(view_.antenna[static_cast<std::size_t>(a)], n, i16_gain_, re, im);
    view_.antenna_i16[static_cast<std::size_t>(a)] = {re, im};
  }
}

void ReceiverEngine::collect_navigation(ReceiverChannel& channel) {
  NavigationDataChannel& nav = channel.navigation();
  auto& stats = stats_.satellites[static_cast<std::size_t>(channel.prn())];
  if (nav.synchronised()) stats.frame_synced = true;
  const auto& decoder = nav.decoder();
  // Almanacs of every PRN, from any channel (a page every 30 s); the latest reference time wins.
  for (std::size_t prn = 1; prn < almanacs_.size(); ++prn) {
    const auto& a = decoder.almanacs()[prn];
    auto& mine = almanacs_[prn];
    if (a && (!mine || mine->week != a->week || mine->toa_s != a->toa_s)) mine = a;
  }
  if (!nav.take_new_ephemeris()) return;
  ionosphere_.set(decoder.klobuchar(), IonosphereSource::kBroadcast, view_.first_sample + view_.num_samples);
  if (decoder.utc().valid) utc_ = decoder.utc();
  if (!decoder.ephemeris()) return;
  const signals::Ephemeris& eph = *decoder.ephemeris();
  stats.ephemeris_decoded = true;
  if (std::none_of(decoded_.begin(), decoded_.end(), [&](const auto& e) { return same_set(e, eph); }))
    decoded_.push_back(eph);
  if (std::none_of(ephemerides_.begin(), ephemerides_.end(), [&](const auto& e) { return same_set(e, eph); }))
    ephemerides_.push_back(eph);
}

void ReceiverEngine::release_lost_channels(std::int64_t sample) {
  for (auto& channel : channels_) {
    if (!channel || !channel->lost()) continue;
    auto& stats = stats_.satellites[static_cast<std::size_t>(channel->prn())];
    ++stats.losses;
    stats.tracked_s += channel->tracked_time_s();
    lost_at_[static_cast<std::size_t>(channel->prn())] = sample;
    ever_lost_[static_cast<std::size_t>(channel->prn())] = true;
    channel.reset();
  }
}

void ReceiverEngine::process(std::span<const std::complex<float>> samples, std::int64_t first_sample) {
  if (options_.num_antennas != 1) throw std::invalid_argument("ReceiverEngine: one span per antenna is needed");
  process_master(samples, first_sample);
}

void ReceiverEngine::process(std::span<const std::complex<float>> samples, std::int64_t first_sample, PlanarI16 i16,
                             float i16_gain) {
  if (options_.num_antennas != 1) throw std::invalid_argument("ReceiverEngine: one span per antenna is needed");
  // The gain may be fixed inside this call (the cold start): only a copy made at that gain is used, so the
  // channels see the same int16 values whoever converted them.
  if (i16_gain > 0.0f && i16.re && i16.im) {
    given_i16_ = i16;
    given_i16_first_ = first_sample;
    given_i16_gain_ = i16_gain;
  }
  try {
    process_master(samples, first_sample);
  } catch (...) {
    given_i16_ = {};
    throw;
  }
  given_i16_ = {};
}

void ReceiverEngine::process(std::span<const std::span<const std::complex<float>>> antennas, std::int64_t first_sample) {
  if (antennas.size() != static_cast<std::size_t>(options_.num_antennas))
    throw std::invalid_argument("ReceiverEngine: one span per antenna is needed");
  for (const auto& a : antennas)
    if (a.size() != antennas[0].size()) throw std::invalid_argument("ReceiverEngine: antenna blocks differ in size");
  for (std::size_t a = 0; a < antennas.size(); ++a) antenna_block_[a] = antennas[a].data();
  antenna_block_first_ = first_sample;
  process_master(antennas[0], first_sample);
}

void ReceiverEngine::process_master(std::span<const std::complex<float>> samples, std::int64_t first_sample) {
  if (!started_) {
    started_ = true;
    stats_.first_sample = first_sample;
    next_sample_ = first_sample;
    next_observation_ = first_sample + observation_step_;
    begin_snapshot(first_sample);
  }
  if (first_sample != next_sample_ && snapshot_active_) begin_snapshot(first_sample);  // a gap: restart it
  const std::int64_t end = first_sample + static_cast<std::int64_t>(samples.size());
  std::int64_t s = first_sample;
  while (s < end) {
    if (search_.pending && search_.apply_at <= s) finish_acquisition(s);  // only after a gap in the samples
    std::int64_t stop = std::min(end, next_observation_);
    if (vector_loop_) {
      if (next_vector_ <= s) next_vector_ += ((s - next_vector_) / vector_step_ + 1) * vector_step_;  // start, gaps
      stop = std::min(stop, next_vector_);
    }
    if (snapshot_active_) stop = std::min(stop, s + static_cast<std::int64_t>(snapshot_.size() - snapshot_have_));
    if (search_.pending) stop = std::min(stop, search_.apply_at);
    const auto part = samples.subspan(static_cast<std::size_t>(s - first_sample), static_cast<std::size_t>(stop - s));
    if (snapshot_active_) {
      std::copy(part.begin(), part.end(), snapshot_.begin() + static_cast<std::ptrdiff_t>(snapshot_have_));
      snapshot_have_ += part.size();
    }
    feed_channels(part, s);
    s = stop;
    if (snapshot_active_ && snapshot_have_ == snapshot_.size()) start_acquisition(s);
    if (search_.pending && search_.apply_at == s) finish_acquisition(s);
    if (vector_loop_ && s == next_vector_) {
      vector_epoch(s);
      next_vector_ += vector_step_;
    }
    if (s == next_observation_) {
      observation_epoch(s);
      next_observation_ += observation_step_;
    }
    release_lost_channels(s);
    if (!snapshot_active_ && !search_.pending && s >= next_reacquisition_ &&
        channels_in_use() < options_.channels && !missing_prns().empty())
      begin_snapshot(s);
  }
  next_sample_ = end;
  stats_.samples_processed += static_cast<std::int64_t>(samples.size());
}

void ReceiverEngine::observation_epoch(std::int64_t sample) {
  ++epoch_index_;
  measured_.clear();
  for (auto& channel : channels_)
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
            ? dll_thermal_jitter_chips(to.dll_bw_coherent_hz, std::min(1.0, 2.0 * to.early_late_offset_chips), 0.02, o.cn0_dbhz) *
                  signals::kSpeedOfLight_mps / signals::kCaChipRate_hz
            : 0.0;
    const double smoothed =
        smoothing_.update(o.prn, epoch_index_, o.pseudorange_m, o.carrier_phase_cycles, o.loss_of_lock, code_sigma_m);
    smoothed_m_[static_cast<std::size_t>(o.prn)] = options_.smoothing_window_s > 0.0 ? smoothed : o.pseudorange_m;
    auto& stats = stats_.satellites[static_cast<std::size_t>(m.prn)];
    ++stats.observations;
    stats.cn0_sum_dbhz += m.cn0_dbhz;
  }
  if (epoch_.observations.empty()) return;
  ++stats_.observation_epochs;
  observer_.on_observations(epoch_);
  solve(epoch_);
  if (options_.num_antennas > 1) antenna_phases(sample);
}

// Every antenna's phase for the satellites of this epoch, with the line of sight from this epoch's fix.
void ReceiverEngine::antenna_phases(std::int64_t sample) {
  if (!last_fix_ || std::abs(signals::seconds_between(last_fix_->time, epoch_.receive_time)) > 0.05) return;
  antenna_epoch_.receive_time = epoch_.receive_time;
  antenna_epoch_.sample_index = sample;
  antenna_epoch_.master_position_e = last_fix_->r_e_m;
  antenna_epoch_.satellites.clear();
  for (const Observation& o : epoch_.observations) {
    auto channel = std::find_if(channels_.begin(), channels_.end(), [&](const auto& c) { return c && c->prn() == o.prn; });
    if (channel == channels_.end() || !(*channel)->antenna_phases()) continue;
    const auto eph = signals::select_ephemeris(ephemerides_, o.prn, epoch_.receive_time, {.include_unhealthy = true});
    if (!eph) continue;
    antenna_epoch_.satellites.push_back(make_antenna_observation(
        *(*channel)->antenna_phases(), o.prn, o.carrier_phase_cycles, o.cn0_dbhz, o.loss_of_lock, o.pseudorange_m, *eph,
        epoch_.receive_time, last_fix_->clock_bias_m, last_fix_->r_e_m, sample, options_.fs_hz));
  }
  observer_.on_antenna_phases(antenna_epoch_);
}

void ReceiverEngine::solve(const ObservationEpoch& epoch) {
  pvt_input_.clear();
  for (const Observation& o : epoch.observations) {
    const auto eph = signals::select_ephemeris(ephemerides_, o.prn, epoch.receive_time, {.include_unhealthy = true});
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
  const Eigen::Vector3d initial = last_fix_ ? last_fix_->r_e_m : Eigen::Vector3d::Zero();
  PvtSolution fix = solve_pvt(pvt_input_, epoch.receive_time, ionosphere_.parameters(), pvt, initial);
  if (!fix.valid) return;
  if (!stats_.first_fix_sample) stats_.first_fix_sample = epoch.sample_index;
  ++stats_.fixes;
  stats_.sum_r_e_m += fix.r_e_m;
  stats_.sum_lat_rad += fix.lat_rad;
  stats_.sum_lon_rad += fix.lon_rad;
  stats_.sum_height_m += fix.height_m;
  for (int prn : fix.used_prns) ++stats_.satellites[static_cast<std::size_t>(prn)].used_in_fixes;
  observer_.on_fix(fix, epoch);
  // Keep the receiver clock within clock_jump_threshold_s of GPS time: a jump, as RINEX allows (the
  // pseudoranges of later epochs drop by c * bias; carrier phases are unaffected).
  fix_clock_corrections_s_ = clock_corrections_s_;
  const double bias_s = fix.clock_bias_m / signals::kSpeedOfLight_mps;
  if (std::abs(bias_s) > options_.clock_jump_threshold_s) {
    clock_->correct(bias_s);
    clock_corrections_s_ += bias_s;
    smoothing_.clock_jump(bias_s);
    ++stats_.clock_jumps;
  }
  last_fix_ = std::move(fix);
}

void ReceiverEngine::set_vector_loop(VectorLoop* loop, double interval_s, bool pipelined) {
  if (!(interval_s >= 0.001 && interval_s <= 1.0)) throw std::invalid_argument("ReceiverEngine: vector interval outside [0.001, 1] s");
  if (!loop)
    for (auto& channel : channels_)
      if (channel) channel->set_vector_command({});
  vector_loop_ = loop;
  vector_pipelined_ = pipelined;
  pipelined_.queued = pipelined_.answered = false;
  vector_step_ = std::max<std::int64_t>(1, std::llround(interval_s * options_.fs_hz));
  next_vector_ = (started_ ? next_sample_ : stats_.first_sample) + vector_step_;
}

void ReceiverEngine::finish_vector_loop() {
  if (vector_loop_ && pipelined_.queued) run_pipelined_vector();
  pipelined_.answered = false;
}

void ReceiverEngine::collect_vector_inputs(std::int64_t sample, std::vector<VectorChannelInput>& in,
                                           VectorEpochInput& epoch) {
  in.clear();
  for (std::size_t slot = 0; slot < channels_.size(); ++slot) {
    auto& channel = channels_[slot];
    if (!channel) continue;
    if (clock_) {
      in.push_back(channel->vector_input(*clock_, static_cast<int>(slot)));
    } else {  // no receive time yet: nothing can be measured
      VectorChannelInput c;
      c.slot = static_cast<int>(slot);
      c.prn = channel->prn();
      in.push_back(c);
    }
  }
  epoch = VectorEpochInput{};
  epoch.sample = sample;
  epoch.command_sample = vector_pipelined_ ? sample + vector_step_ : sample;
  epoch.fs_hz = options_.fs_hz;
  if (clock_) epoch.receive_time = clock_->time_at(sample);
  epoch.clock_corrections_s = clock_corrections_s_;
  epoch.last_fix_clock_corrections_s = fix_clock_corrections_s_;
}

// The vector loop's turn: every channel's state and latest measurements in slot order, its commands back.
void ReceiverEngine::vector_epoch(std::int64_t sample) {
  if (vector_pipelined_) {
    if (pipelined_.queued) run_pipelined_vector();  // not run yet (no block since): in turn
    apply_pipelined_vector();
    PipelinedVector& p = pipelined_;
    collect_vector_inputs(sample, p.in, p.epoch);
    p.ephemerides = ephemerides_;
    p.iono = ionosphere_.parameters();
    p.last_fix = last_fix_;
    p.epoch.ephemerides = &p.ephemerides;
    p.epoch.iono = &p.iono;
    p.epoch.last_fix = p.last_fix ? &*p.last_fix : nullptr;
    p.epoch.channels = p.in;
    p.out.assign(p.in.size(), VectorChannelCommand{});
    p.queued = clock_.has_value();
    return;
  }
  VectorEpochInput epoch;
  collect_vector_inputs(sample, vector_in_, epoch);
  vector_out_.assign(vector_in_.size(), VectorChannelCommand{});
  epoch.ephemerides = &ephemerides_;
  epoch.iono = &ionosphere_.parameters();
  epoch.last_fix = last_fix_ ? &*last_fix_ : nullptr;
  epoch.channels = vector_in_;
  if (clock_) vector_loop_->update(epoch, vector_out_);
  for (std::size_t i = 0; i < vector_in_.size(); ++i) {
    const bool ok = vector_in_[i].synchronised;
    channels_[static_cast<std::size_t>(vector_in_[i].slot)]->set_vector_command(ok ? vector_out_[i] : VectorChannelCommand{});
  }
}

void ReceiverEngine::run_pipelined_vector() {
  pipelined_.queued = false;
  vector_loop_->update(pipelined_.epoch, pipelined_.out);
  pipelined_.answered = true;
}

// A channel released since the inputs were copied gets nothing; a new one in its slot (another PRN, or the same
// PRN re-acquired: not bit-synced, so ReceiverChannel::set_vector_command drops a vector command) stays scalar.
void ReceiverEngine::apply_pipelined_vector() {
  if (!pipelined_.answered) return;
  pipelined_.answered = false;
  for (std::size_t i = 0; i < pipelined_.in.size(); ++i) {
    const VectorChannelInput& in = pipelined_.in[i];
    auto& channel = channels_[static_cast<std::size_t>(in.slot)];
    if (!channel || channel->prn() != in.prn) continue;
    channel->set_vector_command(in.synchronised ? pipelined_.out[i] : VectorChannelCommand{});
  }
}

}  // namespace ultratrack::receiver
