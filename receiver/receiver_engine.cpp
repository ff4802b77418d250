// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/receiver_engine.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "io/why_invalid.hpp"

namespace ultratrack::receiver {
namespace {

const ReceiverOptions& checked(const ReceiverOptions& o) {
  const std::string why = io::why_invalid(o);
  if (!why.empty()) throw std::invalid_argument("ReceiverEngine: " + why);
  return o;
}

}  // namespace

ReceiverEngine::ReceiverEngine(const ReceiverOptions& options, ReceiverObserver& observer)
    : options_(checked(options)),
      observer_(observer),
      pool_(options_.threads),
      acquisition_(options_, pool_),
      solver_(options_) {
  channels_.resize(static_cast<std::size_t>(options_.channels));
  observation_step_ = std::max<std::int64_t>(1, std::llround(options_.observation_interval_s * options_.fs_hz));
  record_periods_ = std::max(1, static_cast<int>(std::lround(options_.tracking_record_interval_s * 1e3)));
  records_.resize(channels_.size());
  for (auto& r : records_) r.reserve(64);
}

ReceiverEngine::~ReceiverEngine() = default;

void ReceiverEngine::add_navigation(const std::vector<signals::Ephemeris>& ephemerides,
                                    const signals::KlobucharParameters& iono, const signals::UtcParameters& utc) {
  navigation_.add_supplied(ephemerides, iono, utc);
}

int ReceiverEngine::channels_in_use() const {
  return static_cast<int>(
      std::count_if(channels_.begin(), channels_.end(), [](const auto& c) { return c != nullptr; }));
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

NavBitCounts ReceiverEngine::nav_bit_counts(int prn) const {
  NavBitCounts c = stats_.satellites[static_cast<std::size_t>(prn)].nav_bits;
  for (const auto& ch : channels_)
    if (ch && ch->prn() == prn) c += ch->nav_bit_counts();
  return c;
}

std::vector<int> ReceiverEngine::tracked_prns() const {
  std::vector<int> out;
  for (const auto& c : channels_)
    if (c) out.push_back(c->prn());
  return out;
}

std::vector<int> ReceiverEngine::missing_prns() const {
  std::vector<int> out;
  for (int prn : acquisition_.prns()) {
    const bool tracked =
        std::any_of(channels_.begin(), channels_.end(), [prn](const auto& c) { return c && c->prn() == prn; });
    if (!tracked) out.push_back(prn);
  }
  return out;
}

void ReceiverEngine::start_acquisition(std::int64_t end_sample) {
  acquisition_.start(end_sample, missing_prns(), channels_in_use(), solver_.clock(), solver_.last_fix(), navigation_,
                     &i16_gain_);
}

void ReceiverEngine::finish_acquisition(std::int64_t start_sample) {
  const std::vector<AcquisitionResult>& results = acquisition_.finish(start_sample);
  observer_.on_acquisition(acquisition_.snapshot_first(), results);
  std::vector<const AcquisitionResult*> detected;
  for (const auto& r : results)
    if (r.detected) detected.push_back(&r);
  std::sort(detected.begin(), detected.end(), [](auto* a, auto* b) { return a->metric > b->metric; });
  for (const AcquisitionResult* r : detected) {
    auto free = std::find(channels_.begin(), channels_.end(), nullptr);
    if (free == channels_.end()) break;
    const ChannelStart start =
        channel_start_from_acquisition(*r, acquisition_.snapshot_first(), start_sample, options_.fs_hz);
    *free = std::make_unique<ReceiverChannel>(r->prn, start, options_.fs_hz, options_.tracking, options_.reference_week,
                                              options_.reference_week_is_signal_week, record_periods_,
                                              options_.num_antennas);
    (*free)->supply_navigation(navigation_.supplied(), options_.nav_bits);
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
    view_.antenna[static_cast<std::size_t>(a)] =
        antenna_block_[static_cast<std::size_t>(a)] + (first_sample - antenna_block_first_);
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
  const int loop_job = vector_.queued() ? 1 : 0;
  auto job = [this, loop_job](int i) {
    if (i < loop_job)
      vector_.run_pipelined();
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
    ReceiverChannel& channel = *channels_[slot];
    navigation_.collect(channel.navigation(), stats_.satellites[static_cast<std::size_t>(channel.prn())],
                        view_.first_sample + view_.num_samples);
  }
}

// Once per part, on this thread, shared read-only by every channel (5 Gsamples/s: ~1 % of a channel's work).
void ReceiverEngine::convert_part_to_i16(int n) {
  const auto need = 2 * static_cast<std::size_t>(n) * static_cast<std::size_t>(options_.num_antennas);
  if (i16_block_.size() < need) i16_block_.resize(need);  // only while parts grow
  for (int a = 0; a < options_.num_antennas; ++a) {
    std::int16_t* re = i16_block_.data() + static_cast<std::ptrdiff_t>(2 * a * n);
    std::int16_t* im = re + n;
    convert_to_planar_i16(view_.antenna[static_cast<std::size_t>(a)], n, i16_gain_, re, im);
    view_.antenna_i16[static_cast<std::size_t>(a)] = {re, im};
  }
}

void ReceiverEngine::release_lost_channels(std::int64_t sample) {
  for (auto& channel : channels_) {
    if (!channel || !channel->lost()) continue;
    auto& stats = stats_.satellites[static_cast<std::size_t>(channel->prn())];
    ++stats.losses;
    stats.tracked_s += channel->tracked_time_s();
    stats.nav_bits += channel->nav_bit_counts();
    acquisition_.channel_lost(channel->prn(), sample);
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

void ReceiverEngine::process(std::span<const std::span<const std::complex<float>>> antennas,
                             std::int64_t first_sample) {
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
    acquisition_.begin_snapshot(first_sample);
  }
  // a gap: restart the snapshot
  if (first_sample != next_sample_ && acquisition_.snapshot_active()) acquisition_.begin_snapshot(first_sample);
  const std::int64_t end = first_sample + static_cast<std::int64_t>(samples.size());
  std::int64_t s = first_sample;
  while (s < end) {
    if (acquisition_.pending() && acquisition_.apply_at() <= s)
      finish_acquisition(s);  // only after a gap in the samples
    std::int64_t stop = std::min(end, next_observation_);
    if (vector_.attached()) stop = std::min(stop, vector_.next_epoch_after(s));
    if (acquisition_.snapshot_active()) stop = std::min(stop, s + acquisition_.snapshot_missing());
    if (acquisition_.pending()) stop = std::min(stop, acquisition_.apply_at());
    const auto part = samples.subspan(static_cast<std::size_t>(s - first_sample), static_cast<std::size_t>(stop - s));
    if (acquisition_.snapshot_active()) acquisition_.add_to_snapshot(part);
    feed_channels(part, s);
    s = stop;
    if (acquisition_.snapshot_complete()) start_acquisition(s);
    if (acquisition_.pending() && acquisition_.apply_at() == s) finish_acquisition(s);
    if (vector_.attached() && s == vector_.next_epoch()) vector_.epoch(s, channels_, solver_, navigation_);
    if (s == next_observation_) {
      solver_.observation_epoch(s, channels_, navigation_, stats_, observer_);
      next_observation_ += observation_step_;
    }
    release_lost_channels(s);
    if (!acquisition_.snapshot_active() && !acquisition_.pending() && acquisition_.reacquisition_due(s) &&
        channels_in_use() < options_.channels && !missing_prns().empty())
      acquisition_.begin_snapshot(s);
  }
  next_sample_ = end;
  stats_.samples_processed += static_cast<std::int64_t>(samples.size());
}

void ReceiverEngine::set_vector_loop(VectorLoop* loop, double interval_s, bool pipelined) {
  vector_.set(loop, interval_s, pipelined, options_.fs_hz, started_ ? next_sample_ : stats_.first_sample, channels_);
}

void ReceiverEngine::finish_vector_loop() { vector_.finish(); }

}  // namespace ultratrack::receiver
