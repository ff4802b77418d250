// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/sample_reader.hpp"

#include <bit>
#include <cstring>
#include <string>
#include <system_error>

#include "io/open_failure.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::signals {
namespace {

// Little-endian decoding that does not depend on the host's byte order.
inline std::int16_t le_i16(const char* p) {
  const auto lo = static_cast<std::uint16_t>(static_cast<unsigned char>(p[0]));
  const auto hi = static_cast<std::uint16_t>(static_cast<unsigned char>(p[1]));
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(lo | (hi << 8)));
}

inline float le_f32(const char* p) {
  std::uint32_t u = 0;
  for (int i = 3; i >= 0; --i) u = (u << 8) | static_cast<unsigned char>(p[i]);
  return std::bit_cast<float>(u);
}

}  // namespace

SampleReader::SampleReader(std::filesystem::path path, SampleFormat format, std::int64_t start_sample,
                           TwoBitLayout layout)
    : path_(std::move(path)), format_(format), per_byte_(samples_per_byte(format)) {
  const std::string name = path_.string();
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) throw InputError(name, "sample file does not exist");
  if (!std::filesystem::is_regular_file(path_, ec)) throw InputError(name, "sample file is not a regular file");
  const auto size = std::filesystem::file_size(path_, ec);
  if (ec) throw InputError(name, "cannot read the size of the sample file: " + ec.message());
  if (size == 0) throw InputError(name, "sample file is empty");
  if (per_byte_ > 0) {
    open_packed(size, start_sample, layout);
    return;
  }
  const auto bps = bytes_per_sample(format_);
  if (size % bps != 0) {
    throw InputError(name, "file size " + std::to_string(size) + " bytes is not a whole number of " +
                               std::string(to_string(format_)) + " samples (" + std::to_string(bps) +
                               " bytes each): the final sample is truncated or the format is wrong");
  }
  total_samples_ = static_cast<std::int64_t>(size / bps);
  if (start_sample < 0) throw InputError(name, "start sample " + std::to_string(start_sample) + " is negative");
  if (start_sample >= total_samples_) {
    throw InputError(name, "start sample " + std::to_string(start_sample) + " is at or beyond the end of the file (" +
                               std::to_string(total_samples_) + " samples)");
  }
  file_.open(path_, std::ios::binary);
  if (!file_) throw InputError(name, "cannot open the sample file for reading: " + io::open_failure_reason());
  file_.seekg(static_cast<std::streamoff>(start_sample) * static_cast<std::streamoff>(bps));
  if (!file_) throw InputError(name, "cannot seek to start sample " + std::to_string(start_sample));
  position_ = start_sample;
}

void SampleReader::open_packed(std::uintmax_t size, std::int64_t start_sample, TwoBitLayout layout) {
  const std::string name = path_.string();
  total_samples_ = static_cast<std::int64_t>(size * per_byte_);
  if (start_sample < 0) throw InputError(name, "start sample " + std::to_string(start_sample) + " is negative");
  if (start_sample >= total_samples_) {
    throw InputError(name, "start sample " + std::to_string(start_sample) + " is at or beyond the end of the file (" +
                               std::to_string(total_samples_) + " samples)");
  }
  // Four 2-bit fields per byte, field j in bits 2j+1:2j; lsb_first takes field 0 first.
  const auto level = two_bit_levels(layout.coding);
  for (int b = 0; b < 256; ++b) {
    for (int j = 0; j < 4; ++j) {
      const int field = layout.order == BitOrder::lsb_first ? j : 3 - j;
      levels_[static_cast<std::size_t>(b)][static_cast<std::size_t>(j)] =
          static_cast<float>(level[static_cast<std::size_t>((b >> (2 * field)) & 3)]);
    }
  }
  file_.open(path_, std::ios::binary);
  if (!file_) throw InputError(name, "cannot open the sample file for reading: " + io::open_failure_reason());
  const auto per_byte = static_cast<std::int64_t>(per_byte_);
  file_.seekg(static_cast<std::streamoff>(start_sample / per_byte));
  if (!file_) throw InputError(name, "cannot seek to start sample " + std::to_string(start_sample));
  position_ = start_sample;
  if (const auto within = static_cast<std::size_t>(start_sample % per_byte); within != 0) {
    char b = 0;
    if (!file_.get(b)) throw InputError(name, "cannot read the byte of start sample " + std::to_string(start_sample));
    carry_end_ = unpack(static_cast<unsigned char>(b), within, per_byte_, carry_, 0);
  }
}

std::size_t SampleReader::unpack(unsigned char b, std::size_t k, std::size_t k_end, std::span<std::complex<float>> out,
                                 std::size_t n) const {
  const auto& v = levels_[b];
  if (per_byte_ == 4) {
    for (; k < k_end; ++k) out[n++] = {v[k], 0.0f};
  } else {
    for (; k < k_end; ++k) out[n++] = {v[2 * k], v[2 * k + 1]};
  }
  return n;
}

std::size_t SampleReader::read_packed(std::span<std::complex<float>> out) {
  const auto left = static_cast<std::size_t>(total_samples_ - position_);
  const std::size_t count = out.size() < left ? out.size() : left;
  std::size_t n = 0;
  while (n < count && carry_begin_ < carry_end_) out[n++] = carry_[carry_begin_++];
  if (n < count) {
    const std::size_t rest = count - n;
    const std::size_t bytes = (rest + per_byte_ - 1) / per_byte_;
    raw_.resize(bytes);
    file_.read(raw_.data(), static_cast<std::streamsize>(bytes));
    if (file_.gcount() != static_cast<std::streamsize>(bytes)) {
      throw InputError(path_.string(), "read failed at sample " +
                                           std::to_string(position_ + static_cast<std::int64_t>(n)) +
                                           " (the file changed while being read?)");
    }
    const std::size_t whole = rest / per_byte_;
    for (std::size_t i = 0; i < whole; ++i) n = unpack(static_cast<unsigned char>(raw_[i]), 0, per_byte_, out, n);
    if (const std::size_t part = rest % per_byte_; part != 0) {
      const auto b = static_cast<unsigned char>(raw_[whole]);
      n = unpack(b, 0, part, out, n);
      carry_begin_ = 0;
      carry_end_ = unpack(b, part, per_byte_, carry_, 0);
    }
  }
  position_ += static_cast<std::int64_t>(count);
  return count;
}

std::size_t SampleReader::read(std::span<std::complex<float>> out) {
  if (per_byte_ > 0) return read_packed(out);
  const auto bps = bytes_per_sample(format_);
  const auto left = static_cast<std::size_t>(total_samples_ - position_);
  const std::size_t count = out.size() < left ? out.size() : left;
  if (count == 0) return 0;
  raw_.resize(count * bps);
  file_.read(raw_.data(), static_cast<std::streamsize>(raw_.size()));
  if (file_.gcount() != static_cast<std::streamsize>(raw_.size())) {
    throw InputError(path_.string(),
                     "read failed at sample " + std::to_string(position_) + " (the file changed while being read?)");
  }
  const char* p = raw_.data();
  switch (format_) {
    case SampleFormat::i8:
      for (std::size_t i = 0; i < count; ++i, p += 2)
        out[i] = {static_cast<float>(static_cast<std::int8_t>(p[0])),
                  static_cast<float>(static_cast<std::int8_t>(p[1]))};
      break;
    case SampleFormat::i16:
      for (std::size_t i = 0; i < count; ++i, p += 4)
        out[i] = {static_cast<float>(le_i16(p)), static_cast<float>(le_i16(p + 2))};
      break;
    case SampleFormat::f32:
      if constexpr (std::endian::native == std::endian::little) {
        std::memcpy(out.data(), p, count * 8);  // std::complex<float> is two packed floats
      } else {
        for (std::size_t i = 0; i < count; ++i, p += 8) out[i] = {le_f32(p), le_f32(p + 4)};
      }
      break;
    case SampleFormat::r8:
      for (std::size_t i = 0; i < count; ++i, ++p) out[i] = {static_cast<float>(static_cast<std::int8_t>(p[0])), 0.0f};
      break;
    case SampleFormat::r16:
      for (std::size_t i = 0; i < count; ++i, p += 2) out[i] = {static_cast<float>(le_i16(p)), 0.0f};
      break;
    case SampleFormat::r2:
    case SampleFormat::i2:
      break;  // read_packed
  }
  position_ += static_cast<std::int64_t>(count);
  return count;
}

}  // namespace ultratrack::signals
