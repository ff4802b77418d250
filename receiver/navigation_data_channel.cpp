// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/navigation_data_channel.hpp"

#include <algorithm>
#include <cmath>

#include "signals/lnav_parity.hpp"

namespace ultratrack::receiver {

NavigationDataChannel::NavigationDataChannel(int prn, int reference_week) : decoder_(prn, reference_week) {}

void NavigationDataChannel::reset() {
  frame_sync_.reset();
  tag_.reset();
  holding_ = false;
  word_fill_ = 0;
}

void NavigationDataChannel::read_word(float soft, std::int64_t first_code_period) {
  if (!tag_) {
    word_fill_ = 0;
    return;
  }
  constexpr std::int64_t kBitsPerWeek = 30240000;  // 604800 s / 20 ms
  // The bit's middle in GPS time (robust to the tag's code-period arithmetic in double).
  const signals::GpsTime mid = signals::add_seconds(
      tag_->transmit_time, 1e-3 * static_cast<double>(first_code_period - tag_->code_period) + 0.01);
  const std::int64_t n =
      static_cast<std::int64_t>(mid.week) * kBitsPerWeek + static_cast<std::int64_t>(std::floor(mid.tow_s / 0.02));
  word_fill_ = n == last_bit_number_ + 1 ? std::min(word_fill_ + 1, 32) : 1;
  last_bit_number_ = n;
  std::copy(word_bits_.begin() + 1, word_bits_.end(), word_bits_.begin());
  word_bits_.back() = soft < 0.0f ? 1 : 0;
  const std::int64_t in_week = n % kBitsPerWeek;
  if (in_week % 30 != 29 || word_fill_ < 32) return;
  // Parity is polarity-blind: an inverted word with inverted D29*, D30* checks and gives the same data.
  const auto data =
      signals::check_word(std::span<const std::uint8_t, 30>(word_bits_.data() + 2, 30), word_bits_[0], word_bits_[1]);
  if (!data) return;
  const std::int64_t subframe_bit = in_week - in_week % 300;
  const signals::GpsTime start{static_cast<int>(n / kBitsPerWeek), 0.02 * static_cast<double>(subframe_bit)};
  // D29*, D30* as transmitted: the received pair when upright; the word's own polarity is in its parity.
  const int invert = polarity_ < 0 ? 1 : 0;
  predictor_.add_word(start, static_cast<int>(in_week % 300 / 30), *data, word_bits_[0] ^ invert,
                      word_bits_[1] ^ invert);
}

bool NavigationDataChannel::take_new_ephemeris() {
  const bool fresh = new_ephemeris_;
  new_ephemeris_ = false;
  return fresh;
}

void NavigationDataChannel::add_bit(float soft, std::int64_t first_code_period) {
  code_periods_[static_cast<std::size_t>(frame_sync_.bits_pushed() % kHistory)] = first_code_period;
  const auto out = frame_sync_.push(soft < 0.0f ? 1 : 0);
  if (!out) {
    read_word(soft, first_code_period);
    return;
  }
  if (out->result.status != signals::LnavStatus::kOk) {
    if (!frame_sync_.locked() && !holding_) tag_.reset();
    read_word(soft, first_code_period);
    return;
  }
  holding_ = false;
  decoder_.add(out->result.subframe);
  if (decoder_.last_update().ephemeris) new_ephemeris_ = true;
  polarity_ = out->result.subframe.inverted ? -1 : 1;
  const auto start = decoder_.last_subframe_start();
  if (start) predictor_.add_subframe(out->result.subframe, *start);
  if (start) tag_ = TransmitTimeTag{code_periods_[static_cast<std::size_t>(out->first_bit_index % kHistory)], *start};
  read_word(soft, first_code_period);
}

}  // namespace ultratrack::receiver
