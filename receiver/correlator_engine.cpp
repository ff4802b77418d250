#include "receiver/correlator_engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <stdexcept>
#include <string>

#include "signals/ca_code.hpp"

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define ULTRATRACK_HAVE_AVX2_KERNEL 1
#include <immintrin.h>
#endif

namespace ultratrack::receiver {
namespace {

constexpr int kCodeLength = signals::kCaCodeLength_chips;
constexpr int kChunk = 256;  // samples per inner pass: the replica buffers stay in L1
constexpr int kLanes = 8;    // independent partial sums, so the compiler can vectorise without reassociation

// Force-inlined helpers: the kernel body below is compiled once per instruction set (see the wrappers), and only
// code inlined into a target("avx2,fma") wrapper is vectorised with AVX2.
#define ULTRATRACK_ALWAYS_INLINE inline __attribute__((always_inline))

// Quadrant rotation by integer arithmetic, then Taylor series on |theta| <= pi/4 (truncation < 3e-8).
ULTRATRACK_ALWAYS_INLINE void sincos_q32(std::uint32_t phase, float& c_out, float& s_out) {
  const std::uint32_t quadrant = ((phase + (1u << 29)) >> 30) & 3u;
  const auto residual = static_cast<std::int32_t>(phase - (quadrant << 30));  // [-2^29, 2^29)
  const float theta = static_cast<float>(residual) * static_cast<float>(2.0 * 3.14159265358979323846 / 4294967296.0);
  const float t2 = theta * theta;
  const float c = 1.0f + t2 * (-0.5f + t2 * (1.0f / 24 + t2 * (-1.0f / 720 + t2 * (1.0f / 40320))));
  const float s = theta * (1.0f + t2 * (-1.0f / 6 + t2 * (1.0f / 120 + t2 * (-1.0f / 5040 + t2 * (1.0f / 362880)))));
  c_out = quadrant == 0 ? c : quadrant == 1 ? -s : quadrant == 2 ? -c : s;
  s_out = quadrant == 0 ? s : quadrant == 1 ? c : quadrant == 2 ? -s : -c;
}

// Code chips of one tap over a chunk: out[i] = chips[int(frac + step * i)], frac in [0, 1). The float
// expression is the contract: every instruction-set copy evaluates it identically (no FMA), so the chips agree.
// The baseline fill is also the AVX2 copy's fallback, hence noinline (no contraction inside an AVX2 caller).
using CodeFill = void (*)(const float* chips, float frac, float step, int n, float* out);

__attribute__((noinline)) void fill_code_baseline(const float* __restrict chips, float frac, float step, int n, float* __restrict out) {
  for (int i = 0; i < n; ++i) out[i] = chips[static_cast<int>(frac + step * static_cast<float>(i))];
}


template <int kTaps, CodeFill kFill>
ULTRATRACK_ALWAYS_INLINE void correlate_chunked(const float* table, const double* offsets, std::span<const std::complex<float>* const> antennas,
                       int num_samples, const ReplicaSegment& rep, std::span<TapSums> sums) {
  alignas(64) float carrier_cos[kChunk];
  alignas(64) float carrier_sin[kChunk];
  alignas(64) float code[kTaps][kChunk];
  const int num_antennas = static_cast<int>(antennas.size());

  // The carrier over a chunk is its exact first-sample phasor (fixed point, so nothing accumulates across
  // chunks) times a rotation table that every chunk of this call shares: one complex product per sample
  // instead of a polynomial sin/cos. Error < 3e-6 (two sin/cos errors plus float rounding).
  alignas(64) float rotation_cos[kChunk];
  alignas(64) float rotation_sin[kChunk];
  const int table_n = num_samples < kChunk ? num_samples : kChunk;
  for (int i = 0; i < table_n; ++i) {
    float c, s;
    sincos_q32(rep.carrier_step_q32 * static_cast<std::uint32_t>(i), c, s);
    rotation_cos[i] = c;
    rotation_sin[i] = s;
  }

  for (int start = 0; start < num_samples; start += kChunk) {
    const int n = num_samples - start < kChunk ? num_samples - start : kChunk;
    const std::uint32_t phase0 = rep.carrier_phase_q32 + rep.carrier_step_q32 * static_cast<std::uint32_t>(start);
    float c0, s0;
    sincos_q32(phase0, c0, s0);
    for (int i = 0; i < n; ++i) {
      carrier_cos[i] = c0 * rotation_cos[i] - s0 * rotation_sin[i];
      carrier_sin[i] = s0 * rotation_cos[i] + c0 * rotation_sin[i];
    }
    const double code0 = rep.code_phase_chips + rep.code_step_chips * start + 2 * kCodeLength;  // table origin
    // Chip index = whole part of the chunk's start (exact, integer) + float offset within the chunk: the float
    // part stays below ~kChunk * step chips, so its rounding is < 1e-5 chips and never accumulates.
    const auto step_f = static_cast<float>(rep.code_step_chips);
    for (int t = 0; t < kTaps; ++t) {
      const double base = code0 + offsets[t];
      const int whole = static_cast<int>(base);
      const auto frac = static_cast<float>(base - whole);
      kFill(table + whole, frac, step_f, n, code[t]);
    }
    for (int a = 0; a < num_antennas; ++a) {
      const float* __restrict x = reinterpret_cast<const float*>(antennas[a] + start);
      float acc_re[kTaps][kLanes] = {};
      float acc_im[kTaps][kLanes] = {};
      const int n_lanes = n - n % kLanes;
      for (int i = 0; i < n_lanes; i += kLanes) {
        for (int l = 0; l < kLanes; ++l) {
          const float xr = x[2 * (i + l)], xi = x[2 * (i + l) + 1];
          const float cr = carrier_cos[i + l], ci = carrier_sin[i + l];
          // x * exp(-j phase)
          const float wr = xr * cr + xi * ci;
          const float wi = xi * cr - xr * ci;
          for (int t = 0; t < kTaps; ++t) {
            acc_re[t][l] += wr * code[t][i + l];
            acc_im[t][l] += wi * code[t][i + l];
          }
        }
      }
      for (int i = n_lanes; i < n; ++i) {
        const float xr = x[2 * i], xi = x[2 * i + 1];
        const float wr = xr * carrier_cos[i] + xi * carrier_sin[i];
        const float wi = xi * carrier_cos[i] - xr * carrier_sin[i];
        for (int t = 0; t < kTaps; ++t) {
          acc_re[t][0] += wr * code[t][i];
          acc_im[t][0] += wi * code[t][i];
        }
      }
      for (int t = 0; t < kTaps; ++t) {
        double re = 0.0, im = 0.0;
        for (int l = 0; l < kLanes; ++l) {
          re += acc_re[t][l];
          im += acc_im[t][l];
        }
        sums[a][t] += std::complex<double>(re, im);
      }
    }
  }
}

// One copy of the kernel per instruction set. Explicit lanes fix the summation order and the chip indices are
// identical; the AVX2 copy fuses multiply-adds (GCC's default -ffp-contract=fast), so the sums differ from the
// baseline copy's by float rounding only (~1e-7 relative).
template <int kTaps>
void correlate_baseline(const float* table, const double* offsets, std::span<const std::complex<float>* const> antennas,
                        int num_samples, const ReplicaSegment& rep, std::span<TapSums> sums) {
  correlate_chunked<kTaps, fill_code_baseline>(table, offsets, antennas, num_samples, rep, sums);
}

#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
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
#endif

// ---- The integer kernel ------------------------------------------------------------------------------------
// Samples: planar int16. Carrier: the wipe-off multiplies by a Q15 rotation table r_i = exp(j 2 pi s_t i),
// i < Rotation::kChunk, shared by every chunk of kChunk samples; the chunk's own phase is applied to the chunk's
// integer sums afterwards, in double, from the exact 32-bit NCO phase:
//   sum_i x_i exp(-j(phi_c + s_t (i - m))) c_i = exp(-j(phi_c - s_t m)) * sum_i (x_i conj(r_i)) c_i,
// m = (n - 1) / 2 the chunk's centre and phi_c = phi0 + s m the NCO's phase there, so nothing accumulates
// across chunks or calls. The table's step s_t is the NCO step s rounded to 2^-19 cycles per sample (a table
// is rebuilt only when that moves, not every epoch): inside a chunk the replica's phase departs from the NCO's
// by |s - s_t| |i - m| <= 2^-20 * 512 = 4.9e-4 cycles, zero at the centre (loss ~1e-6 dB). Loss from
// quantisation: the table's rounding (0.5 / 32767 of amplitude) and the wipe-off's rounding to int16 (0.5 of a
// sample scaled to ~2^11 rms) are noise ~70 dB below the input noise: < 0.01 dB measured on a clean signal
// (test: CorrelatorEngine.IntegerKernelFollowsDirichletAndLosesUnder0p01Db), ~1e-6 dB in noise.
// Code: chip index of tap t at sample i of a chunk = whole_t + ((F_t + S i) >> 22), F_t the 22-bit fraction of
// the tap's code phase at the chunk start, S = round(step * 2^22) <= 0.99 * 2^22, so F_t + S i < 2^22 (1 + 0.99 *
// 1023) < 2^32 over a 1024-sample chunk (index error < 1024 * 2^-23 = 1.2e-4 chips, reset each chunk). Taps a whole number of chips
// apart (early/late at +-0.5; prompt and the noise tap) have the same F_t and share one index computation.
// Sums: w * chip with |w| <= 32767 per component (saturating wipe-off), so one chunk's int32 lane sums stay
// below 64 * 2 * 32768 = 2^22 (AVX2: 64 pmaddwd per lane per chunk) and the int64 totals below 2^25: no
// overflow. Integer sums are exact, so both copies give bit-identical results (the double finish is shared).

constexpr int kChunkI16 = CorrelatorEngine::Rotation::kChunk;
constexpr int kFracBits = 22;
constexpr double kQ24 = 4194304.0;  // 2^kFracBits
constexpr std::uint32_t kTableStepQuantum = 1u << 13;  // 2^-19 cycles per sample, in 2^-32 units

std::uint32_t table_step(std::uint32_t step_q32) {
  return (step_q32 + kTableStepQuantum / 2) & ~(kTableStepQuantum - 1);
}

// The phase to apply to a chunk of n samples starting at `start`: the NCO's phase at the chunk centre minus the
// table's rotation to that centre (2^-32 cycles, wrapping; exact integer arithmetic, ties to the lower half).
std::uint32_t chunk_phase(const ReplicaSegment& rep, std::uint32_t table_step_q32, int start, int n) {
  const std::uint32_t phase0 = rep.carrier_phase_q32 + rep.carrier_step_q32 * static_cast<std::uint32_t>(start);
  const auto delta = static_cast<std::int64_t>(static_cast<std::int32_t>(rep.carrier_step_q32 - table_step_q32));
  return phase0 + static_cast<std::uint32_t>((delta * (n - 1)) / 2);
}

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

// Per chunk and tap: the whole chip index (into the table) and the 22-bit fraction at the chunk's first sample.
__attribute__((noinline)) void chunk_taps(const ReplicaSegment& rep, const double* offsets, int num_taps, int start,
                                          int* whole, std::uint32_t* frac_q24) {
  const double code0 = rep.code_phase_chips + rep.code_step_chips * start + 2 * kCodeLength;  // table origin
  for (int t = 0; t < num_taps; ++t) {
    const double base = code0 + offsets[t];
    whole[t] = static_cast<int>(base);
    frac_q24[t] = static_cast<std::uint32_t>((base - whole[t]) * kQ24);
  }
}

// Adds one chunk's integer sums, rotated by the chunk's start phase and scaled, to an antenna's sums.
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

ULTRATRACK_ALWAYS_INLINE std::int32_t mulhrs(std::int32_t a, std::int32_t b) { return (((a * b) >> 14) + 1) >> 1; }
ULTRATRACK_ALWAYS_INLINE std::int32_t sat16(std::int32_t v) { return v > 32767 ? 32767 : v < -32768 ? -32768 : v; }

// One sample's wipe-off and tap products, the portable copy's loop body (also the AVX2 copy's tail).
ULTRATRACK_ALWAYS_INLINE void mac_sample(std::int32_t xr, std::int32_t xi, std::int32_t rr, std::int32_t ri, const std::int8_t* table,
                                         const int* whole, const std::uint32_t* frac, std::uint32_t step_q24, int i,
                                         int num_taps, std::int64_t* re, std::int64_t* im) {
  const std::int32_t wr = sat16(mulhrs(xr, rr) + mulhrs(xi, ri));  // x * conj(r)
  const std::int32_t wi = sat16(mulhrs(xi, rr) - mulhrs(xr, ri));
  for (int t = 0; t < num_taps; ++t) {
    const std::int32_t chip = table[whole[t] + static_cast<int>((std::uint64_t{frac[t]} + std::uint64_t{step_q24} * static_cast<std::uint64_t>(i)) >> kFracBits)];  // 64-bit: any step
    re[t] += wr * chip;
    im[t] += wi * chip;
  }
}

std::uint32_t step_q24(const ReplicaSegment& rep) { return static_cast<std::uint32_t>(std::lround(rep.code_step_chips * kQ24)); }

void correlate_i16_portable(const std::int8_t* table, const std::int16_t* /*table16*/, const double* offsets, int num_taps,
                            std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& rep,
                            const CorrelatorEngine::Rotation& rot, double scale, std::span<TapSums> sums) {
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
      for (int i = 0; i < n; ++i) mac_sample(xr[i], xi[i], rot.re[i], rot.im[i], table, whole, frac, step, i, num_taps, re, im);
      finish_chunk(re, im, num_taps, phase0, scale, sums[a]);
    }
  }
}

// Chip indices of a group of L samples without a multiply or a shift per lane: with S l = h_l 2^22 + g_l
// (g_l < 2^22) fixed per call, the index of lane l relative to the group's first chip, for the group's 22-bit
// fraction q, is floor((q + S l) / 2^22) = h_l + [q + g_l >= 2^22] = h_l + [q >= 2^22 - g_l]: one compare
// against a per-call threshold per lane (exactly the portable copy's index, as q + g_l < 2^23).
constexpr std::uint32_t kFracMask = (1u << kFracBits) - 1;

// Which taps reuse another tap's chip indices, fixed per engine (taps whole chips apart, e.g. early/late at
// +-0.5 and prompt/noise): 3 bits per tap, the index of the tap whose indices it reuses (itself if none).
// A compile-time pattern, so that the shared indices stay in registers (a pattern read at run time made the
// compiler keep them in memory and cost more than it saved).
constexpr int share_leader(std::uint32_t share, int t) { return static_cast<int>((share >> (3 * t)) & 7u); }
constexpr std::uint32_t share_code(std::initializer_list<int> leaders) {
  std::uint32_t code = 0;
  int t = 0;
  for (const int l : leaders) code |= static_cast<std::uint32_t>(l) << (3 * t++);
  return code;
}
constexpr std::uint32_t no_sharing(int taps) {
  std::uint32_t code = 0;
  for (int t = 0; t < taps; ++t) code |= static_cast<std::uint32_t>(t) << (3 * t);
  return code;
}

#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
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
__attribute__((target("avx2,fma"), always_inline)) inline void avx2_chunk(const std::int16_t* xr_p, const std::int16_t* xi_p, int n,
                                                                         const CorrelatorEngine::Rotation& rot,
                                                                         const std::int8_t* const* base, const std::uint32_t* frac,
                                                                         std::uint32_t step, const LaneIndexAvx2& lanes,
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
        const __m256i carry = _mm256_packs_epi32(_mm256_cmpgt_epi32(q, lanes.below_lo), _mm256_cmpgt_epi32(q, lanes.below_hi));
        rel[t] = _mm_sub_epi8(lanes.whole, _mm_packs_epi16(_mm256_castsi256_si128(carry), _mm256_extracti128_si256(carry, 1)));
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
                                                           const ReplicaSegment& rep, const CorrelatorEngine::Rotation& rot,
                                                           double scale, std::span<TapSums> sums) {
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
        avx2_chunk<kTaps, no_sharing(kTaps)>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re, im);
      else
        avx2_chunk<kTaps, kShare>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re, im);
      finish_chunk(re, im, kTaps, phase0, scale, sums[a]);
    }
  }
}

// Sum of the 16 int32 lanes. Zero-masked extracts: GCC 12's plain ones (and _mm512_reduce_add_epi32,
// _mm512_castsi512_si256) warn about an undefined register.
__attribute__((target("avx2,avx512f"), always_inline)) inline std::int32_t lane_sum(__m512i v) {
  const __m256i h = _mm256_add_epi32(_mm512_maskz_extracti64x4_epi64(0xFF, v, 0), _mm512_maskz_extracti64x4_epi64(0xFF, v, 1));
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
        const __mmask32 carry = _mm512_kunpackw(_mm512_cmpge_epu32_mask(q, lanes.threshold_hi), _mm512_cmpge_epu32_mask(q, lanes.threshold_lo));
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
        avx512_chunk<kTaps, no_sharing(kTaps)>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re, im);
      else
        avx512_chunk<kTaps, kShare>(antennas[a].re + start, antennas[a].im + start, n, rot, base, frac, step, lanes, re, im);
      finish_chunk(re, im, kTaps, phase0, scale, sums[a]);
    }
  }
}

// A vector kernel for an engine's tap count and sharing pattern: the receiver's (early/prompt/late/noise;
// prompt/noise for further antennas; early/prompt/late) and the benchmarks' are compiled with sharing; any
// other pattern runs without it.
struct Avx2Kernels {
  template <int kTaps, std::uint32_t kShare>
  static constexpr CorrelatorEngine::KernelI16 get() { return &correlate_i16_avx2<kTaps, kShare>; }
};
struct Avx512Kernels {
  template <int kTaps, std::uint32_t kShare>
  static constexpr CorrelatorEngine::KernelI16 get() { return &correlate_i16_avx512<kTaps, kShare>; }
};

template <int kTaps, class Kernels>
CorrelatorEngine::KernelI16 select_shared(std::uint32_t share) {
  constexpr std::uint32_t kPatterns[] = {share_code({0, 0}),          share_code({0, 1, 0}),
                                         share_code({0, 1, 1}),       share_code({0, 1, 0, 1}),
                                         share_code({0, 1, 1, 0, 0}), share_code({0, 1, 0, 1, 0})};
#define ULTRATRACK_SHARE_CASE(k) \
  if (share == kPatterns[k]) return Kernels::template get<kTaps, kPatterns[k]>();
  if constexpr (kTaps == 2) ULTRATRACK_SHARE_CASE(0)
  if constexpr (kTaps == 3) {
    ULTRATRACK_SHARE_CASE(1)
    ULTRATRACK_SHARE_CASE(2)
  }
  if constexpr (kTaps == 4) ULTRATRACK_SHARE_CASE(3)
  if constexpr (kTaps == 5) {
    ULTRATRACK_SHARE_CASE(4)
    ULTRATRACK_SHARE_CASE(5)
  }
#undef ULTRATRACK_SHARE_CASE
  return Kernels::template get<kTaps, no_sharing(kTaps)>();
}

__attribute__((target("avx2,fma"))) void convert_planar_avx2(const std::complex<float>* in, int n, float gain, std::int16_t* re,
                                                            std::int16_t* im) {
  const float* x = reinterpret_cast<const float*>(in);
  const __m256 g = _mm256_set1_ps(gain), top = _mm256_set1_ps(32767.0f), bottom = _mm256_set1_ps(-32768.0f);
  const __m256i order = _mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7);
#define ULTRATRACK_SCALED(p) _mm256_cvtps_epi32(_mm256_max_ps(_mm256_min_ps(_mm256_mul_ps(_mm256_loadu_ps(p), g), top), bottom))
  const int n_vec = n - n % 16;
  for (int i = 0; i < n_vec; i += 16) {
    // Each 8-float load holds 4 samples. The int16 pack of two of them holds samples 0 1 4 5 | 2 3 6 7 (an
    // I/Q pair per 32-bit unit); one 32-bit permutation restores sample order, then I and Q are split by shuffles.
    const __m256i a = ULTRATRACK_SCALED(x + 2 * i), b = ULTRATRACK_SCALED(x + 2 * i + 8);
    const __m256i c = ULTRATRACK_SCALED(x + 2 * i + 16), d = ULTRATRACK_SCALED(x + 2 * i + 24);
    const __m256i ab = _mm256_permutevar8x32_epi32(_mm256_packs_epi32(a, b), order);
    const __m256i cd = _mm256_permutevar8x32_epi32(_mm256_packs_epi32(c, d), order);
    // now ab = r0 i0 r1 i1 ... r7 i7 (natural); split I/Q: byte shuffle within lanes, then 64-bit permute
    const __m256i split = _mm256_setr_epi8(0, 1, 4, 5, 8, 9, 12, 13, 2, 3, 6, 7, 10, 11, 14, 15, 0, 1, 4, 5, 8, 9, 12, 13, 2, 3,
                                           6, 7, 10, 11, 14, 15);
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
#endif

// The instruction set is chosen once per process from the running CPU (the build targets baseline x86-64);
// ULTRATRACK_CORRELATOR_ISA (baseline, avx2, avx512) caps the choice (tests and benchmarks of every copy).
bool cpu_has_avx2() {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
#else
  return false;
#endif
}

bool cpu_has_avx512() {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  static const bool has = [] {
    __builtin_cpu_init();
    return cpu_has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512vnni");
  }();
  return has;
#else
  return false;
#endif
}

bool isa_available(CorrelatorIsa isa) {
  switch (isa) {
    case CorrelatorIsa::kAvx2:
      return cpu_has_avx2();
    case CorrelatorIsa::kAvx512:
      return cpu_has_avx512();
    default:
      return true;
  }
}

CorrelatorIsa auto_isa() {
  static const CorrelatorIsa chosen = [] {
    const char* forced = std::getenv("ULTRATRACK_CORRELATOR_ISA");
    const std::string cap = forced != nullptr ? forced : "";
    if (cap == "baseline") return CorrelatorIsa::kBaseline;
    if (cpu_has_avx512() && cap != "avx2") return CorrelatorIsa::kAvx512;
    return cpu_has_avx2() ? CorrelatorIsa::kAvx2 : CorrelatorIsa::kBaseline;
  }();
  return chosen;
}

CorrelatorIsa resolve_isa(CorrelatorIsa isa) {
  if (isa == CorrelatorIsa::kAuto) return auto_isa();
  if (!isa_available(isa))
    throw std::invalid_argument(isa == CorrelatorIsa::kAvx2 ? "CorrelatorEngine: AVX2+FMA kernel not available here"
                                                            : "CorrelatorEngine: AVX-512 BW/VL/VNNI kernel not available here");
  return isa;
}

template <int kTaps>
CorrelatorEngine::Kernel select_kernel([[maybe_unused]] CorrelatorIsa isa) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (isa != CorrelatorIsa::kBaseline) return &correlate_avx2<kTaps>;  // no AVX-512 float copy
#endif
  return &correlate_baseline<kTaps>;
}

template <int kTaps>
CorrelatorEngine::KernelI16 select_kernel_i16([[maybe_unused]] CorrelatorIsa isa, [[maybe_unused]] std::uint32_t share) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (isa == CorrelatorIsa::kAvx512) return select_shared<kTaps, Avx512Kernels>(share);
  if (isa == CorrelatorIsa::kAvx2) return select_shared<kTaps, Avx2Kernels>(share);
#endif
  return &correlate_i16_portable;
}

}  // namespace

bool correlator_avx2_available() { return cpu_has_avx2(); }
bool correlator_isa_available(CorrelatorIsa isa) { return isa_available(isa); }
CorrelatorIsa correlator_auto_isa() { return auto_isa(); }

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
  for (int i = 0; i < static_cast<int>(table_i8_.size()); ++i) table_i8_[i] = static_cast<std::int8_t>(chips[i % kCodeLength]);
  table_i16_.resize(table_.size() + 64);  // the AVX-512 copy reads 32-word windows past the last chip used
  for (int i = 0; i < static_cast<int>(table_i16_.size()); ++i) table_i16_[i] = static_cast<std::int16_t>(chips[i % kCodeLength]);
  const CorrelatorIsa level = resolve_isa(isa);
  std::uint32_t share = 0;  // per tap: the first tap a whole number of chips from it (the AVX-512 copy's pattern)
  for (int t = 0; t < num_taps_; ++t) {
    int lead = t;
    for (int u = 0; u < t && lead == t; ++u)
      if (const double d = offsets_[t] - offsets_[u]; d == std::floor(d)) lead = u;
    share |= static_cast<std::uint32_t>(lead) << (3 * t);
  }
  switch (num_taps_) {
    case 1: kernel_ = select_kernel<1>(level); kernel_i16_ = select_kernel_i16<1>(level, share); break;
    case 2: kernel_ = select_kernel<2>(level); kernel_i16_ = select_kernel_i16<2>(level, share); break;
    case 3: kernel_ = select_kernel<3>(level); kernel_i16_ = select_kernel_i16<3>(level, share); break;
    case 4: kernel_ = select_kernel<4>(level); kernel_i16_ = select_kernel_i16<4>(level, share); break;
    case 5: kernel_ = select_kernel<5>(level); kernel_i16_ = select_kernel_i16<5>(level, share); break;
    default: kernel_ = select_kernel<6>(level); kernel_i16_ = select_kernel_i16<6>(level, share); break;
  }
}

void CorrelatorEngine::correlate_i16(std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& replica,
                                     double scale, std::span<TapSums> sums) const {
  const std::uint32_t step = table_step(replica.carrier_step_q32);
  if (!rotation_.valid || rotation_.step_q32 != step) build_rotation(step, rotation_);
  kernel_i16_(table_i8_.data(), table_i16_.data(), offsets_.data(), num_taps_, antennas, num_samples, replica, rotation_, scale, sums);
}

void convert_to_planar_i16(const std::complex<float>* in, int n, float gain, std::int16_t* re, std::int16_t* im) {
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
  if (auto_isa() != CorrelatorIsa::kBaseline) {
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
