// SPDX-License-Identifier: GPL-3.0-or-later
// Internal to the correlator engine: what its kernel files share (correlator_engine.cpp and
// correlator_kernel_float.cpp, correlator_kernel_i16.cpp, correlator_kernel_avx2.cpp, correlator_kernel_avx512.cpp):
// the fixed-point sin/cos, the float kernel's chunked body (inlined into each instruction-set copy), the integer
// kernel's chunk arithmetic, and each family's entry points by tap count. Not for use outside those files.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <span>

#include "receiver/correlator_engine.hpp"
#include "receiver/correlator_isa.hpp"
#include "signals/ca_code.hpp"

#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
#include <immintrin.h>
#endif

namespace ultratrack::receiver::correlator_kernels {

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

__attribute__((noinline)) void fill_code_baseline(const float* __restrict chips, float frac, float step, int n,
                                                  float* __restrict out);

template <int kTaps, CodeFill kFill>
ULTRATRACK_ALWAYS_INLINE void correlate_chunked(const float* table, const double* offsets,
                                                std::span<const std::complex<float>* const> antennas, int num_samples,
                                                const ReplicaSegment& rep, std::span<TapSums> sums) {
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
// 1023) < 2^32 over a 1024-sample chunk (index error < 1024 * 2^-23 = 1.2e-4 chips, reset each chunk). Taps a whole
// number of chips apart (early/late at +-0.5; prompt and the noise tap) have the same F_t and share one index
// computation. Sums: w * chip with |w| <= 32767 per component (saturating wipe-off), so one chunk's int32 lane sums
// stay below 64 * 2 * 32768 = 2^22 (AVX2: 64 pmaddwd per lane per chunk) and the int64 totals below 2^25: no overflow.
// Integer sums are exact, so both copies give bit-identical results (the double finish is shared).

constexpr int kChunkI16 = CorrelatorEngine::Rotation::kChunk;
constexpr int kFracBits = 22;
constexpr double kQ24 = 4194304.0;                     // 2^kFracBits
constexpr std::uint32_t kTableStepQuantum = 1u << 13;  // 2^-19 cycles per sample, in 2^-32 units

inline std::uint32_t table_step(std::uint32_t step_q32) {
  return (step_q32 + kTableStepQuantum / 2) & ~(kTableStepQuantum - 1);
}

// The phase to apply to a chunk of n samples starting at `start`: the NCO's phase at the chunk centre minus the
// table's rotation to that centre (2^-32 cycles, wrapping; exact integer arithmetic, ties to the lower half).
inline std::uint32_t chunk_phase(const ReplicaSegment& rep, std::uint32_t table_step_q32, int start, int n) {
  const std::uint32_t phase0 = rep.carrier_phase_q32 + rep.carrier_step_q32 * static_cast<std::uint32_t>(start);
  const auto delta = static_cast<std::int64_t>(static_cast<std::int32_t>(rep.carrier_step_q32 - table_step_q32));
  return phase0 + static_cast<std::uint32_t>((delta * (n - 1)) / 2);
}

__attribute__((noinline)) void build_rotation(std::uint32_t step_q32, CorrelatorEngine::Rotation& r);
// Per chunk and tap: the whole chip index (into the table) and the 22-bit fraction at the chunk's first sample.
__attribute__((noinline)) void chunk_taps(const ReplicaSegment& rep, const double* offsets, int num_taps, int start,
                                          int* whole, std::uint32_t* frac_q24);
// Adds one chunk's integer sums, rotated by the chunk's start phase and scaled, to an antenna's sums.
__attribute__((noinline)) void finish_chunk(const std::int64_t* re, const std::int64_t* im, int num_taps,
                                            std::uint32_t phase0, double scale, TapSums& sums);

ULTRATRACK_ALWAYS_INLINE std::int32_t mulhrs(std::int32_t a, std::int32_t b) { return (((a * b) >> 14) + 1) >> 1; }
ULTRATRACK_ALWAYS_INLINE std::int32_t sat16(std::int32_t v) { return v > 32767 ? 32767 : v < -32768 ? -32768 : v; }

// One sample's wipe-off and tap products, the portable copy's loop body (also the AVX2 copy's tail).
ULTRATRACK_ALWAYS_INLINE void mac_sample(std::int32_t xr, std::int32_t xi, std::int32_t rr, std::int32_t ri,
                                         const std::int8_t* table, const int* whole, const std::uint32_t* frac,
                                         std::uint32_t step_q24, int i, int num_taps, std::int64_t* re,
                                         std::int64_t* im) {
  const std::int32_t wr = sat16(mulhrs(xr, rr) + mulhrs(xi, ri));  // x * conj(r)
  const std::int32_t wi = sat16(mulhrs(xi, rr) - mulhrs(xr, ri));
  for (int t = 0; t < num_taps; ++t) {
    const std::int32_t chip =
        table[whole[t] +
              static_cast<int>((std::uint64_t{frac[t]} + std::uint64_t{step_q24} * static_cast<std::uint64_t>(i)) >>
                               kFracBits)];  // 64-bit: any step
    re[t] += wr * chip;
    im[t] += wi * chip;
  }
}
inline std::uint32_t step_q24(const ReplicaSegment& rep) {
  return static_cast<std::uint32_t>(std::lround(rep.code_step_chips * kQ24));
}

// The portable integer copy (also the vector copies' fallback for steps above 0.99 chips per sample).
void correlate_i16_portable(const std::int8_t* table, const std::int16_t* table16, const double* offsets, int num_taps,
                            std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& rep,
                            const CorrelatorEngine::Rotation& rot, double scale, std::span<TapSums> sums);

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

// A vector kernel for an engine's tap count and sharing pattern: the receiver's (early/prompt/late/noise;
// prompt/noise for further antennas; early/prompt/late) and the benchmarks' are compiled with sharing; any
// other pattern runs without it.
// Kernels: a struct with `template <int kTaps, std::uint32_t kShare> static KernelI16 get()`.
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

// Each family's copy for a tap count (1..kMaxTaps) and, for the integer vector copies, sharing pattern.
CorrelatorEngine::Kernel float_kernel_baseline(int num_taps);
CorrelatorEngine::KernelI16 i16_kernel_portable();
#ifdef ULTRATRACK_HAVE_AVX2_KERNEL
CorrelatorEngine::Kernel float_kernel_avx2(int num_taps);
CorrelatorEngine::KernelI16 i16_kernel_avx2(int num_taps, std::uint32_t share);
CorrelatorEngine::KernelI16 i16_kernel_avx512(int num_taps, std::uint32_t share);
void convert_planar_avx2(const std::complex<float>* in, int n, float gain, std::int16_t* re, std::int16_t* im);
#endif

}  // namespace ultratrack::receiver::correlator_kernels
