// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_frame_sync.hpp"

#include <algorithm>
#include <span>

#include "signals/lnav_fields.hpp"

namespace ultratrack::signals {

std::optional<LnavFrameSyncOutput> LnavFrameSync::decode_window() {
  LnavFrameSyncOutput out;
  std::span<const std::uint8_t, 300> bits(window_.data() + 2, 300);
  std::optional<std::array<std::uint8_t, 2>> previous;
  if (filled_ >= 302) previous = std::array<std::uint8_t, 2>{window_[0], window_[1]};
  out.result = decode_lnav_subframe(bits, previous);
  out.first_bit_index = count_ - 300;
  return out;
}

std::optional<LnavFrameSyncOutput> LnavFrameSync::push(std::uint8_t bit) {
  std::copy(window_.begin() + 1, window_.end(), window_.begin());
  window_.back() = bit & 1u;
  ++count_;
  filled_ = std::min(filled_ + 1, 302);
  if (filled_ < 300) return std::nullopt;

  if (locked_) {
    if (++since_start_ < 300) return std::nullopt;
    since_start_ = 0;
    auto out = decode_window();
    if (out->result.status == LnavStatus::kOk) {
      misses_ = 0;
    } else if (++misses_ >= kMaxMisses) {
      locked_ = false;
    }
    return out;
  }

  // Searching: most positions fail on the 8-bit preamble before any parity work.
  std::uint32_t preamble = 0;
  for (int i = 0; i < 8; ++i) preamble = (preamble << 1) | window_[2 + static_cast<std::size_t>(i)];
  if (preamble != kLnavPreamble && preamble != (~kLnavPreamble & 0xFFu)) return std::nullopt;
  auto out = decode_window();
  if (out->result.status != LnavStatus::kOk) return std::nullopt;
  locked_ = true;
  since_start_ = 0;
  misses_ = 0;
  return out;
}

}  // namespace ultratrack::signals
