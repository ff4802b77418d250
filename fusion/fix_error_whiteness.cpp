// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/fix_error_whiteness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
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
// value(fix, ref) and variance(fix): the quantity differenced (positions about a reference fix, or velocities) and
// its stated variance per axis.
template <class Value, class Variance>
std::array<std::vector<double>, 3> normalised_third_differences(const std::vector<GnssFix>& p,
                                                                const std::vector<int>& breaks_before, int lag,
                                                                double interval_s, Value value, Variance variance) {
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
      d += c * value(p[i + k * m], ref);
      var += c * c * variance(p[i + k * m]);
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

// The growth of the robust variance per fix of lag between lag 1 (x1) and a longer lag (x_long, lags_apart fixes
// more), and its 1-sigma from the scatter of kBlocks contiguous blocks.
struct Slope {
  double value = 0.0, sigma = 0.0;
  bool significant() const { return value > 2.0 * sigma; }
};

Slope slope_between(const std::vector<double>& x1, const std::vector<double>& x_long, int lags_apart) {
  Slope s;
  s.value = (robust_variance(x_long, 0, x_long.size()) - robust_variance(x1, 0, x1.size())) / lags_apart;
  const auto part = [](const std::vector<double>& x, int j) {
    return x.size() * static_cast<std::size_t>(j) / kBlocks;
  };
  std::array<double, kBlocks> b{};
  double mean = 0.0;
  for (int k = 0; k < kBlocks; ++k) {
    b[static_cast<std::size_t>(k)] = (robust_variance(x_long, part(x_long, k), part(x_long, k + 1)) -
                                      robust_variance(x1, part(x1, k), part(x1, k + 1))) /
                                     lags_apart;
    mean += b[static_cast<std::size_t>(k)] / kBlocks;
  }
  double ss = 0.0;
  for (const double v : b) ss += (v - mean) * (v - mean);
  s.sigma = std::sqrt(ss / (kBlocks - 1) / kBlocks);
  return s;
}

// The fixes of a span (those with the quantity), their median interval and the run breaks (an interval more than 50 %
// off the median). false when there is no rate to measure at.
struct Runs {
  std::vector<GnssFix> fixes;
  double interval_s = 0.0;
  std::vector<int> breaks_before;
};

template <class Keep>
std::optional<Runs> regular_runs(std::span<const GnssFix> fixes, Keep keep) {
  Runs r;
  for (const GnssFix& f : fixes)
    if (keep(f)) r.fixes.push_back(f);
  if (r.fixes.size() < 8) return std::nullopt;
  std::vector<double> intervals;
  for (std::size_t i = 1; i < r.fixes.size(); ++i) intervals.push_back(r.fixes[i].t_s - r.fixes[i - 1].t_s);
  r.interval_s = median(intervals);
  if (!(r.interval_s > 0.0) || !std::isfinite(r.interval_s)) return std::nullopt;
  r.breaks_before.assign(r.fixes.size(), 0);
  for (std::size_t i = 1; i < r.fixes.size(); ++i)
    r.breaks_before[i] =
        r.breaks_before[i - 1] + (std::abs(intervals[i - 1] - r.interval_s) > kRegularSpacing * r.interval_s ? 1 : 0);
  return r;
}

}  // namespace

FixErrorWhiteness measure_fix_error_whiteness(std::span<const GnssFix> fixes, const FixWhitenessOptions& o) {
  FixErrorWhiteness w;
  const auto runs =
      regular_runs(fixes, [](const GnssFix& f) { return f.has_position && (f.sigma_pos_ned_m.array() > 0.0).all(); });
  if (!runs) {
    w.note = "position fixes: too few, or without a rate, to measure their errors' correlation, taken as white";
    return w;
  }
  const std::vector<GnssFix>& p = runs->fixes;
  const double T = runs->interval_s;
  w.interval_s = T;
  const int M = std::clamp(static_cast<int>(std::lround(o.long_lag_s / T)), 2, 20);
  w.long_lag = M;
  const auto position = [](const GnssFix& f, const GnssFix& ref) { return ned_of(f, ref); };
  const auto position_variance = [](const GnssFix& f) { return Eigen::Vector3d(f.sigma_pos_ned_m.cwiseAbs2()); };
  const auto d1 = normalised_third_differences(p, runs->breaks_before, 1, T, position, position_variance);
  const auto d_long = normalised_third_differences(p, runs->breaks_before, M, T, position, position_variance);
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

  std::array<Slope, 3> slope;
  Eigen::Vector3d median_sigma;
  for (int a = 0; a < 3; ++a) {
    const auto& x1 = d1[static_cast<std::size_t>(a)];
    const auto& x_long = d_long[static_cast<std::size_t>(a)];
    const double v1 = robust_variance(x1, 0, x1.size());
    const Slope& sl = slope[static_cast<std::size_t>(a)] = slope_between(x1, x_long, M - 1);
    w.growth(a) = v1 > 0.0 ? robust_variance(x_long, 0, x_long.size()) / v1 : 1.0;
    // The intercept takes the slope off only when it is there: a slope within its noise would only add that noise.
    w.white_share(a) = std::max(0.0, (v1 - (sl.significant() ? sl.value : 0.0)) / 20.0);
    std::vector<double> sig;
    for (const GnssFix& f : p) sig.push_back(f.sigma_pos_ned_m(a));
    median_sigma(a) = median(sig);
  }

  const double white_horizontal = 0.5 * (w.white_share.x() + w.white_share.y());
  if (white_horizontal >= o.white_share_threshold) {
    for (int a = 0; a < 3; ++a)
      if (w.white_share(a) > o.understated_share) w.sigma_scale(a) = std::sqrt(w.white_share(a));
    w.note = fmt::format(
        "position fixes every {:.3g} s: errors white at that rate (white share of the stated variance {:.2f} / "
        "{:.2f} / {:.2f} N/E/D), used as white{}",
        T, w.white_share.x(), w.white_share.y(), w.white_share.z(),
        w.sigma_scale.maxCoeff() > 1.0
            ? fmt::format(", the stated sigmas widened {:.2f} / {:.2f} / {:.2f} times to the noise measured",
                          w.sigma_scale.x(), w.sigma_scale.y(), w.sigma_scale.z())
            : std::string());
    return w;
  }
  w.correlated = true;
  double tau_sum = 0.0;
  bool bound = false;
  for (int a = 0; a < 2; ++a) {
    const double correlated_share = std::clamp(1.0 - w.white_share(a), 0.0, 1.0);
    const Slope& sl = slope[static_cast<std::size_t>(a)];
    bound = bound || !sl.significant();
    const double s = sl.significant() ? sl.value : 2.0 * sl.sigma;
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

VelocityWhiteness measure_velocity_whiteness(std::span<const GnssFix> fixes, double sigma_mps,
                                             const FixWhitenessOptions& o) {
  VelocityWhiteness w;
  const auto runs = regular_runs(fixes, [](const GnssFix& f) { return f.has_velocity; });
  if (!runs || !(sigma_mps > 0.0)) {
    w.note = "velocity fixes: too few or without a rate to measure their errors' correlation, taken as white";
    return w;
  }
  const std::vector<GnssFix>& p = runs->fixes;
  const double T = runs->interval_s;
  w.interval_s = T;
  const auto velocity = [](const GnssFix& f, const GnssFix&) { return f.v_n_mps; };
  const auto variance = [&](const GnssFix&) { return Eigen::Vector3d::Constant(sigma_mps * sigma_mps).eval(); };
  const auto d1 = normalised_third_differences(p, runs->breaks_before, 1, T, velocity, variance);
  const auto d2 = normalised_third_differences(p, runs->breaks_before, 2, T, velocity, variance);
  w.differences = static_cast<long long>(d1[0].size());
  if (d2[0].size() < static_cast<std::size_t>(o.min_differences)) {
    w.note = fmt::format(
        "{} regularly spaced runs of velocity fixes: too few to measure their errors' correlation "
        "(at least {}), taken as white",
        d2[0].size(), o.min_differences);
    return w;
  }
  w.measured = true;
  double tau_sum = 0.0;
  int correlated_axes = 0;
  for (int a = 0; a < 2; ++a) {  // horizontal: the vertical velocity of a land vehicle is small either way
    const auto& x1 = d1[static_cast<std::size_t>(a)];
    const Slope sl = slope_between(x1, d2[static_cast<std::size_t>(a)], 1);
    w.white_share(a) = std::max(0.0, (robust_variance(x1, 0, x1.size()) - (sl.significant() ? sl.value : 0.0)) / 20.0);
    if (sl.significant() && w.white_share(a) < o.white_share_threshold) {
      tau_sum += 12.0 * (1.0 - w.white_share(a)) * T / sl.value;
      ++correlated_axes;
    }
  }
  if (correlated_axes < 2) {
    const double share = 0.5 * (w.white_share.x() + w.white_share.y());
    if (share > o.understated_share) w.variance_factor = share;  // noisier than told: widened to the noise
    w.note = fmt::format(
        "velocity fixes every {:.3g} s: errors white at that rate for the told {} m/s (white share "
        "{:.2f} / {:.2f} N/E), {}",
        T, sigma_mps, w.white_share.x(), w.white_share.y(),
        w.variance_factor > 1.0 ? fmt::format("noisier than told: sigma widened {:.2f} times", std::sqrt(share))
                                : std::string("used as told"));
    return w;
  }
  w.correlated = true;
  w.correlation_time_s = std::min(0.5 * tau_sum, o.max_correlation_time_s);
  w.variance_factor = 1.0 + 2.0 * w.correlation_time_s / T;
  w.note = fmt::format(
      "velocity fixes every {:.3g} s: errors correlated in time (white share of the told {} m/s {:.2f} / {:.2f} N/E), "
      "tau {:.2f} s: each velocity's sigma widened {:.1f} times ([gnss] error_correlation_time_s overrides)",
      T, sigma_mps, w.white_share.x(), w.white_share.y(), w.correlation_time_s, std::sqrt(w.variance_factor));
  return w;
}

}  // namespace ultratrack::fusion
