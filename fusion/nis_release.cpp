// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/nis_release.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {
namespace {

WindowedNisOptions window_options(const NisReleaseOptions& o) {
  WindowedNisOptions w;
  w.window = o.window;
  w.probability = o.probability;
  return w;  // the cap per dof stays inert: add() caps at the gate threshold first
}

bool valid_prn(int prn) { return prn >= 1 && prn <= 32; }

}  // namespace

bool NisReleaseOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (window < 1) return fail("NIS release: the window must hold at least 1 update");
  if (!(probability > 0.0 && probability < 1.0)) return fail("NIS release: the probability must lie in (0, 1)");
  if (!(margin >= 1.0) || !std::isfinite(margin)) return fail("NIS release: the margin must be >= 1");
  if (!(gate_probability > 0.0 && gate_probability < 1.0))
    return fail("NIS release: the gate probability must lie in (0, 1)");
  if (min_filter_channels < 1) return fail("NIS release: min_filter_channels must be >= 1");
  if (filter_persistence < 1) return fail("NIS release: filter_persistence must be >= 1");
  return true;
}

NisReleaseMonitor::NisReleaseMonitor(const NisReleaseOptions& options) : opt_(options) {
  if (std::string why; !opt_.IsValid(&why)) throw std::invalid_argument(why);
  windows_.assign(33, WindowedNis(window_options(opt_)));
}

double NisReleaseMonitor::gate_cap(int dof) const {
  if (dof >= static_cast<int>(gate_caps_.size()))
    return receiver::chi_square_upper_quantile(dof, 1.0 - opt_.gate_probability);
  double& c = gate_caps_[static_cast<std::size_t>(dof)];
  if (c == 0.0) c = receiver::chi_square_upper_quantile(dof, 1.0 - opt_.gate_probability);
  return c;
}

double NisReleaseMonitor::limit(int dof) const {
  return opt_.margin * receiver::chi_square_upper_quantile(dof, opt_.probability);
}

void NisReleaseMonitor::add(int prn, double nis, int dof) {
  if (!opt_.enabled || !valid_prn(prn) || dof < 1) return;
  const double cap = gate_cap(dof);
  windows_[static_cast<std::size_t>(prn)].add(std::isfinite(nis) ? std::min(nis, cap) : cap, dof);
  touched_[static_cast<std::size_t>(prn)] = true;
}

NisVerdict NisReleaseMonitor::evaluate() {
  NisVerdict v;
  if (!opt_.enabled) return v;
  int tested = 0, pool_dof = 0;
  double pool = 0.0;
  std::vector<int> out;
  for (int prn = 1; prn <= 32; ++prn) {
    const auto i = static_cast<std::size_t>(prn);
    if (!touched_[i]) continue;
    touched_[i] = false;
    const WindowedNis& w = windows_[i];
    if (!w.full()) continue;
    ++tested;
    pool += w.sum();
    pool_dof += w.dof();
    if (w.sum() > limit(w.dof())) out.push_back(prn);
  }
  if (tested >= opt_.min_filter_channels) {
    if (pool_dof != pool_dof_) {
      pool_limit_ = limit(pool_dof);
      pool_dof_ = pool_dof;
    }
    if (pool > pool_limit_) {
      if (filter_out_) return v;  // logged already: no channel is blamed while the pool stays out
      if (++pool_out_evaluations_ < opt_.filter_persistence) return v;  // not yet persistent: nobody blamed
      pool_out_evaluations_ = 0;
      filter_out_ = true;
      v.filter = true;
      v.reasons.push_back(fmt::format("pooled NIS {:.0f} of {} channels over {} updates each (limit {:.0f})", pool,
                                      tested, opt_.window, pool_limit_));
      reset();
      return v;
    }
    filter_out_ = false;
    pool_out_evaluations_ = 0;
  }
  for (int prn : out) {
    const WindowedNis& w = windows_[static_cast<std::size_t>(prn)];
    v.released.push_back(prn);
    v.reasons.push_back(
        fmt::format("windowed NIS {:.0f} over {} updates (limit {:.0f})", w.sum(), w.updates(), limit(w.dof())));
    forget(prn);
  }
  return v;
}

void NisReleaseMonitor::forget(int prn) {
  if (!valid_prn(prn)) return;
  windows_[static_cast<std::size_t>(prn)].reset();
  touched_[static_cast<std::size_t>(prn)] = false;
}

void NisReleaseMonitor::reset() {
  for (auto& w : windows_) w.reset();
  touched_.fill(false);
  pool_out_evaluations_ = 0;
}

void ReleaseLog::add(double t_s, int prn, const std::string& reason, const std::string& detail) {
  events_.push_back({t_s, prn, reason, detail});
  auto it = std::find_if(counts_.begin(), counts_.end(), [&](const auto& c) { return c.first == reason; });
  if (it == counts_.end())
    counts_.emplace_back(reason, 1);
  else
    ++it->second;
}

long long ReleaseLog::count(const std::string& reason) const {
  auto it = std::find_if(counts_.begin(), counts_.end(), [&](const auto& c) { return c.first == reason; });
  return it == counts_.end() ? 0 : it->second;
}

std::string ReleaseLog::json_members() const {
  std::string j = "\"releases_by_reason\": {";
  for (std::size_t i = 0; i < counts_.size(); ++i)
    j += fmt::format("{}\"{}\": {}", i ? ", " : "", counts_[i].first, counts_[i].second);
  j += "}, \"release_log\": [";
  for (std::size_t i = 0; i < events_.size(); ++i) {
    const Event& e = events_[i];
    j += fmt::format("{}{{\"t_s\": {:.3f}, \"prn\": {}, \"reason\": \"{}\", \"detail\": \"{}\"}}", i ? ", " : "", e.t_s,
                     e.prn, e.reason, e.detail);
  }
  return j + "]";
}

}  // namespace ultratrack::fusion
