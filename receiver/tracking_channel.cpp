// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/tracking_channel.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

constexpr Int128 kPeriodRaw = static_cast<Int128>(signals::kCaCodeLength_chips) << 52;

Int128 floor_div(Int128 a, Int128 b) {  // b > 0
  Int128 q = a / b;
  if (a % b != 0 && a < 0) --q;
  return q;
}

std::vector<double> tap_offsets(const CorrelatorLayout& l, int prn, int* ve, int* e, int* p, int* lt, int* vl, int* n) {
  std::vector<double> off;
  *e = static_cast<int>(off.size());
  off.push_back(l.early_late_offset_chips);
  *p = static_cast<int>(off.size());
  off.push_back(0.0);
  *lt = static_cast<int>(off.size());
  off.push_back(-l.early_late_offset_chips);
  if (l.very_early_late) {
    *ve = static_cast<int>(off.size());
    off.push_back(l.very_early_late_offset_chips);
    *vl = static_cast<int>(off.size());
    off.push_back(-l.very_early_late_offset_chips);
  }
  if (l.noise) {
    *n = static_cast<int>(off.size());
    off.push_back(noise_tap_offset_chips(prn));
  }
  return off;
}

const ChannelConfig& checked(const ChannelConfig& c) {
  if (c.prn < signals::kMinPrn || c.prn > signals::kMaxPrn)
    throw std::invalid_argument("TrackingChannel: PRN out of 1..32");
  if (!(c.sample_rate_hz > 1.1e6 && c.sample_rate_hz < 1e9))
    throw std::invalid_argument("TrackingChannel: sample rate");
  if (c.num_antennas < 1 || c.num_antennas > kMaxAntennas) throw std::invalid_argument("TrackingChannel: antennas");
  const auto& l = c.layout;
  if (!(l.early_late_offset_chips > 0.0 && l.early_late_offset_chips <= 1.0))
    throw std::invalid_argument("TrackingChannel: early_late_offset_chips outside (0, 1]");
  if (l.very_early_late &&
      !(l.very_early_late_offset_chips > l.early_late_offset_chips && l.very_early_late_offset_chips <= 2.0))
    throw std::invalid_argument("TrackingChannel: very_early_late_offset_chips outside (early_late_offset_chips, 2]");
  return c;
}

}  // namespace

ChannelStart start_from_code_start(std::int64_t first_sample, double samples_to_code_start, double doppler_hz,
                                   double sample_rate_hz) {
  ChannelStart s;
  s.sample_index = first_sample;
  s.carrier_frequency_hz = doppler_hz;
  const double rate = signals::kCaChipRate_hz * (1.0 + doppler_hz / signals::kL1Frequency_hz);
  const double phase = std::fmod(-samples_to_code_start * rate / sample_rate_hz, 1023.0);
  s.code_phase_chips = phase < 0.0 ? phase + 1023.0 : phase;
  if (s.code_phase_chips >= 1023.0) s.code_phase_chips = 0.0;
  return s;
}

TrackingChannel::TrackingChannel(const ChannelConfig& config, const ChannelStart& start)
    : config_(checked(config)),
      engine_(config.prn,
              tap_offsets(config.layout, config.prn, &tap_ve_, &tap_e_, &tap_p_, &tap_l_, &tap_vl_, &tap_n_)) {
  if (!(start.code_phase_chips >= 0.0 && start.code_phase_chips < signals::kCaCodeLength_chips))
    throw std::invalid_argument("TrackingChannel: start code phase outside [0, 1023)");
  NcoCommand cmd;
  cmd.carrier_frequency_hz = start.carrier_frequency_hz;
  cmd.code_rate_chips_per_s =
      start.code_rate_chips_per_s > 0.0
          ? start.code_rate_chips_per_s
          : signals::kCaChipRate_hz * (1.0 + start.carrier_frequency_hz / signals::kL1Frequency_hz);
  apply(cmd);
  code_.set(start.code_phase_chips);
  carrier_.set(start.carrier_phase_cycles);
  nco_sample_ = start.sample_index;
  epoch_.prn = config.prn;
  epoch_.num_antennas = config.num_antennas;
  if (config_.num_antennas > 1 && config_.layout.slaves_prompt_and_noise_only) {
    std::vector<double> slave_offsets{0.0};
    if (config_.layout.noise) {
      slave_tap_n_ = 1;
      slave_offsets.push_back(noise_tap_offset_chips(config_.prn));
    }
    slave_engine_.emplace(config_.prn, slave_offsets);
  }
}

ReplicaState TrackingChannel::replica() const {
  const Int128 raw = code_.raw();
  const Int128 period = floor_div(raw, kPeriodRaw);
  ReplicaState r;
  r.sample_index = nco_sample_;
  r.code_period = static_cast<std::int64_t>(period);
  r.code_phase_chips = static_cast<double>(raw - period * kPeriodRaw) * 0x1p-52;
  r.carrier_phase_cycles = carrier_.value();
  return r;
}

void TrackingChannel::apply(const NcoCommand& cmd) {
  current_ = cmd;
  current_.code_phase_jump_chips = 0.0;
  current_.carrier_phase_jump_cycles = 0.0;
  code_.set_step(cmd.code_rate_chips_per_s / config_.sample_rate_hz);
  carrier_.set_step(cmd.carrier_frequency_hz / config_.sample_rate_hz);
  code_.add(std::clamp(cmd.code_phase_jump_chips, -511.0, 511.0));
  carrier_.add(cmd.carrier_phase_jump_cycles);
}

void TrackingChannel::command(const NcoCommand& cmd) {
  pending_ = cmd;
  has_pending_ = true;
}

void TrackingChannel::set_coherent_periods(int periods, std::int64_t aligned_period) {
  coherent_periods_ = std::clamp(periods, 1, 20);
  aligned_period_ = aligned_period;
}

void TrackingChannel::advance(std::int64_t samples) {
  code_.advance(samples);
  carrier_.advance(samples);
  nco_sample_ += samples;
}

void TrackingChannel::begin_epoch() {
  if (has_pending_) {
    apply(pending_);
    has_pending_ = false;
  }
  const Int128 raw = code_.raw();
  const Int128 period = floor_div(raw + kPeriodRaw / 2, kPeriodRaw);  // nearest period start
  int periods = 1;
  if (coherent_periods_ > 1) {
    const auto p = static_cast<std::int64_t>(period);
    const std::int64_t rem = ((p - aligned_period_) % coherent_periods_ + coherent_periods_) % coherent_periods_;
    if (rem == 0) periods = coherent_periods_;
  }
  epoch_period_start_raw_ = period * kPeriodRaw;
  const Int128 end_raw = (period + periods) * kPeriodRaw;
  const Int128 step = code_.raw_step();
  const auto n = static_cast<std::int64_t>((end_raw - raw + step - 1) / step);

  epoch_.first_sample = nco_sample_;
  epoch_.num_samples = static_cast<int>(n);
  epoch_.first_code_period = static_cast<std::int64_t>(period);
  epoch_.num_code_periods = periods;
  epoch_.code_phase_start_chips = static_cast<double>(raw - epoch_period_start_raw_) * 0x1p-52;
  epoch_.code_rate_chips_per_s = current_.code_rate_chips_per_s;
  epoch_.carrier_phase_start_cycles = carrier_.value();
  epoch_.carrier_frequency_hz = current_.carrier_frequency_hz;
  epoch_mid_ = nco_sample_ + n / 2;
  epoch_end_ = nco_sample_ + n;
  for (auto& half : sums_)
    for (auto& a : half) a.fill({});
  in_epoch_ = true;
}

void TrackingChannel::finish_epoch() {
  const double fs = config_.sample_rate_hz;
  epoch_.integration_time_s = epoch_.num_samples / fs;
  epoch_.code_phase_end_chips = static_cast<double>(code_.raw() - epoch_period_start_raw_) * 0x1p-52;
  epoch_.carrier_phase_end_cycles = carrier_.value();
  auto tap = [](const TapSums& first, const TapSums& second, int index) {
    return index < 0 ? std::complex<float>{} : std::complex<float>(first[index] + second[index]);
  };
  for (int a = 0; a < config_.num_antennas; ++a) {
    const TapSums& s0 = sums_[0][a];
    const TapSums& s1 = sums_[1][a];
    CorrelatorTaps& t = epoch_.antenna[a];
    if (a > 0 && slave_engine_) {
      t = CorrelatorTaps{};
      t.prompt = tap(s0, s1, 0);
      t.noise = tap(s0, s1, slave_tap_n_);
      continue;
    }
    t.very_early = tap(s0, s1, tap_ve_);
    t.early = tap(s0, s1, tap_e_);
    t.prompt = tap(s0, s1, tap_p_);
    t.late = tap(s0, s1, tap_l_);
    t.very_late = tap(s0, s1, tap_vl_);
    t.noise = tap(s0, s1, tap_n_);
  }
  epoch_.prompt_halves = {std::complex<float>(sums_[0][0][tap_p_]), std::complex<float>(sums_[1][0][tap_p_])};
  in_epoch_ = false;
  aligned_ = true;
}

TrackingChannel::FeedResult TrackingChannel::feed(const SampleBlockView& block, int offset) {
  const int remaining = block.num_samples - offset;
  if (remaining <= 0) return {0, false};
  assert(block.num_antennas >= config_.num_antennas);
  const std::int64_t s = block.first_sample + offset;
  if (s < nco_sample_) return {static_cast<int>(std::min<std::int64_t>(remaining, nco_sample_ - s)), false};
  if (in_epoch_ && s > nco_sample_) in_epoch_ = false;  // samples went missing: drop the partial epoch
  if (!in_epoch_) {
    if (s > nco_sample_) {  // samples we never saw: dead-reckon the replica over them
      advance(s - nco_sample_);
      aligned_ = false;
    }
    if (!aligned_) {  // wait for the next code-period start
      const Int128 raw = code_.raw();
      const Int128 next = floor_div(raw + kPeriodRaw - 1, kPeriodRaw) * kPeriodRaw;
      const Int128 step = code_.raw_step();
      const auto k = static_cast<std::int64_t>((next - raw + step - 1) / step);
      if (k > 0) {
        const int m = static_cast<int>(std::min<std::int64_t>(k, remaining));
        advance(m);
        aligned_ = m == k;  // the NCO now sits on the first sample of the new period
        return {m, false};
      }
      aligned_ = true;
    }
    begin_epoch();
  }
  const int half = nco_sample_ < epoch_mid_ ? 0 : 1;
  const std::int64_t limit = half == 0 ? epoch_mid_ : epoch_end_;
  // A segment covers at most one code period so that the engine's code table spans every tap.
  const auto max_per_segment = static_cast<std::int64_t>(kPeriodRaw / code_.raw_step());
  const int m = static_cast<int>(
      std::min<std::int64_t>({static_cast<std::int64_t>(remaining), limit - nco_sample_, max_per_segment}));

  const Int128 raw = code_.raw();
  const Int128 period_start = floor_div(raw, kPeriodRaw) * kPeriodRaw;
  ReplicaSegment rep;
  rep.code_phase_chips = static_cast<double>(raw - period_start) * 0x1p-52;
  rep.code_step_chips = code_.step();
  rep.carrier_phase_q32 = carrier_.fraction_q32();
  rep.carrier_step_q32 = carrier_.step_q32();
  // One pass over the block per engine: the master with every tap, then the slaves with prompt (and noise).
  const auto engine_antennas = static_cast<std::size_t>(slave_engine_ ? 1 : config_.num_antennas);
  const auto slaves = static_cast<std::size_t>(config_.num_antennas - 1);
  if (block.i16_gain > 0.0) {
    std::array<PlanarI16, kMaxAntennas> ptr{};
    for (int a = 0; a < config_.num_antennas; ++a)
      ptr[a] = {block.antenna_i16[a].re + offset, block.antenna_i16[a].im + offset};
    const double scale = 1.0 / block.i16_gain;
    engine_.correlate_i16(std::span(ptr.data(), engine_antennas), m, rep, scale,
                          std::span(sums_[half].data(), engine_antennas));
    if (slave_engine_)
      slave_engine_->correlate_i16(std::span(ptr.data() + 1, slaves), m, rep, scale,
                                   std::span(sums_[half].data() + 1, slaves));
  } else {
    std::array<const std::complex<float>*, kMaxAntennas> ptr{};
    for (int a = 0; a < config_.num_antennas; ++a) ptr[a] = block.antenna[a] + offset;
    engine_.correlate(std::span(ptr.data(), engine_antennas), m, rep, std::span(sums_[half].data(), engine_antennas));
    if (slave_engine_)
      slave_engine_->correlate(std::span(ptr.data() + 1, slaves), m, rep, std::span(sums_[half].data() + 1, slaves));
  }
  advance(m);
  if (nco_sample_ == epoch_end_) {
    finish_epoch();
    return {m, true};
  }
  return {m, false};
}

}  // namespace ultratrack::receiver
