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
  constexpr float lo = static_cast<float>(std::numeric_limits<Int>::min());
  constexpr float hi = static_cast<float>(std::numeric_limits<Int>::max());
  // Branch-free so the loops vectorise: NaN -> 0, then round half away from zero, clamp, truncate.
  const float v = (x == x) ? x : 0.0f;
  const float r = std::clamp(v + std::copysign(0.5f, v), lo, hi);
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

SampleWriter::SampleWriter(std::filesystem::path path, SampleFormat format) : path_(std::move(path)), format_(format) {
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

void SampleWriter::write(std::span<const std::complex<float>> samples) {
  const std::size_t count = samples.size();
  raw_.resize(count * bytes_per_sample(format_));
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
  }
  file_.write(raw_.data(), static_cast<std::streamsize>(raw_.size()));
  if (!file_) throw InputError(path_.string(), "write failed (disk full?)");
}

void SampleWriter::finish() {
  if (finished_) return;
  file_.flush();
  file_.close();
  if (file_.fail()) throw InputError(path_.string(), "closing the sample file failed");
  std::error_code ec;
  std::filesystem::rename(temp_path_, path_, ec);
  if (ec) throw InputError(path_.string(), "cannot rename " + temp_path_.string() + ": " + ec.message());
  finished_ = true;
}

}  // namespace ultratrack::signals
