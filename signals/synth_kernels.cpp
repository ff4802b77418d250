// SPDX-License-Identifier: GPL-3.0-or-later
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

namespace {

// Ziggurat tables for 128 layers (Marsaglia & Tsang 2000, "The ziggurat method for generating random
// variables", J. Stat. Software 5(8)): kn thresholds, wn scales, fn densities at the layer edges.
struct ZigguratTables {
  std::array<std::int64_t, 128> kn{};
  std::array<double, 128> wn{}, fn{};
  ZigguratTables() {
    constexpr double kM1 = 2147483648.0;
    constexpr double kVn = 9.91256303526217e-3;
    double dn = 3.442619855899, tn = dn;
    const double q = kVn / std::exp(-0.5 * dn * dn);
    kn[0] = static_cast<std::int64_t>((dn / q) * kM1);
    kn[1] = 0;
    wn[0] = q / kM1;
    wn[127] = dn / kM1;
    fn[0] = 1.0;
    fn[127] = std::exp(-0.5 * dn * dn);
    for (int i = 126; i >= 1; --i) {
      dn = std::sqrt(-2.0 * std::log(kVn / dn + std::exp(-0.5 * dn * dn)));
      kn[i + 1] = static_cast<std::int64_t>((dn / tn) * kM1);
      tn = dn;
      fn[i] = std::exp(-0.5 * dn * dn);
      wn[i] = dn / kM1;
    }
  }
};

const ZigguratTables& ziggurat() {
  static const ZigguratTables tables;
  return tables;
}

constexpr double kZigguratR = 3.442619855899;

}  // namespace

double GaussianNoise::uniform() {
  return (static_cast<double>(rng_() >> 11) + 0.5) * (1.0 / 9007199254740992.0);  // 2^-53
}

double GaussianNoise::next() {
  const auto& z = ziggurat();
  const std::uint64_t u = rng_();
  const int iz = static_cast<int>(u & 127u);
  const auto hz = static_cast<std::int32_t>(static_cast<std::uint32_t>(u >> 32));
  if (std::abs(static_cast<std::int64_t>(hz)) < z.kn[iz]) return hz * z.wn[iz];
  return slow_path(hz, iz);
}

double GaussianNoise::slow_path(std::int32_t hz, int iz) {
  const auto& z = ziggurat();
  for (;;) {
    const double x = hz * z.wn[iz];
    if (iz == 0) {  // the tail beyond r (Marsaglia's exact tail method)
      double xt = 0.0, y = 0.0;
      do {
        xt = -std::log(uniform()) / kZigguratR;
        y = -std::log(uniform());
      } while (y + y < xt * xt);
      return hz > 0 ? kZigguratR + xt : -kZigguratR - xt;
    }
    if (z.fn[iz] + uniform() * (z.fn[iz - 1] - z.fn[iz]) < std::exp(-0.5 * x * x)) return x;
    const std::uint64_t u = rng_();
    iz = static_cast<int>(u & 127u);
    hz = static_cast<std::int32_t>(static_cast<std::uint32_t>(u >> 32));
    if (std::abs(static_cast<std::int64_t>(hz)) < z.kn[iz]) return hz * z.wn[iz];
  }
}

void GaussianNoise::fill(std::complex<float>* out, std::size_t count, float sigma, bool real_output) {
  if (real_output) {
    for (std::size_t i = 0; i < count; ++i) out[i] = {sigma * static_cast<float>(next()), 0.0f};
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      const auto x = static_cast<float>(next());
      const auto y = static_cast<float>(next());
      out[i] = {sigma * x, sigma * y};
    }
  }
}

}  // namespace ultratrack::signals::synth
