// SPDX-License-Identifier: GPL-3.0-or-later
#include "brute_force_fine_search.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::test {

namespace {

using signals::kCaChipRate_hz;
using signals::kCaCodeLength_chips;
using signals::kL1Frequency_hz;

constexpr double kCodeLength = kCaCodeLength_chips;

struct Searcher {
  std::span<const std::complex<float>> samples;
  double fs_hz;
  const signals::CaCodeChips& chips;
  std::vector<std::complex<double>> wiped;  // samples times exp(-j 2 pi f0 t)
  double doppler_hz = 0.0;

  void wipe(double f0_hz) {
    doppler_hz = f0_hz;
    wiped.resize(samples.size());
    const double w = -2.0 * std::numbers::pi * f0_hz / fs_hz;
    for (std::size_t n = 0; n < samples.size(); ++n)
      wiped[n] = std::complex<double>(samples[n]) * std::polar(1.0, w * static_cast<double>(n));
  }

  // Code chips advanced per sample, with the code Doppler of the current carrier Doppler.
  double chips_per_sample() const { return kCaChipRate_hz * (1.0 + doppler_hz / kL1Frequency_hz) / fs_hz; }

  // Correlations over whole code periods of the replica whose chip at sample 0 is tau0.
  std::vector<std::complex<double>> correlations(double tau0) const {
    const double r = chips_per_sample();
    std::vector<std::complex<double>> out;
    std::complex<double> acc = 0.0;
    long current = -1;
    for (std::size_t n = 0; n < wiped.size(); ++n) {
      const double p = tau0 + r * static_cast<double>(n);
      const long period = static_cast<long>(std::floor(p / kCodeLength));
      if (period != current) {
        if (current >= 0) out.push_back(acc);
        acc = 0.0;
        current = period;
      }
      const long chip = static_cast<long>(std::floor(p - static_cast<double>(period) * kCodeLength));
      acc += wiped[n] * static_cast<double>(chips[static_cast<std::size_t>(chip)]);
    }
    // The first (partial, started at sample 0 mid-period when tau0 > 0) and last (partial) periods are dropped.
    if (!out.empty() && tau0 - std::floor(tau0 / kCodeLength) * kCodeLength > 1e-9) out.erase(out.begin());
    return out;
  }

  double amplitude(double tau0) const {
    const auto c = correlations(tau0);
    double power = 0.0;
    for (const auto& v : c) power += std::norm(v);
    return c.empty() ? 0.0 : std::sqrt(power / static_cast<double>(c.size()));
  }

  // Early-late balance A(tau - d) = A(tau + d) on the triangle's linear flanks, by bisection around tau_max.
  double balance(double tau_max, double d) const {
    auto g = [&](double tau) { return amplitude(tau - d) - amplitude(tau + d); };
    double lo = tau_max - 0.15, hi = tau_max + 0.15;
    double g_lo = g(lo);
    if (g_lo > 0.0 || g(hi) < 0.0) return tau_max;  // no bracket: keep the grid maximum
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      const double g_mid = g(mid);
      if ((g_mid < 0.0) == (g_lo < 0.0)) {
        lo = mid;
        g_lo = g_mid;
      } else {
        hi = mid;
      }
    }
    return 0.5 * (lo + hi);
  }

  // Residual frequency from the phase progression over `lag` code periods; squaring removes data bits.
  double residual_hz(double tau0, int lag) const {
    const auto c = correlations(tau0);
    std::complex<double> sum = 0.0;
    for (std::size_t k = 0; k + static_cast<std::size_t>(lag) < c.size(); ++k) {
      const auto z = c[k + static_cast<std::size_t>(lag)] * std::conj(c[k]);
      sum += z * z;
    }
    const double period_s = kCodeLength / (kCaChipRate_hz * (1.0 + doppler_hz / kL1Frequency_hz));
    return std::arg(sum) / (2.0 * 2.0 * std::numbers::pi * lag * period_s);
  }

  double code_search(double hint, double half_width_chips) const {
    double best = hint, best_a = -1.0;
    for (double tau = hint - half_width_chips; tau <= hint + half_width_chips + 1e-9; tau += 0.05) {
      const double a = amplitude(tau);
      if (a > best_a) best_a = a, best = tau;
    }
    return balance(best, 0.25);
  }
};

double wrap_chips(double tau) { return tau - std::floor(tau / kCodeLength) * kCodeLength; }

}  // namespace

FineSearchResult brute_force_fine_search(std::span<const std::complex<float>> samples, double fs_hz, int prn,
                                         double doppler_hint_hz, double code_hint_chips) {
  Searcher s{samples, fs_hz, signals::ca_code(prn), {}, 0.0};
  // Code and Doppler are refined in turn; two rounds converge (the code rate depends on the Doppler).
  s.wipe(doppler_hint_hz);
  double tau = s.code_search(wrap_chips(code_hint_chips) + kCodeLength, 1.5);  // + one period keeps tau0 > 0
  for (int round = 0; round < 2; ++round) {
    s.wipe(s.doppler_hz + s.residual_hz(tau, 1));   // +-250 Hz unambiguous
    s.wipe(s.doppler_hz + s.residual_hz(tau, 10));  // +-25 Hz unambiguous, ten times finer
    tau = s.code_search(tau, 0.3);
  }
  FineSearchResult result;
  result.doppler_hz = s.doppler_hz;
  result.code_phase_chips = wrap_chips(tau);
  result.peak_amplitude = s.amplitude(tau);
  result.off_peak_amplitude = s.amplitude(tau + 511.5);
  return result;
}

}  // namespace ultratrack::test
