// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/correlator_isa.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace ultratrack::receiver {
namespace {

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
    throw std::invalid_argument(isa == CorrelatorIsa::kAvx2
                                    ? "CorrelatorEngine: AVX2+FMA kernel not available here"
                                    : "CorrelatorEngine: AVX-512 BW/VL/VNNI kernel not available here");
  return isa;
}

}  // namespace

bool correlator_avx2_available() { return cpu_has_avx2(); }
bool correlator_isa_available(CorrelatorIsa isa) { return isa_available(isa); }
CorrelatorIsa correlator_auto_isa() { return auto_isa(); }
CorrelatorIsa resolve_correlator_isa(CorrelatorIsa isa) { return resolve_isa(isa); }

}  // namespace ultratrack::receiver
