// SPDX-License-Identifier: GPL-3.0-or-later
// Correlator engine: the hot path's single home. Carrier wipe-off and up to kMaxTaps code correlators (very
// early, early, prompt, late, very late, noise: any set of code offsets in chips) over one block of complex
// baseband samples, for 1..kMaxAntennas antennas against one replica in one pass. Code chips come from a table
// built once per PRN; the carrier from a 32-bit fixed-point phase and a polynomial sin/cos (|error| < 1e-6).
// No allocation, no exceptions per call. Two copies chosen once at run time from the CPU's features: portable
// C++ written for auto-vectorisation (baseline x86-64), and AVX2+FMA intrinsics with the code fill fused into the
// multiply-accumulate loop (same chip indices as the portable copy; sums equal to float rounding).
// An integer copy (correlate_i16) takes planar int16 samples: int16 carrier wipe-off against a Q15 rotation
// table, +-1 chips from one index computation per group of taps a whole number of chips apart, pmaddwd-style
// multiply-adds into int32, and the chunk's exact carrier phase applied to the sums afterwards (the derivation:
// correlator_kernels.hpp). Three copies (portable, AVX2, AVX-512 BW+VL+VNNI: 32 samples per step), bit-identical.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <span>
#include <vector>

#include "receiver/correlation_epoch.hpp"

namespace ultratrack::receiver {

inline constexpr int kMaxTaps = 6;

// Which copy of the kernel an engine runs: the best one the CPU has (kAuto), or one named (tests comparing
// copies in one process; a level the CPU or the build lacks throws std::invalid_argument: see
// correlator_isa_available()). kAvx512 is the integer kernel's AVX-512 BW+VL+VNNI copy (the float kernel has
// no AVX-512 copy and runs its AVX2 one there). The environment variable ULTRATRACK_CORRELATOR_ISA = baseline,
// avx2 or avx512 caps what kAuto picks (tests and benchmarks of every copy on one machine; correlator_isa.cpp).
enum class CorrelatorIsa { kAuto, kBaseline, kAvx2, kAvx512 };
bool correlator_isa_available(CorrelatorIsa isa);
bool correlator_avx2_available();
// The level kAuto resolves to in this process (after ULTRATRACK_CORRELATOR_ISA): kBaseline, kAvx2 or kAvx512.
CorrelatorIsa correlator_auto_isa();

// The replica over one block: prompt code phase at the first sample, chips, measured from a code period start
// and within [-1023, 2046), with at most 1023 chips covered by the block (so that every tap stays in the
// engine's 5-period table); code step in chips per sample; carrier phase at the first sample and its step per sample in
// 2^-32 cycles (wrapping).
struct ReplicaSegment {
  double code_phase_chips = 0.0;
  double code_step_chips = 0.0;
  std::uint32_t carrier_phase_q32 = 0;
  std::uint32_t carrier_step_q32 = 0;
};

// Sums per tap (in the order of the engine's offsets) for one antenna.
using TapSums = std::array<std::complex<double>, kMaxTaps>;

// One antenna's block of samples as planar int16 (in-phase and quadrature arrays), for the integer kernel.
struct PlanarI16 {
  const std::int16_t* re = nullptr;
  const std::int16_t* im = nullptr;
};

class CorrelatorEngine final {
 public:
  // tap_offsets_chips: code offset of each tap relative to prompt, chips, |offset| <= 1023 (positive = early:
  // the tap reads the code that many chips ahead of prompt). At most kMaxTaps taps. Throws std::invalid_argument.
  CorrelatorEngine(int prn, std::span<const double> tap_offsets_chips, CorrelatorIsa isa = CorrelatorIsa::kAuto);

  int num_taps() const { return num_taps_; }
  int prn() const { return prn_; }

  // Adds to sums[a][t] the correlation of antennas[a][0..num_samples) with tap t of the replica.
  // Preconditions: antennas.size() == sums.size() <= kMaxAntennas; the replica stays inside the table.
  void correlate(std::span<const std::complex<float>* const> antennas, int num_samples, const ReplicaSegment& replica,
                 std::span<TapSums> sums) const;

  // The integer kernel: the same correlations from int16 samples, added to sums times `scale` (1 / the gain
  // that made the int16 samples, so the sums are in the float kernel's units). Loss against the float kernel
  // < 0.01 dB (Q15 carrier, see the .cpp); AVX2 and portable copies give bit-identical sums. Samples should
  // stay within +-16384 per component (larger ones saturate in the wipe-off, never wrap).
  // Not safe to call concurrently on one engine (a carrier rotation table is cached per carrier step).
  void correlate_i16(std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& replica, double scale,
                     std::span<TapSums> sums) const;

 public:
  // One instruction-set-specific copy of the kernel for this engine's tap count, picked at construction.
  using Kernel = void (*)(const float* table, const double* offsets,
                          std::span<const std::complex<float>* const> antennas, int num_samples,
                          const ReplicaSegment& replica, std::span<TapSums> sums);
  // The carrier rotation over one chunk of the integer kernel, Q15, for one carrier step (cached: the two
  // halves of an epoch and every antenna share it).
  struct Rotation {
    static constexpr int kChunk = 1024;
    alignas(64) std::int16_t re[kChunk];
    alignas(64) std::int16_t im[kChunk];
    std::uint32_t step_q32 = 0;
    bool valid = false;
  };
  using KernelI16 = void (*)(const std::int8_t* table, const std::int16_t* table16, const double* offsets, int num_taps,
                             std::span<const PlanarI16> antennas, int num_samples, const ReplicaSegment& replica,
                             const Rotation& rotation, double scale, std::span<TapSums> sums);

 private:
  int prn_;
  int num_taps_;
  std::array<double, kMaxTaps> offsets_{};
  std::vector<float> table_;  // 5 code periods of +1/-1 chips (float: no conversion per sample): index = chip + 2046
  std::vector<std::int8_t> table_i8_;    // the same chips as int8 (the integer kernel's byte shuffles)
  std::vector<std::int16_t> table_i16_;  // and as int16 (the AVX-512 copy's word permutes)
  Kernel kernel_ = nullptr;
  KernelI16 kernel_i16_ = nullptr;
  mutable Rotation rotation_;
};

// Converts complex float samples to planar int16: round(x * gain), saturated to int16. AVX2 where the CPU has
// it (same results as the portable loop: round to nearest even in both). Allocates nothing.
void convert_to_planar_i16(const std::complex<float>* in, int n, float gain, std::int16_t* re, std::int16_t* im);

// A lag (chips, -723..-300: the noise replica lags prompt) where this PRN's periodic autocorrelation is -1/1023 at that
// lag and its two neighbours on each side: a replica shifted by it sees noise only, whatever the fractional code error.
// Throws for bad PRNs.
double noise_tap_offset_chips(int prn);

// cos and sin of 2*pi*phase for a 2^-32-cycle fixed-point phase; |error| < 1e-6. Exposed for tests.
void fixed_point_sincos(std::uint32_t phase_q32, float* cos_out, float* sin_out);

}  // namespace ultratrack::receiver
