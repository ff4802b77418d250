#include "signals/sample_reader.hpp"

#include <bit>
#include <cstring>
#include <string>
#include <system_error>

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

SampleReader::SampleReader(std::filesystem::path path, SampleFormat format, std::int64_t start_sample)
    : path_(std::move(path)), format_(format) {
  const std::string name = path_.string();
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) throw InputError(name, "sample file does not exist");
  if (!std::filesystem::is_regular_file(path_, ec)) throw InputError(name, "sample file is not a regular file");
  const auto size = std::filesystem::file_size(path_, ec);
  if (ec) throw InputError(name, "cannot read the size of the sample file: " + ec.message());
  if (size == 0) throw InputError(name, "sample file is empty");
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
  if (!file_) throw InputError(name, "cannot open the sample file for reading");
  file_.seekg(static_cast<std::streamoff>(start_sample) * static_cast<std::streamoff>(bps));
  if (!file_) throw InputError(name, "cannot seek to start sample " + std::to_string(start_sample));
  position_ = start_sample;
}

std::size_t SampleReader::read(std::span<std::complex<float>> out) {
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
  }
  position_ += static_cast<std::int64_t>(count);
  return count;
}

}  // namespace ultratrack::signals
