// SPDX-License-Identifier: GPL-3.0-or-later
// The integer kernel's portable copy, and the chunk arithmetic every integer copy shares (rotation table, chip
// indices per chunk, the exact finish of a chunk's sums).
#include "receiver/correlator_kernels.hpp"

namespace ultratrack::receiver::correlator_kernels {

__attribute__((noinline)) void build_rotation(std::uint32_t step_q32, CorrelatorEngine::Rotation& r) {
  for (int i = 0; i < kChunkI16; ++i) {
    float c, s;
    sincos_q32(step_q32 * static_cast<std::uint32_t>(i), c, s);
    const auto q15 = [](float v) {
      const long q = std::lrint(v * 32767.0f);
      return static_cast<std::int16_t>(q > 32767 ? 32767 : q < -32767 ? -32767 : q);  // never -32768: mulhrs safe
    };
    r.re[i] = q15(c);
    r.im[i] = q15(s);
  }
  r.step_q32 = step_q32;
  r.valid = true;
}

__attribute__((noinline)) void chunk_taps(const ReplicaSegment& rep, const double* offsets, int num_taps, int start,
                                          int* whole, std::uint32_t* frac_q24) {
  const double code0 = rep.code_phase_chips + rep.code_step_chips * start + 2 * kCodeLength;  // table origin
  for (int t = 0; t < num_taps; ++t) {
    const double base = code0 + offsets[t];
    whole[t] = static_cast<int>(base);
    frac_q24[t] = static_cast<std::uint32_t>((base - whole[t]) * kQ24);
  }
}

__attribute__((noinline)) void finish_chunk(const std::int64_t* re, const std::int64_t* im, int num_taps,
                                            std::uint32_t phase0, double scale, TapSums& sums) {
  float c, s;
  sincos_q32(phase0, c, s);
  const double cd = static_cast<double>(c) * scale, sd = static_cast<double>(s) * scale;
  for (int t = 0; t < num_taps; ++t) {
    const auto r = static_cast<double>(re[t]), i = static_cast<double>(im[t]);
    sums[t] += std::complex<double>(r * cd + i * sd, i * cd - r * sd);  // (r + j i)(c - j s)
  }
}

void correlate_i16_portable(const std::int8_t* table, const std::int16_t* /*table16*/, const double* offsets,
                            int num_taps, std::span<const PlanarI16> antennas, int num_samples,
                            const ReplicaSegment& rep, const CorrelatorEngine::Rotation& rot, double scale,
                            std::span<TapSums> sums) {
  const std::uint32_t step = step_q24(rep);
  for (int start = 0; start < num_samples; start += kChunkI16) {
    const int n = num_samples - start < kChunkI16 ? num_samples - start : kChunkI16;
    int whole[kMaxTaps];
    std::uint32_t frac[kMaxTaps];
    chunk_taps(rep, offsets, num_taps, start, whole, frac);
    const std::uint32_t phase0 = chunk_phase(rep, rot.step_q32, start, n);
    for (std::size_t a = 0; a < antennas.size(); ++a) {
      const std::int16_t* xr = antennas[a].re + start;
      const std::int16_t* xi = antennas[a].im + start;
      std::int64_t re[kMaxTaps] = {}, im[kMaxTaps] = {};
      for (int i = 0; i < n; ++i)
        mac_sample(xr[i], xi[i], rot.re[i], rot.im[i], table, whole, frac, step, i, num_taps, re, im);
      finish_chunk(re, im, num_taps, phase0, scale, sums[a]);
    }
  }
}

CorrelatorEngine::KernelI16 i16_kernel_portable() { return &correlate_i16_portable; }

}  // namespace ultratrack::receiver::correlator_kernels
