// SPDX-License-Identifier: GPL-3.0-or-later
// The float kernel's portable copy: C++ written for auto-vectorisation on baseline x86-64.
#include "receiver/correlator_kernels.hpp"

namespace ultratrack::receiver::correlator_kernels {
namespace {

// One copy of the kernel per instruction set. Explicit lanes fix the summation order and the chip indices are
// identical; the AVX2 copy fuses multiply-adds (GCC's default -ffp-contract=fast), so the sums differ from the
// baseline copy's by float rounding only (~1e-7 relative).
template <int kTaps>
void correlate_baseline(const float* table, const double* offsets, std::span<const std::complex<float>* const> antennas,
                        int num_samples, const ReplicaSegment& rep, std::span<TapSums> sums) {
  correlate_chunked<kTaps, fill_code_baseline>(table, offsets, antennas, num_samples, rep, sums);
}

}  // namespace

__attribute__((noinline)) void fill_code_baseline(const float* __restrict chips, float frac, float step, int n,
                                                  float* __restrict out) {
  for (int i = 0; i < n; ++i) out[i] = chips[static_cast<int>(frac + step * static_cast<float>(i))];
}

CorrelatorEngine::Kernel float_kernel_baseline(int num_taps) {
  switch (num_taps) {
    case 1:
      return &correlate_baseline<1>;
    case 2:
      return &correlate_baseline<2>;
    case 3:
      return &correlate_baseline<3>;
    case 4:
      return &correlate_baseline<4>;
    case 5:
      return &correlate_baseline<5>;
    default:
      return &correlate_baseline<6>;
  }
}

}  // namespace ultratrack::receiver::correlator_kernels
