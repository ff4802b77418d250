#include "signals/synth_kernels.hpp"

#include <array>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals::synth {
namespace {

constexpr int kTableBits = 12;
constexpr std::uint32_t kTableShift = 32 - kTableBits;

// exp(j 2 pi (i + 1/2) / 4096): bin centres, so truncating the phase is unbiased (max error pi/4096 rad).
const std::array<std::complex<float>, 1u << kTableBits>& carrier_table() {
  static const auto table = [] {
    std::array<std::complex<float>, 1u << kTableBits> t{};
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double a = 2.0 * M_PI * (static_cast<double>(i) + 0.5) / static_cast<double>(t.size());
      t[i] = {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))};
    }
    return t;
  }();
  return table;
}

constexpr double kTwo32 = 4294967296.0;

// Fractional cycles as a 32-bit phase word (two's complement wrap handles negative values).
inline std::uint32_t phase_word(double cycles) {
  const double frac = cycles - std::floor(cycles);
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(frac * kTwo32) & 0xffffffffu);
}

}  // namespace

std::mt19937_64 seeded_engine(std::uint64_t seed, std::uint64_t stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(stream), static_cast<std::uint32_t>(stream >> 32)};
  return std::mt19937_64(seq);
}

void add_code_carrier(std::complex<float>* out, std::size_t count, const float* chip_amplitude, float data,
                      double code0_chips, double code_rate, double carrier0_cycles, double carrier_rate,
                      bool real_output) {
  const auto& table = carrier_table();
  // Code phase in 32.32 fixed point chips.
  constexpr std::uint64_t kWrap = static_cast<std::uint64_t>(kCaCodeLength_chips) << 32;
  std::uint64_t code = static_cast<std::uint64_t>(code0_chips * kTwo32);
  if (code >= kWrap) code -= kWrap;
  const auto code_step = static_cast<std::uint64_t>(code_rate * kTwo32);
  std::uint32_t phase = phase_word(carrier0_cycles);
  const std::uint32_t phase_step = phase_word(carrier_rate);
  if (real_output) {
    for (std::size_t i = 0; i < count; ++i) {
      const float a = data * chip_amplitude[code >> 32];
      out[i].real(out[i].real() + a * table[phase >> kTableShift].real());
      code += code_step;
      if (code >= kWrap) code -= kWrap;
      phase += phase_step;
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      const float a = data * chip_amplitude[code >> 32];
      out[i] += a * table[phase >> kTableShift];
      code += code_step;
      if (code >= kWrap) code -= kWrap;
      phase += phase_step;
    }
  }
}

void GaussianNoise::pair(float& a, float& b) {
  constexpr float kScale = 1.0f / 2147483648.0f;  // 2^-31: int32 -> [-1, 1)
  for (;;) {
    const std::uint64_t r = rng_();
    const float u = static_cast<float>(static_cast<std::int32_t>(r & 0xffffffffu)) * kScale;
    const float v = static_cast<float>(static_cast<std::int32_t>(r >> 32)) * kScale;
    const float s = u * u + v * v;
    if (s >= 1.0f || s == 0.0f) continue;
    const float f = std::sqrt(-2.0f * std::log(s) / s);
    a = u * f;
    b = v * f;
    return;
  }
}

void GaussianNoise::fill(std::complex<float>* out, std::size_t count, float sigma, bool real_output) {
  float a = 0.0f, b = 0.0f;
  if (real_output) {
    std::size_t i = 0;
    if (has_spare_ && count > 0) {
      out[i++] = {sigma * spare_, 0.0f};
      has_spare_ = false;
    }
    for (; i + 1 < count; i += 2) {
      pair(a, b);
      out[i] = {sigma * a, 0.0f};
      out[i + 1] = {sigma * b, 0.0f};
    }
    if (i < count) {
      pair(a, b);
      out[i] = {sigma * a, 0.0f};
      spare_ = b;
      has_spare_ = true;
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      pair(a, b);
      out[i] = {sigma * a, sigma * b};
    }
  }
}

}  // namespace ultratrack::signals::synth
