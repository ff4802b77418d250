// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/correlator_engine.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "receiver/correlator_isa.hpp"
#include "receiver/correlator_kernels.hpp"
#include "signals/ca_code.hpp"

namespace ultratrack::receiver {
namespace {

using namespace correlator_kernels;

CorrelatorEngine::Kernel select_kernel([[maybe_unused]] CorrelatorIsa isa, int num_taps) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (isa != CorrelatorIsa::kBaseline) return float_kernel_avx2(num_taps);  // no AVX-512 float copy
#endif
  return float_kernel_baseline(num_taps);
}

CorrelatorEngine::KernelI16 select_kernel_i16([[maybe_unused]] CorrelatorIsa isa, [[maybe_unused]] int num_taps,
                                              [[maybe_unused]] std::uint32_t share) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (isa == CorrelatorIsa::kAvx512) return i16_kernel_avx512(num_taps, share);
  if (isa == CorrelatorIsa::kAvx2) return i16_kernel_avx2(num_taps, share);
#endif
  return i16_kernel_portable();
}

}  // namespace

CorrelatorEngine::CorrelatorEngine(int prn, std::span<const double> tap_offsets_chips, CorrelatorIsa isa)
    : prn_(prn), num_taps_(static_cast<int>(tap_offsets_chips.size())) {
  if (num_taps_ < 1 || num_taps_ > kMaxTaps)
    throw std::invalid_argument("CorrelatorEngine: 1.." + std::to_string(kMaxTaps) + " taps required");
  for (int t = 0; t < num_taps_; ++t) {
    if (!(std::abs(tap_offsets_chips[t]) <= kCodeLength))
      throw std::invalid_argument("CorrelatorEngine: tap offset beyond one code period");
    offsets_[t] = tap_offsets_chips[t];
  }
  const auto& chips = signals::ca_code(prn);  // throws std::out_of_range for a bad PRN
  table_.resize(5 * kCodeLength + 8);
  for (int i = 0; i < static_cast<int>(table_.size()); ++i) table_[i] = static_cast<float>(chips[i % kCodeLength]);
  table_i8_.resize(table_.size() + 32);  // the AVX2 integer copy reads 16-byte windows past the last chip used
  for (int i = 0; i < static_cast<int>(table_i8_.size()); ++i)
    table_i8_[i] = static_cast<std::int8_t>(chips[i % kCodeLength]);
  table_i16_.resize(table_.size() + 64);  // the AVX-512 copy reads 32-word windows past the last chip used
  for (int i = 0; i < static_cast<int>(table_i16_.size()); ++i)
    table_i16_[i] = static_cast<std::int16_t>(chips[i % kCodeLength]);
  const CorrelatorIsa level = resolve_correlator_isa(isa);
  std::uint32_t share = 0;  // per tap: the first tap a whole number of chips from it (the AVX-512 copy's pattern)
  for (int t = 0; t < num_taps_; ++t) {
    int lead = t;
    for (int u = 0; u < t && lead == t; ++u)
      if (const double d = offsets_[t] - offsets_[u]; d == std::floor(d)) lead = u;
    share |= static_cast<std::uint32_t>(lead) << (3 * t);
  }
  kernel_ = select_kernel(level, num_taps_);
  kernel_i16_ = select_kernel_i16(level, num_taps_, share);
}

void CorrelatorEngine::correlate_i16(std::span<const PlanarI16> antennas, int num_samples,
                                     const ReplicaSegment& replica, double scale, std::span<TapSums> sums) const {
  const std::uint32_t step = table_step(replica.carrier_step_q32);
  if (!rotation_.valid || rotation_.step_q32 != step) build_rotation(step, rotation_);
  kernel_i16_(table_i8_.data(), table_i16_.data(), offsets_.data(), num_taps_, antennas, num_samples, replica,
              rotation_, scale, sums);
}

void convert_to_planar_i16(const std::complex<float>* in, int n, float gain, std::int16_t* re, std::int16_t* im) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (correlator_auto_isa() != CorrelatorIsa::kBaseline) {
    convert_planar_avx2(in, n, gain, re, im);
    return;
  }
#endif
  for (int i = 0; i < n; ++i) {
    re[i] = static_cast<std::int16_t>(std::nearbyint(std::clamp(in[i].real() * gain, -32768.0f, 32767.0f)));
    im[i] = static_cast<std::int16_t>(std::nearbyint(std::clamp(in[i].imag() * gain, -32768.0f, 32767.0f)));
  }
}

void CorrelatorEngine::correlate(std::span<const std::complex<float>* const> antennas, int num_samples,
                                 const ReplicaSegment& replica, std::span<TapSums> sums) const {
  kernel_(table_.data(), offsets_.data(), antennas, num_samples, replica, sums);
}

double noise_tap_offset_chips(int prn) {
  const auto& c = signals::ca_code(prn);
  auto autocorr = [&](int lag) {
    int s = 0;
    for (int k = 0; k < kCodeLength; ++k) s += c[k] * c[(k + lag) % kCodeLength];
    return s;
  };
  for (int lag = 300; lag <= 723; ++lag) {
    bool clean = true;
    for (int d = -2; d <= 2 && clean; ++d) clean = autocorr(lag + d) == -1;
    if (clean) return -lag;
  }
  throw std::logic_error("noise_tap_offset_chips: no clean lag for PRN " + std::to_string(prn));
}

void fixed_point_sincos(std::uint32_t phase_q32, float* cos_out, float* sin_out) {
  sincos_q32(phase_q32, *cos_out, *sin_out);
}

}  // namespace ultratrack::receiver
