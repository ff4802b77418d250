// SPDX-License-Identifier: GPL-3.0-or-later
// The correlator's instruction-set copies: which ones this build has (ULTRATRACK_HAVE_AVX2_KERNEL: GCC-compatible
// compiler on x86, the AVX2 and AVX-512 copies compiled per function with target attributes) and the level an
// engine runs. The public choice (CorrelatorIsa, correlator_isa_available, correlator_auto_isa, the
// ULTRATRACK_CORRELATOR_ISA cap) is declared in correlator_engine.hpp; CPU feature detection is in
// correlator_isa.cpp, decided once per process.
#pragma once

#include "receiver/correlator_engine.hpp"

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define ULTRATRACK_HAVE_AVX2_KERNEL 1
#endif

namespace ultratrack::receiver {

// The level an engine asked for `isa` runs: kAuto resolved (correlator_auto_isa); a named level the CPU or the
// build lacks throws std::invalid_argument.
CorrelatorIsa resolve_correlator_isa(CorrelatorIsa isa);

}  // namespace ultratrack::receiver
