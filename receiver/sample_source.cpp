// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/sample_source.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "signals/input_error.hpp"

namespace ultratrack::receiver {

bool SampleSourceOptions::IsValid(signals::SampleFormat format, std::string* error) const {
  auto fail = [&](std::string why) {
    if (error) *error = std::move(why);
    return false;
  };
  if (!(fs_hz > 0.0) || !std::isfinite(fs_hz)) return fail("sample rate must be a positive number of Hz");
  if (!std::isfinite(if_hz) || std::abs(if_hz) >= fs_hz / 2.0)
    return fail("intermediate frequency must lie within +-fs/2 (give the aliased IF for bandpass sampling)");
  if (start_sample < 0) return fail("start sample must not be negative");
  if (!(int16_gain >= 0.0) || !std::isfinite(int16_gain)) return fail("int16 gain must be >= 0 (0: automatic)");
  if (!signals::is_complex(format)) {
    if (if_hz == 0.0) return fail("a real sample format needs a non-zero intermediate frequency (--if)");
    if (iq_swap) return fail("--iq-swap needs a complex (I/Q) sample format");
  }
  return true;
}

BasebandConverter::BasebandConverter(const SampleSourceOptions& options, bool complex_input)
    : if_cycles_per_sample_(options.if_hz / options.fs_hz),
      next_sample_(options.start_sample),
      complex_input_(complex_input),
      iq_swap_(options.iq_swap),
      q_negate_(options.q_negate) {
  // Phase at the start sample from the exact product in long double, so skipping samples stays exact.
  const long double cycles = static_cast<long double>(next_sample_) * if_cycles_per_sample_;
  phase_cycles_ = static_cast<double>(cycles - std::floor(cycles));
}

void BasebandConverter::convert(std::span<std::complex<float>> samples) {
  if (complex_input_ && (iq_swap_ || q_negate_)) {
    for (auto& x : samples) {
      float i = x.real(), q = x.imag();
      if (iq_swap_) std::swap(i, q);
      if (q_negate_) q = -q;
      x = {i, q};
    }
  }
  if (if_cycles_per_sample_ != 0.0) {
    // Rotator in double, restarted from the exact phase every block: rounding cannot accumulate across
    // blocks and within a block the error grows by ~1e-16 per sample.
    constexpr double kTwoPi = 2.0 * std::numbers::pi;
    const std::complex<double> step = std::polar(1.0, -kTwoPi * if_cycles_per_sample_);
    std::complex<double> nco = std::polar(1.0, -kTwoPi * phase_cycles_);
    for (auto& x : samples) {
      const std::complex<double> y = std::complex<double>(x.real(), x.imag()) * nco;
      x = {static_cast<float>(y.real()), static_cast<float>(y.imag())};
      nco *= step;
    }
    const double advanced = phase_cycles_ + static_cast<double>(samples.size()) * if_cycles_per_sample_;
    phase_cycles_ = advanced - std::floor(advanced);
  }
  if (!complex_input_ && q_negate_) {
    for (auto& x : samples) x = std::conj(x);
  }
  next_sample_ += static_cast<std::int64_t>(samples.size());
}

namespace {

SampleSourceOptions checked(const std::filesystem::path& path, signals::SampleFormat format,
                            const SampleSourceOptions& options) {
  std::string why;
  if (!options.IsValid(format, &why)) throw signals::InputError(path.string(), why);
  return options;
}

float gain_for(const std::filesystem::path& path, signals::SampleFormat format, const SampleSourceOptions& options) {
  if (options.int16_gain > 0.0) return static_cast<float>(options.int16_gain);
  switch (format) {
    case signals::SampleFormat::i8:
    case signals::SampleFormat::r8:
      return 64.0f;  // 127 * 64 * sqrt(2) = 11494 < 32767
    case signals::SampleFormat::i16:
    case signals::SampleFormat::r16:
      return 0.25f;  // 32767 / 4 * sqrt(2) = 11585
    case signals::SampleFormat::r2:
    case signals::SampleFormat::i2:
      return 1024.0f;  // 3 * 1024 * sqrt(2) = 4345
    case signals::SampleFormat::f32:
      break;
  }
  signals::SampleReader probe(path, format, 0, options.two_bit);
  std::vector<std::complex<float>> head(std::size_t{1} << 16);
  const std::size_t n = probe.read(head);
  double power = 0.0;
  for (std::size_t i = 0; i < n; ++i) power += std::norm(head[i]);
  const double rms = n > 0 ? std::sqrt(power / static_cast<double>(n)) : 0.0;
  return rms > 0.0 && std::isfinite(rms) ? static_cast<float>(2048.0 / rms) : 1.0f;
}

}  // namespace

SampleSource::SampleSource(std::filesystem::path path, signals::SampleFormat format, const SampleSourceOptions& options)
    : options_(checked(path, format, options)),
      reader_(path, format, options.start_sample, options.two_bit),
      converter_(options_, signals::is_complex(format)),
      int16_gain_(gain_for(path, format, options_)) {}

SampleBlock SampleSource::read(std::span<std::complex<float>> out) {
  const SampleBlock block{converter_.next_sample(), reader_.read(out)};
  converter_.convert(out.first(block.count));
  return block;
}

SampleBlock SampleSource::read(std::span<std::complex<std::int16_t>> out) {
  if (scratch_.size() < out.size()) scratch_.resize(out.size());
  const SampleBlock block = read(std::span(scratch_.data(), out.size()));
  auto to_int16 = [](float v) { return static_cast<std::int16_t>(std::clamp(std::nearbyint(v), -32768.0f, 32767.0f)); };
  for (std::size_t i = 0; i < block.count; ++i)
    out[i] = {to_int16(scratch_[i].real() * int16_gain_), to_int16(scratch_[i].imag() * int16_gain_)};
  return block;
}

}  // namespace ultratrack::receiver
