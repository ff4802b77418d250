// SPDX-License-Identifier: GPL-3.0-or-later
// The AVX2+FMA copies (compiled per function with target attributes; chosen at run time when the CPU has them):
// the float kernel with the code fill fused into the multiply-accumulate loop, the integer kernel (16 samples
// per step), and the float-to-planar-int16 conversion.
#include "receiver/correlator_kernels.hpp"

#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
namespace ultratrack::receiver::correlator_kernels {
namespace {

// The AVX2 copy with the code fill fused into the multiply-accumulate loop: each tap's chips for 8 samples are
// made in a register (index, one unaligned load of 8 chips, a lane permutation) and used at once, instead of
// being stored to a buffer and read back; the step * i product is shared by all taps. Samples are taken in
// the lane order 0 1 4 5 2 3 6 7, which is what a two-shuffle de-interleave of I/Q gives; the carrier rotation
// table and the chip index lanes follow that order, and the sums do not care. Chip indices are evaluated with
// the same float expression as fill_code_baseline (fp-contract=off: no fused multiply-add there), so every
// tap reads the same chips as the portable copy; the carrier and the sums use explicit FMA.
template <int kTaps>
__attribute__((target("avx2,fma"), optimize("fp-contract=off"))) void correlate_avx2(
    const float* table, const double* offsets, std::span<const std::complex<float>* const> antennas, int num_samples,
    const ReplicaSegment& rep, std::span<TapSums> sums) {
  const auto step_f = static_cast<float>(rep.code_step_chips);
  if (!(step_f <= 0.99f)) {  // above ~1 chip per sample 8 samples can span more than 8 chips
    correlate_chunked<kTaps, fill_code_baseline>(table, offsets, antennas, num_samples, rep, sums);
    return;
  }
  constexpr int kOrder[8] = {0, 1, 4, 5, 2, 3, 6, 7};
  alignas(64) float rotation_cos[kChunk];
  alignas(64) float rotation_sin[kChunk];
  alignas(64) float carrier_cos[kChunk];
  alignas(64) float carrier_sin[kChunk];
  const int table_n = num_samples < kChunk ? num_samples : kChunk;
  const int table_vec = table_n - table_n % 8;
  for (int i = 0; i < table_n; ++i) {
    const int sample = i < table_vec ? (i & ~7) + kOrder[i & 7] : i;  // lane order inside whole groups of 8
    float c, s;
    sincos_q32(rep.carrier_step_q32 * static_cast<std::uint32_t>(sample), c, s);
    rotation_cos[i] = c;
    rotation_sin[i] = s;
  }
  const int num_antennas = static_cast<int>(antennas.size());
  const __m256 vstep = _mm256_set1_ps(step_f);
  const __m256 lane_order = _mm256_setr_ps(0, 1, 4, 5, 2, 3, 6, 7);
  for (int start = 0; start < num_samples; start += kChunk) {
    const int n = num_samples - start < kChunk ? num_samples - start : kChunk;
    const int n_vec = n - n % 8;
    const std::uint32_t phase0 = rep.carrier_phase_q32 + rep.carrier_step_q32 * static_cast<std::uint32_t>(start);
    float c0, s0;
    sincos_q32(phase0, c0, s0);
    for (int i = 0; i < n_vec; ++i) {
      carrier_cos[i] = c0 * rotation_cos[i] - s0 * rotation_sin[i];
      carrier_sin[i] = s0 * rotation_cos[i] + c0 * rotation_sin[i];
    }
    const double code0 = rep.code_phase_chips + rep.code_step_chips * start + 2 * kCodeLength;
    const float* chips[kTaps];
    float frac[kTaps];
    __m256 vfrac[kTaps];
    for (int t = 0; t < kTaps; ++t) {
      const double base = code0 + offsets[t];
      const int whole = static_cast<int>(base);
      frac[t] = static_cast<float>(base - whole);
      chips[t] = table + whole;
      vfrac[t] = _mm256_set1_ps(frac[t]);
    }
    for (int a = 0; a < num_antennas; ++a) {
      const float* x = reinterpret_cast<const float*>(antennas[a] + start);
      __m256 acc_re[kTaps], acc_im[kTaps];
      for (int t = 0; t < kTaps; ++t) acc_re[t] = acc_im[t] = _mm256_setzero_ps();
      __m256 vi = lane_order;
      for (int i = 0; i < n_vec; i += 8) {
        const __m256 lo = _mm256_loadu_ps(x + 2 * i), hi = _mm256_loadu_ps(x + 2 * i + 8);
        const __m256 xr = _mm256_shuffle_ps(lo, hi, 0x88);  // samples 0 1 4 5 2 3 6 7, in-phase
        const __m256 xi = _mm256_shuffle_ps(lo, hi, 0xDD);  // quadrature
        const __m256 cr = _mm256_load_ps(carrier_cos + i), ci = _mm256_load_ps(carrier_sin + i);
        const __m256 wr = _mm256_fmadd_ps(xr, cr, _mm256_mul_ps(xi, ci));  // x * exp(-j phase)
        const __m256 wi = _mm256_fmsub_ps(xi, cr, _mm256_mul_ps(xr, ci));
        const __m256 advance = _mm256_mul_ps(vstep, vi);
        for (int t = 0; t < kTaps; ++t) {
          const __m256i index = _mm256_cvttps_epi32(_mm256_add_ps(vfrac[t], advance));
          const int first = _mm256_cvtsi256_si32(index);  // lane 0 is the group's first sample
          const __m256 code = _mm256_permutevar8x32_ps(_mm256_loadu_ps(chips[t] + first),
                                                       _mm256_sub_epi32(index, _mm256_set1_epi32(first)));
          acc_re[t] = _mm256_fmadd_ps(wr, code, acc_re[t]);
          acc_im[t] = _mm256_fmadd_ps(wi, code, acc_im[t]);
        }
        vi = _mm256_add_ps(vi, _mm256_set1_ps(8.0f));
      }
      alignas(32) float re[kTaps][8], im[kTaps][8];
      for (int t = 0; t < kTaps; ++t) {
        _mm256_store_ps(re[t], acc_re[t]);
        _mm256_store_ps(im[t], acc_im[t]);
      }
      for (int i = n_vec; i < n; ++i) {  // the last < 8 samples, natural order, carrier straight from the phase
        float cr, ci;
        sincos_q32(phase0 + rep.carrier_step_q32 * static_cast<std::uint32_t>(i), cr, ci);
        const float xr = x[2 * i], xi = x[2 * i + 1];
        const float wr = xr * cr + xi * ci;
        const float wi = xi * cr - xr * ci;
        for (int t = 0; t < kTaps; ++t) {
          const float code = chips[t][static_cast<int>(frac[t] + step_f * static_cast<float>(i))];
          re[t][0] += wr * code;
          im[t][0] += wi * code;
        }
      }
      for (int t = 0; t < kTaps; ++t) {
        double sum_re = 0.0, sum_im = 0.0;
        for (int l = 0; l < 8; ++l) {
          sum_re += re[t][l];
          sum_im += im[t][l];
        }
        sums[a][t] += std::complex<double>(sum_re, sum_im);
      }
    }
  }
}

// The AVX2 copy: 16 samples per step. Per group of taps sharing a fraction: the 16 relative chip indices
// (0..15, since step <= 0.99) as bytes, from two compares against per-call thresholds and two packs (the
// threshold lanes are laid out so that the packs give natural sample order); per tap: one 16-byte load of
// chips, one byte shuffle, a widening to int16, then two pmaddwd (in-phase, quadrature) into int32 lanes. The
// last n % 16 samples of a chunk go through the same step from a zero-padded copy (zero samples add nothing).
struct LaneIndexAvx2 {  // per call: thresholds 2^22 - 1 - g_l in pack order, whole parts h_l as bytes
  __m256i below_lo, below_hi;
  __m128i whole;
};

template <int kTaps, std::uint32_t kShare>
__attribute__((target("avx2,fma"), always_inline)) inline void avx2_chunk(
    const std::int16_t* xr_p, const std::int16_t* xi_p, int n, const CorrelatorEngine::Rotation& rot,
    const std::int8_t* const* base, const std::uint32_t* frac, std::uint32_t step, const LaneIndexAvx2& lanes,
    std::int64_t* re, std::int64_t* im) {
  __m256i acc_re[kTaps], acc_im[kTaps];
  for (int t = 0; t < kTaps; ++t) acc_re[t] = acc_im[t] = _mm256_setzero_si256();
  for (int i = 0; i < n; i += 16) {
    __m256i xr, xi;
    if (i + 16 <= n) {
      xr = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(xr_p + i));
      xi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(xi_p + i));
    } else {
      alignas(32) std::int16_t pr[16] = {}, pi[16] = {};
      std::memcpy(pr, xr_p + i, sizeof(std::int16_t) * static_cast<std::size_t>(n - i));
      std::memcpy(pi, xi_p + i, sizeof(std::int16_t) * static_cast<std::size_t>(n - i));
      xr = _mm256_load_si256(reinterpret_cast<const __m256i*>(pr));
      xi = _mm256_load_si256(reinterpret_cast<const __m256i*>(pi));
    }
    const __m256i rr = _mm256_load_si256(reinterpret_cast<const __m256i*>(rot.re + i));
    const __m256i ri = _mm256_load_si256(reinterpret_cast<const __m256i*>(rot.im + i));
    const __m256i wr = _mm256_adds_epi16(_mm256_mulhrs_epi16(xr, rr), _mm256_mulhrs_epi16(xi, ri));
    const __m256i wi = _mm256_subs_epi16(_mm256_mulhrs_epi16(xi, rr), _mm256_mulhrs_epi16(xr, ri));
    __m128i rel[kTaps];
    std::uint32_t first[kTaps];
#pragma GCC unroll 8
    for (int t = 0; t < kTaps; ++t) {
      const int lead = share_leader(kShare, t);
      if (lead == t) {
        const std::uint32_t p = frac[t] + step * static_cast<std::uint32_t>(i);
        first[t] = p >> kFracBits;
        const __m256i q = _mm256_set1_epi32(static_cast<int>(p & kFracMask));
        const __m256i carry =
            _mm256_packs_epi32(_mm256_cmpgt_epi32(q, lanes.below_lo), _mm256_cmpgt_epi32(q, lanes.below_hi));
        rel[t] = _mm_sub_epi8(lanes.whole,
                              _mm_packs_epi16(_mm256_castsi256_si128(carry), _mm256_extracti128_si256(carry, 1)));
      } else {
        rel[t] = rel[lead];
        first[t] = first[lead];
      }
      const __m128i window = _mm_loadu_si128(reinterpret_cast<const __m128i*>(base[t] + first[t]));
      const __m256i chips = _mm256_cvtepi8_epi16(_mm_shuffle_epi8(window, rel[t]));
      acc_re[t] = _mm256_add_epi32(acc_re[t], _mm256_madd_epi16(wr, chips));
      acc_im[t] = _mm256_add_epi32(acc_im[t], _mm256_madd_epi16(wi, chips));
    }
  }
  for (int t = 0; t < kTaps; ++t) {
    alignas(32) std::int32_t lr[8], li[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lr), acc_re[t]);
    _mm256_store_si256(reinterpret_cast<__m256i*>(li), acc_im[t]);
    re[t] = im[t] = 0;
    for (int l = 0; l < 8; ++l) {
      re[t] += lr[l];
      im[t] += li[l];
    }
  }
}

template <int kTaps, std::uint32_t kShare>
__attribute__((target("avx2,fma"))) void correlate_i16_avx2(const std::int8_t* table, const std::int16_t* table16,
                                                            const double* offsets, int num_taps,
                                                            std::span<const PlanarI16> antennas, int num_samples,
                                                            const ReplicaSegment& rep,
                                                            const CorrelatorEngine::Rotation& rot, double scale,
                                                            std::span<TapSums> sums) {
  if (!(rep.code_step_chips <= 0.99)) {  // 16 samples could span more than 16 chips
    correlate_i16_portable(table, table16, offsets, num_taps, antennas, num_samples, rep, rot, scale, sums);
    return;
  }
  const std::uint32_t step = step_q24(rep);
  // Compare lanes: the first vector holds samples 0-3 and 8-11, the second 4-7 and 12-15 (pack order).
  alignas(32) std::int32_t below[16];  // 2^22 - 1 - g_l: q > below <=> q >= 2^22 - g_l (signed compare, < 2^23)
  alignas(16) std::int8_t lane_whole[16];
  for (int l = 0; l < 16; ++l) {
    const std::uint32_t a = step * static_cast<std::uint32_t>(l);
    const int slot = (l & 4) ? 8 + (l & 3) + ((l & 8) ? 4 : 0) : (l & 3) + ((l & 8) ? 4 : 0);
    below[slot] = static_cast<std::int32_t>(kFracMask - (a & kFracMask));
    lane_whole[l] = static_cast<std::int8_t>(a >> kFracBits);
  }
  const LaneIndexAvx2 lanes{_mm256_load_si256(reinterpret_cast<const __m256i*>(below)),
                            _mm256_load_si256(reinterpret_cast<const __m256i*>(below + 8)),
                            _mm_load_si128(reinterpret_cast<const __m128i*>(lane_whole))};
  for (int start = 0; start < num_samples; start += kChunkI16) {
    const int n = num_samples - start < kChunkI16 ? num_samples - start : kChunkI16;
    int whole[kMaxTaps];
    std::uint32_t frac[kMaxTaps];
    chunk_taps(rep, offsets, kTaps, start, whole, frac);
    const std::int8_t* base[kTaps];
    bool shared = true;  // the engine's pattern holds in this chunk (equal fractions: exact, as in the portable copy)
    for (int t = 0; t < kTaps; ++t) {
      base[t] = table + whole[t];
      shared = shared && frac[share_leader(kShare, t)] == frac[t];
    }
    const std::uint32_t phase0 = chunk_phase(rep, rot.step_q32, start, n);
    for (std::size_t a = 0; a < antennas.size(); ++a) {
      std::int64_t re[kMaxTaps], im[kMaxTaps];
      if (kShare == no_sharing(kTaps) || !shared)
        avx2_chunk<kTaps, no_sharing(kTaps)>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step,
                                             lanes, re, im);
      else
        avx2_chunk<kTaps, kShare>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re,
                                  im);
      finish_chunk(re, im, kTaps, phase0, scale, sums[a]);
    }
  }
}

struct Avx2Kernels {
  template <int kTaps, std::uint32_t kShare>
  static constexpr CorrelatorEngine::KernelI16 get() {
    return &correlate_i16_avx2<kTaps, kShare>;
  }
};

}  // namespace

CorrelatorEngine::Kernel float_kernel_avx2(int num_taps) {
  switch (num_taps) {
    case 1:
      return &correlate_avx2<1>;
    case 2:
      return &correlate_avx2<2>;
    case 3:
      return &correlate_avx2<3>;
    case 4:
      return &correlate_avx2<4>;
    case 5:
      return &correlate_avx2<5>;
    default:
      return &correlate_avx2<6>;
  }
}

CorrelatorEngine::KernelI16 i16_kernel_avx2(int num_taps, std::uint32_t share) {
  switch (num_taps) {
    case 1:
      return select_shared<1, Avx2Kernels>(share);
    case 2:
      return select_shared<2, Avx2Kernels>(share);
    case 3:
      return select_shared<3, Avx2Kernels>(share);
    case 4:
      return select_shared<4, Avx2Kernels>(share);
    case 5:
      return select_shared<5, Avx2Kernels>(share);
    default:
      return select_shared<6, Avx2Kernels>(share);
  }
}

__attribute__((target("avx2,fma"))) void convert_planar_avx2(const std::complex<float>* in, int n, float gain,
                                                             std::int16_t* re, std::int16_t* im) {
  const float* x = reinterpret_cast<const float*>(in);
  const __m256 g = _mm256_set1_ps(gain), top = _mm256_set1_ps(32767.0f), bottom = _mm256_set1_ps(-32768.0f);
  const __m256i order = _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7);
#define ULTRATRACK_SCALED(p) \
  _mm256_cvtps_epi32(_mm256_max_ps(_mm256_min_ps(_mm256_mul_ps(_mm256_loadu_ps(p), g), top), bottom))
  const int n_vec = n - n % 16;
  for (int i = 0; i < n_vec; i += 16) {
    // Each 8-float load holds 4 samples. The int16 pack of two of them holds samples 0 1 4 5 | 2 3 6 7 (an
    // I/Q pair per 32-bit unit); one 32-bit permutation restores sample order, then I and Q are split by shuffles.
    const __m256i a = ULTRATRACK_SCALED(x + 2 * i), b = ULTRATRACK_SCALED(x + 2 * i + 8);
    const __m256i c = ULTRATRACK_SCALED(x + 2 * i + 16), d = ULTRATRACK_SCALED(x + 2 * i + 24);
    const __m256i ab = _mm256_permutevar8x32_epi32(_mm256_packs_epi32(a, b), order);
    const __m256i cd = _mm256_permutevar8x32_epi32(_mm256_packs_epi32(c, d), order);
    // now ab = r0 i0 r1 i1 ... r7 i7 (natural); split I/Q: byte shuffle within lanes, then 64-bit permute
    const __m256i split = _mm256_setr_epi8(0, 1, 4, 5, 8, 9, 12, 13, 2, 3, 6, 7, 10, 11, 14, 15, 0, 1, 4, 5, 8, 9, 12,
                                           13, 2, 3, 6, 7, 10, 11, 14, 15);
    const __m256i abs = _mm256_permute4x64_epi64(_mm256_shuffle_epi8(ab, split), 0xD8);  // [r0-7 | i0-7]
    const __m256i cds = _mm256_permute4x64_epi64(_mm256_shuffle_epi8(cd, split), 0xD8);  // [r8-15 | i8-15]
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(re + i), _mm256_permute2x128_si256(abs, cds, 0x20));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(im + i), _mm256_permute2x128_si256(abs, cds, 0x31));
  }
#undef ULTRATRACK_SCALED
  for (int i = n_vec; i < n; ++i) {
    re[i] = static_cast<std::int16_t>(std::nearbyint(std::clamp(x[2 * i] * gain, -32768.0f, 32767.0f)));
    im[i] = static_cast<std::int16_t>(std::nearbyint(std::clamp(x[2 * i + 1] * gain, -32768.0f, 32767.0f)));
  }
}

}  // namespace ultratrack::receiver::correlator_kernels
#endif
