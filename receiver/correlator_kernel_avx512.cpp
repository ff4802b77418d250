// SPDX-License-Identifier: GPL-3.0-or-later
// The integer kernel's AVX-512 BW+VL+VNNI copy (compiled per function with target attributes; chosen at run time
// when the CPU has them): 32 samples per step, bit-identical to the portable and AVX2 copies.
#include "receiver/correlator_kernels.hpp"

#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
namespace ultratrack::receiver::correlator_kernels {
namespace {

// Sum of the 16 int32 lanes. Zero-masked extracts: GCC 12's plain ones (and _mm512_reduce_add_epi32,
// _mm512_castsi512_si256) warn about an undefined register.
__attribute__((target("avx2,avx512f"), always_inline)) inline std::int32_t lane_sum(__m512i v) {
  const __m256i h =
      _mm256_add_epi32(_mm512_maskz_extracti64x4_epi64(0xFF, v, 0), _mm512_maskz_extracti64x4_epi64(0xFF, v, 1));
  __m128i x = _mm_add_epi32(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
  x = _mm_add_epi32(x, _mm_shuffle_epi32(x, 0x4E));
  x = _mm_add_epi32(x, _mm_shuffle_epi32(x, 0xB1));
  return _mm_cvtsi128_si32(x);
}

// The AVX-512 copy (BW, VL, VNNI): 32 samples per step. Chips as int16: per group of taps sharing a fraction,
// the 32 relative indices (0..31) from two compares into a mask and one masked add; per tap one 64-byte load of
// chips and one word permute (vpermw), then two vpdpwssd (multiply pairs and accumulate into int32, the
// pmaddwd + add of the AVX2 copy in one instruction: same products, exact). The chunk's last n % 32 samples
// run through the same step with masked (zeroing) sample loads. Lane sums per chunk stay below
// 32 steps * 2 * 32768 = 2^21 (one chunk is 1024 samples), so the int32 reductions are exact.
struct LaneIndex {  // per call: lane l's threshold 2^22 - g_l and whole part h_l (see the comment above kFracMask)
  __m512i threshold_lo, threshold_hi, whole;
};

template <int kTaps, std::uint32_t kShare>
__attribute__((target("avx2,fma,avx512f,avx512bw,avx512vl,avx512vnni"), always_inline)) inline void avx512_chunk(
    const std::int16_t* xr_p, const std::int16_t* xi_p, int n, const CorrelatorEngine::Rotation& rot,
    const std::int16_t* const* base, const std::uint32_t* frac, std::uint32_t step, const LaneIndex& lanes,
    std::int64_t* re, std::int64_t* im) {
  const __m512i one = _mm512_set1_epi16(1);
  __m512i acc_re[kTaps], acc_im[kTaps];
  for (int t = 0; t < kTaps; ++t) acc_re[t] = acc_im[t] = _mm512_setzero_si512();
  for (int i = 0; i < n; i += 32) {
    const __mmask32 valid = n - i >= 32 ? ~__mmask32{0} : static_cast<__mmask32>((1u << (n - i)) - 1u);
    const __m512i xr = _mm512_maskz_loadu_epi16(valid, xr_p + i);
    const __m512i xi = _mm512_maskz_loadu_epi16(valid, xi_p + i);
    const __m512i rr = _mm512_load_si512(rot.re + i), ri = _mm512_load_si512(rot.im + i);
    const __m512i wr = _mm512_adds_epi16(_mm512_mulhrs_epi16(xr, rr), _mm512_mulhrs_epi16(xi, ri));
    const __m512i wi = _mm512_subs_epi16(_mm512_mulhrs_epi16(xi, rr), _mm512_mulhrs_epi16(xr, ri));
    __m512i rel[kTaps];
    std::uint32_t first[kTaps];
#pragma GCC unroll 8
    for (int t = 0; t < kTaps; ++t) {
      const int lead = share_leader(kShare, t);
      if (lead == t) {
        const std::uint32_t p = frac[t] + step * static_cast<std::uint32_t>(i);
        first[t] = p >> kFracBits;
        const __m512i q = _mm512_set1_epi32(static_cast<int>(p & kFracMask));
        const __mmask32 carry = _mm512_kunpackw(_mm512_cmpge_epu32_mask(q, lanes.threshold_hi),
                                                _mm512_cmpge_epu32_mask(q, lanes.threshold_lo));
        rel[t] = _mm512_mask_add_epi16(lanes.whole, carry, lanes.whole, one);
      } else {
        rel[t] = rel[lead];
        first[t] = first[lead];
      }
      const __m512i chips = _mm512_permutexvar_epi16(rel[t], _mm512_loadu_si512(base[t] + first[t]));
      acc_re[t] = _mm512_dpwssd_epi32(acc_re[t], wr, chips);
      acc_im[t] = _mm512_dpwssd_epi32(acc_im[t], wi, chips);
    }
  }
  for (int t = 0; t < kTaps; ++t) {
    re[t] = lane_sum(acc_re[t]);
    im[t] = lane_sum(acc_im[t]);
  }
}

template <int kTaps, std::uint32_t kShare>
__attribute__((target("avx2,fma,avx512f,avx512bw,avx512vl,avx512vnni"))) void correlate_i16_avx512(
    const std::int8_t* table, const std::int16_t* table16, const double* offsets, int num_taps,
    std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& rep,
    const CorrelatorEngine::Rotation& rot, double scale, std::span<TapSums> sums) {
  if (!(rep.code_step_chips <= 0.99)) {  // 32 samples could span more than 32 chips
    correlate_i16_portable(table, table16, offsets, num_taps, antennas, num_samples, rep, rot, scale, sums);
    return;
  }
  const std::uint32_t step = step_q24(rep);
  alignas(64) std::uint32_t threshold[32];
  alignas(64) std::int16_t lane_whole[32];
  for (int l = 0; l < 32; ++l) {
    const std::uint32_t a = step * static_cast<std::uint32_t>(l);
    threshold[l] = (1u << kFracBits) - (a & kFracMask);
    lane_whole[l] = static_cast<std::int16_t>(a >> kFracBits);
  }
  const LaneIndex lanes{_mm512_load_si512(threshold), _mm512_load_si512(threshold + 16), _mm512_load_si512(lane_whole)};
  for (int start = 0; start < num_samples; start += kChunkI16) {
    const int n = num_samples - start < kChunkI16 ? num_samples - start : kChunkI16;
    int whole[kMaxTaps];
    std::uint32_t frac[kMaxTaps];
    chunk_taps(rep, offsets, kTaps, start, whole, frac);
    const std::int16_t* base[kTaps];
    bool shared = true;  // the engine's pattern holds in this chunk (equal fractions: exact, as in the portable copy)
    for (int t = 0; t < kTaps; ++t) {
      base[t] = table16 + whole[t];
      shared = shared && frac[share_leader(kShare, t)] == frac[t];
    }
    const std::uint32_t phase0 = chunk_phase(rep, rot.step_q32, start, n);
    for (std::size_t a = 0; a < antennas.size(); ++a) {
      std::int64_t re[kMaxTaps], im[kMaxTaps];
      if (kShare == no_sharing(kTaps) || !shared)
        avx512_chunk<kTaps, no_sharing(kTaps)>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step,
                                               lanes, re, im);
      else
        avx512_chunk<kTaps, kShare>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re,
                                    im);
      finish_chunk(re, im, kTaps, phase0, scale, sums[a]);
    }
  }
}

struct Avx512Kernels {
  template <int kTaps, std::uint32_t kShare>
  static constexpr CorrelatorEngine::KernelI16 get() {
    return &correlate_i16_avx512<kTaps, kShare>;
  }
};

}  // namespace

CorrelatorEngine::KernelI16 i16_kernel_avx512(int num_taps, std::uint32_t share) {
  switch (num_taps) {
    case 1:
      return select_shared<1, Avx512Kernels>(share);
    case 2:
      return select_shared<2, Avx512Kernels>(share);
    case 3:
      return select_shared<3, Avx512Kernels>(share);
    case 4:
      return select_shared<4, Avx512Kernels>(share);
    case 5:
      return select_shared<5, Avx512Kernels>(share);
    default:
      return select_shared<6, Avx512Kernels>(share);
  }
}

}  // namespace ultratrack::receiver::correlator_kernels
#endif
