// SPDX-License-Identifier: GPL-3.0-or-later
// Tracking-loop discriminators on complex correlator sums (I + jQ). Each returns the error in the loop's own
// unit with unit gain near lock (the closed-form gain is applied here), so loop filters need no extra scaling:
// carrier phase in cycles, frequency in Hz, code in chips. Sign: positive = the signal leads the replica.
#pragma once

#include <cmath>
#include <complex>

namespace ultratrack::receiver {

inline constexpr double kTwoPi = 6.283185307179586;

// Costas (data-insensitive) arctangent: atan(Q/I) / 2pi, cycles in (-1/4, 1/4). Gain 1 for |error| < 1/4.
inline double costas_atan_cycles(std::complex<float> p) {
  if (p.real() == 0.0f) return p.imag() == 0.0f ? 0.0 : (p.imag() > 0 ? 0.25 : -0.25);
  return std::atan(static_cast<double>(p.imag()) / p.real()) / kTwoPi;
}

// Pure PLL four-quadrant arctangent (data wiped off or pilot): atan2(Q, I) / 2pi, cycles in (-1/2, 1/2].
inline double pll_atan2_cycles(std::complex<float> p) { return std::atan2(p.imag(), p.real()) / kTwoPi; }

// FLL cross-dot on two successive sums whose centres are dt_s apart:
// atan2(cross, dot) / (2 pi dt) Hz, cross = I1 Q2 - I2 Q1, dot = I1 I2 + Q1 Q2. Range +-1/(2 dt). Gain 1.
// No data bit may change between the two (use the halves of one code period before bit sync).
inline double fll_atan2_hz(std::complex<float> first, std::complex<float> second, double dt_s) {
  const double cross =
      static_cast<double>(first.real()) * second.imag() - static_cast<double>(second.real()) * first.imag();
  const double dot =
      static_cast<double>(first.real()) * second.real() + static_cast<double>(first.imag()) * second.imag();
  return std::atan2(cross, dot) / (kTwoPi * dt_s);
}

// Bit-tolerant variant: atan(cross / dot) / (2 pi dt), Hz in +-1/(4 dt); a sign flip between the sums is harmless.
inline double fll_atan_hz(std::complex<float> first, std::complex<float> second, double dt_s) {
  const double cross =
      static_cast<double>(first.real()) * second.imag() - static_cast<double>(second.real()) * first.imag();
  const double dot =
      static_cast<double>(first.real()) * second.real() + static_cast<double>(first.imag()) * second.imag();
  if (dot == 0.0) return 0.0;
  return std::atan(cross / dot) / (kTwoPi * dt_s);
}

// Cross and dot products of two successive sums (for FLLs that average them before the arctangent, which keeps
// the discriminator's gain at low SNR): frequency = atan2(cross, dot) / (2 pi dt).
struct CrossDot {
  double cross = 0.0, dot = 0.0;
};
inline CrossDot cross_dot(std::complex<float> first, std::complex<float> second) {
  return {static_cast<double>(first.real()) * second.imag() - static_cast<double>(second.real()) * first.imag(),
          static_cast<double>(first.real()) * second.real() + static_cast<double>(first.imag()) * second.imag()};
}

// DLL normalised early-minus-late envelope for taps at +-offset chips (offset = half the E-L spacing):
// (|E| - |L|) / (|E| + |L|) is tau / (1 - offset) for a triangle correlation with |tau| <= offset <= 0.5,
// so it is multiplied by (1 - offset) to give tau in chips (tau = signal code phase - replica code phase).
inline double dll_nelp_chips(std::complex<float> early, std::complex<float> late, double offset_chips) {
  const double e = std::abs(early), l = std::abs(late);
  if (e + l == 0.0) return 0.0;
  return (1.0 - offset_chips) * (e - l) / (e + l);
}

}  // namespace ultratrack::receiver
