// SPDX-License-Identifier: GPL-3.0-or-later
// Phase-accurate numerically controlled oscillator: a phase (carrier cycles or code chips) accumulated per
// sample in 128-bit fixed point, so that minutes of accumulation add no drift beyond the quantisation of the
// per-sample step (2^-kFracBits units): < 1e-6 cycles after hours. Used by the tracking channel for its replica.
#pragma once

#include <cmath>
#include <cstdint>

namespace ultratrack::receiver {

__extension__ typedef __int128 Int128;  // GCC/Clang extension; -Wpedantic accepts it through __extension__

// kFracBits fractional bits: the step per sample must satisfy |step| < 2^(63 - kFracBits) units.
template <int kFracBits>
class FixedPointPhase {
 public:
  static constexpr double kScale = static_cast<double>(std::uint64_t{1} << (kFracBits - 32)) * 4294967296.0;

  // Phase increment per sample, in units (cycles or chips) per sample.
  void set_step(double units_per_sample) { step_ = static_cast<std::int64_t>(std::llround(units_per_sample * kScale)); }
  double step() const { return static_cast<double>(step_) / kScale; }
  std::int64_t raw_step() const { return step_; }

  void advance(std::int64_t samples) { phase_ += static_cast<Int128>(step_) * samples; }
  void add(double units) { phase_ += static_cast<Int128>(std::llround(units * kScale)); }
  void set(double units) { phase_ = static_cast<Int128>(std::llround(units * kScale)); }

  Int128 raw() const { return phase_; }
  void set_raw(Int128 r) { phase_ = r; }
  // Whole units (floor) and the fraction in [0, 1).
  std::int64_t whole() const { return static_cast<std::int64_t>(phase_ >> kFracBits); }
  double fraction() const {
    const Int128 mask = (static_cast<Int128>(1) << kFracBits) - 1;
    return static_cast<double>(static_cast<std::uint64_t>((phase_ & mask) >> (kFracBits - 52))) * 0x1p-52;
  }
  double value() const { return static_cast<double>(whole()) + fraction(); }
  // Fraction of a unit as 32-bit fixed point (2^-32 units), rounded: the form the correlator's carrier uses.
  std::uint32_t fraction_q32() const {
    return static_cast<std::uint32_t>(
        static_cast<std::uint64_t>((phase_ + (static_cast<Int128>(1) << (kFracBits - 33))) >> (kFracBits - 32)));
  }
  std::uint32_t step_q32() const {
    return static_cast<std::uint32_t>((step_ + (std::int64_t{1} << (kFracBits - 33))) >> (kFracBits - 32));
  }

 private:
  Int128 phase_ = 0;
  std::int64_t step_ = 0;
};

// Carrier: cycles with 2^-62 resolution (|f/fs| < 2). Code: chips with 2^-52 resolution (< 2048 chips/sample).
using CarrierPhase = FixedPointPhase<62>;
using CodePhase = FixedPointPhase<52>;

}  // namespace ultratrack::receiver
