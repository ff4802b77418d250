// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/sample_writer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <system_error>

#include "signals/input_error.hpp"

namespace ultratrack::signals {
namespace {

// Round half away from zero and saturate to [lo, hi]; NaN becomes 0.
template <typename Int>
inline Int quantise(float x) {
  constexpr float kLo = static_cast<float>(std::numeric_limits<Int>::min());
  constexpr float kHi = static_cast<float>(std::numeric_limits<Int>::max());
  // Branch-free so the loops vectorise: NaN -> 0, then round half away from zero, clamp, truncate.
  const float v = (x == x) ? x : 0.0f;
  const float r = std::clamp(v + std::copysign(0.5f, v), kLo, kHi);
  return static_cast<Int>(r);
}

inline void put_le_i16(char* p, std::int16_t v) {
  const auto u = static_cast<std::uint16_t>(v);
  p[0] = static_cast<char>(u & 0xff);
  p[1] = static_cast<char>(u >> 8);
}

inline void put_le_f32(char* p, float v) {
  const auto u = std::bit_cast<std::uint32_t>(v);
  for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((u >> (8 * i)) & 0xff);
}

}  // namespace

SampleWriter::SampleWriter(std::filesystem::path path, SampleFormat format, TwoBitLayout layout)
    : path_(std::move(path)), format_(format) {
  const auto levels = two_bit_levels(layout.coding);
  for (std::size_t c = 0; c < 4; ++c)
    code_[static_cast<std::size_t>((levels[c] + 3) / 2)] = static_cast<std::uint8_t>(c);
  for (int j = 0; j < 4; ++j)
    shift_[static_cast<std::size_t>(j)] = 2 * (layout.order == BitOrder::lsb_first ? j : 3 - j);
  temp_path_ = path_;
  temp_path_ += ".part";
  file_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!file_) throw InputError(path_.string(), "cannot create the sample file (" + temp_path_.string() + ")");
}

SampleWriter::~SampleWriter() {
  if (!finished_) {
    file_.close();
    std::error_code ec;
    std::filesystem::remove(temp_path_, ec);
  }
}

// One 2-bit value into the pending byte; a full byte goes to p.
inline void SampleWriter::pack(float x, char*& p) {
  // Level index 0..3 for -3, -1, +1, +3: thresholds -2, 0, +2 (NaN counts as 0, i.e. +1).
  const float v = (x == x) ? x : 0.0f;
  const int index = (v >= -2.0f) + (v >= 0.0f) + (v >= 2.0f);
  pending_ = static_cast<std::uint8_t>(
      pending_ | (code_[static_cast<std::size_t>(index)] << shift_[static_cast<std::size_t>(pending_fields_)]));
  if (++pending_fields_ == 4) {
    *p++ = static_cast<char>(pending_);
    pending_ = 0;
    pending_fields_ = 0;
  }
}

void SampleWriter::write(std::span<const std::complex<float>> samples) {
  const std::size_t count = samples.size();
  raw_.resize(is_two_bit(format_) ? (count * bits_per_sample(format_)) / 8 + 1 : count * bytes_per_sample(format_));
  char* p = raw_.data();
  switch (format_) {
    case SampleFormat::i8:
      for (const auto& s : samples) {
        *p++ = static_cast<char>(quantise<std::int8_t>(s.real()));
        *p++ = static_cast<char>(quantise<std::int8_t>(s.imag()));
      }
      break;
    case SampleFormat::i16:
      for (const auto& s : samples) {
        put_le_i16(p, quantise<std::int16_t>(s.real()));
        put_le_i16(p + 2, quantise<std::int16_t>(s.imag()));
        p += 4;
      }
      break;
    case SampleFormat::f32:
      if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(p, samples.data(), count * 8);
        p += count * 8;
      } else {
        for (const auto& s : samples) {
          put_le_f32(p, s.real());
          put_le_f32(p + 4, s.imag());
          p += 8;
        }
      }
      break;
    case SampleFormat::r8:
      for (const auto& s : samples) *p++ = static_cast<char>(quantise<std::int8_t>(s.real()));
      break;
    case SampleFormat::r16:
      for (const auto& s : samples) {
        put_le_i16(p, quantise<std::int16_t>(s.real()));
        p += 2;
      }
      break;
    case SampleFormat::r2:
      for (const auto& s : samples) pack(s.real(), p);
      break;
    case SampleFormat::i2:
      for (const auto& s : samples) {
        pack(s.real(), p);
        pack(s.imag(), p);
      }
      break;
  }
  file_.write(raw_.data(), static_cast<std::streamsize>(p - raw_.data()));
  if (!file_) throw InputError(path_.string(), "write failed (disk full?)");
}

void SampleWriter::finish() {
  if (finished_) return;
  if (pending_fields_ > 0) {
    char last[1];
    char* p = last;
    while (pending_fields_ != 0) pack(1.0f, p);
    file_.write(last, 1);
    if (!file_) throw InputError(path_.string(), "write failed (disk full?)");
  }
  file_.flush();
  file_.close();
  if (file_.fail()) throw InputError(path_.string(), "closing the sample file failed");
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec) throw InputError(path_.string(), "cannot rename " + temp_path_.string() + ": " + ec.message());
  finished_ = true;
}

}  // namespace ultratrack::signals
