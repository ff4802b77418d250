// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/fix_error_whiteness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "ins/earth_model.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kChiSquare1Median = 0.4549364231;  // median of chi-square with one degree of freedom
constexpr int kBlocks = 8;                          // contiguous blocks for the slope's sigma
constexpr double kRegularSpacing = 0.5;             // an interval within 50 % of T keeps a run going

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Position of a fix in metres north, east, down of a reference fix (local radii: the spans are metres).
Eigen::Vector3d ned_of(const GnssFix& f, const GnssFix& ref) {
  const ins::Radii r = ins::radii_of_curvature(ref.lat_rad);
  return {(f.lat_rad - ref.lat_rad) * (r.meridian_m + ref.height_m),
          (f.lon_rad - ref.lon_rad) * (r.transverse_m + ref.height_m) * std::cos(ref.lat_rad),
          -(f.height_m - ref.height_m)};
}

// Squared third differences at lag m over their variance for the stated sigmas (scaled so that white errors give
// 20 sigma^2, as evenly spaced fixes do), per axis, for every run of 3m + 1 regularly spaced fixes. Uneven times (a
// receiver's or a logger's time-stamp jitter) take the divided difference's weights, which cancel a constant
// acceleration at any spacing: c_k = 6 (mT)^3 / prod_{j != k} (t_k - t_j), (-1, 3, -3, 1) when even.
// breaks_before[i]: irregular intervals among the first i.
std::array<std::vector<double>, 3> normalised_third_differences(const std::vector<GnssFix>& p,
                                                                const std::vector<int>& breaks_before, int lag,
                                                                double interval_s) {
  std::array<std::vector<double>, 3> out;
  const auto m = static_cast<std::size_t>(lag);
  const std::size_t span = 3 * m;
  const double h3 = std::pow(static_cast<double>(lag) * interval_s, 3);
  for (std::size_t i = 0; i + span < p.size(); ++i) {
    if (breaks_before[i + span] != breaks_before[i]) continue;
    const GnssFix& ref = p[i + m];
    Eigen::Vector3d d = Eigen::Vector3d::Zero(), var = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      double prod = 1.0;
      for (std::size_t j = 0; j < 4; ++j)
        if (j != k) prod *= p[i + k * m].t_s - p[i + j * m].t_s;
      const double c = 6.0 * h3 / prod;
      d += c * ned_of(p[i + k * m], ref);
      var += c * c * p[i + k * m].sigma_pos_ned_m.cwiseAbs2();
    }
    var /= 20.0;
    for (int a = 0; a < 3; ++a) out[static_cast<std::size_t>(a)].push_back(d(a) * d(a) / var(a));
  }
  return out;
}

double robust_variance(const std::vector<double>& x, std::size_t from, std::size_t to) {
  return median(std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(from),
                                    x.begin() + static_cast<std::ptrdiff_t>(to))) /
         kChiSquare1Median;
}

}  // namespace

FixErrorWhiteness measure_fix_error_whiteness(std::span<const GnssFix> fixes, const FixWhitenessOptions& o) {
  FixErrorWhiteness w;
  std::vector<GnssFix> p;
  for (const GnssFix& f : fixes)
    if (f.has_position && (f.sigma_pos_ned_m.array() > 0.0).all()) p.push_back(f);
  if (p.size() < 8) {
    w.note = fmt::format("{} position fixes: too few to measure their errors' correlation, taken as white", p.size());
    return w;
  }
  std::vector<double> intervals;
  for (std::size_t i = 1; i < p.size(); ++i) intervals.push_back(p[i].t_s - p[i - 1].t_s);
  const double T = median(intervals);
  w.interval_s = T;
  if (!(T > 0.0) || !std::isfinite(T)) {  // most fixes share a time stamp
    w.note = fmt::format("position fixes with a median interval of {} s: no rate to measure at, taken as white", T);
    return w;
  }
  std::vector<int> breaks_before(p.size(), 0);
  for (std::size_t i = 1; i < p.size(); ++i)
    breaks_before[i] = breaks_before[i - 1] + (std::abs(intervals[i - 1] - T) > kRegularSpacing * T ? 1 : 0);
  const int M = std::clamp(static_cast<int>(std::lround(o.long_lag_s / T)), 2, 20);
  w.long_lag = M;
  const auto d1 = normalised_third_differences(p, breaks_before, 1, T);
  const auto d_long = normalised_third_differences(p, breaks_before, M, T);
  w.differences = static_cast<long long>(d1[0].size());
  if (d1[0].size() < static_cast<std::size_t>(o.min_differences) ||
      d_long[0].size() < static_cast<std::size_t>(o.min_differences)) {
    w.note = fmt::format(
        "{} regularly spaced runs of position fixes ({:.3g} s apart): too few to measure their errors' correlation "
        "(at least {}), taken as white",
        std::min(d1[0].size(), d_long[0].size()), T, o.min_differences);
    return w;
  }
  w.measured = true;

  Eigen::Vector3d slope, slope_sigma, median_sigma;
  for (int a = 0; a < 3; ++a) {
    const auto& x1 = d1[static_cast<std::size_t>(a)];
    const auto& x_long = d_long[static_cast<std::size_t>(a)];
    const double v1 = robust_variance(x1, 0, x1.size()), v_long = robust_variance(x_long, 0, x_long.size());
    slope(a) = (v_long - v1) / (M - 1);
    w.growth(a) = v1 > 0.0 ? v_long / v1 : 1.0;
    std::array<double, kBlocks> b{};
    double mean = 0.0;
    for (int k = 0; k < kBlocks; ++k) {
      const auto part = [&](const std::vector<double>& x, int j) {
        return x.size() * static_cast<std::size_t>(j) / kBlocks;
      };
      b[static_cast<std::size_t>(k)] = (robust_variance(x_long, part(x_long, k), part(x_long, k + 1)) -
                                        robust_variance(x1, part(x1, k), part(x1, k + 1))) /
                                       (M - 1);
      mean += b[static_cast<std::size_t>(k)] / kBlocks;
    }
    double ss = 0.0;
    for (const double v : b) ss += (v - mean) * (v - mean);
    slope_sigma(a) = std::sqrt(ss / (kBlocks - 1) / kBlocks);
    // The intercept takes the slope off only when it is there: a slope within its noise would only add that noise.
    w.white_share(a) = std::max(0.0, (v1 - (slope(a) > 2.0 * slope_sigma(a) ? slope(a) : 0.0)) / 20.0);
    std::vector<double> sig;
    for (const GnssFix& f : p) sig.push_back(f.sigma_pos_ned_m(a));
    median_sigma(a) = median(sig);
  }

  const double white_horizontal = 0.5 * (w.white_share.x() + w.white_share.y());
  if (white_horizontal >= o.white_share_threshold) {
    w.note = fmt::format(
        "position fixes every {:.3g} s: errors white at that rate (white share of the stated variance {:.2f} / "
        "{:.2f} / {:.2f} N/E/D), used as white",
        T, w.white_share.x(), w.white_share.y(), w.white_share.z());
    return w;
  }
  w.correlated = true;
  double tau_sum = 0.0;
  bool bound = false;
  for (int a = 0; a < 2; ++a) {
    const double correlated_share = std::clamp(1.0 - w.white_share(a), 0.0, 1.0);
    const bool significant = slope(a) > 2.0 * slope_sigma(a);
    bound = bound || !significant;
    const double s = significant ? slope(a) : 2.0 * slope_sigma(a);
    tau_sum += s > 0.0 ? 12.0 * correlated_share * T / s : o.max_correlation_time_s;
  }
  w.correlation_time_is_bound = bound;
  w.correlation_time_s = std::clamp(0.5 * tau_sum, M * T, o.max_correlation_time_s);
  for (int a = 0; a < 3; ++a)
    w.sigma_ned_m(a) = median_sigma(a) * std::sqrt(std::clamp(1.0 - w.white_share(a), 0.01, 1.0));
  w.note = fmt::format(
      "position fixes every {:.3g} s: errors correlated in time (white share of the stated variance {:.2f} / {:.2f} / "
      "{:.2f} N/E/D, growth over {} fixes {:.1f} / {:.1f}): carried as Gauss-Markov states, tau {}{:.1f} s, "
      "1-sigma {:.2f} / {:.2f} / {:.2f} m ([gnss] error_correlation_time_s overrides)",
      T, w.white_share.x(), w.white_share.y(), w.white_share.z(), M, w.growth.x(), w.growth.y(), bound ? ">= " : "",
      w.correlation_time_s, w.sigma_ned_m.x(), w.sigma_ned_m.y(), w.sigma_ned_m.z());
  return w;
}

}  // namespace ultratrack::fusion
