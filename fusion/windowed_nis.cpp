// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/windowed_nis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {

bool WindowedNisOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (window < 1) return fail("windowed NIS: the window must hold at least 1 update");
  if (!(probability > 0.0 && probability < 1.0)) return fail("windowed NIS: the probability must lie in (0, 1)");
  if (!(cap_per_dof > 0.0) || !std::isfinite(cap_per_dof)) return fail("windowed NIS: the cap per dof must be > 0");
  return true;
}

WindowedNis::WindowedNis(const WindowedNisOptions& options) : opt_(options) {
  if (std::string why; !opt_.IsValid(&why)) throw std::invalid_argument(why);
  nis_.assign(static_cast<std::size_t>(opt_.window), 0.0);
  dofs_.assign(static_cast<std::size_t>(opt_.window), 0);
}

void WindowedNis::reset() {
  head_ = count_ = 0;
  sum_ = 0.0;
  dof_ = 0;
}

bool WindowedNis::add(double nis, int dof) {
  const double cap = opt_.cap_per_dof * dof;
  const double capped = std::isfinite(nis) ? std::min(nis, cap) : cap;
  // Added before the oldest is taken out (the order of the floating-point sum is part of the outputs).
  sum_ += capped;
  dof_ += dof;
  const int tail = (head_ + count_) % opt_.window;
  if (count_ == opt_.window) {
    sum_ -= nis_[static_cast<std::size_t>(head_)];
    dof_ -= dofs_[static_cast<std::size_t>(head_)];
    head_ = (head_ + 1) % opt_.window;
  } else {
    ++count_;
  }
  nis_[static_cast<std::size_t>(tail)] = capped;
  dofs_[static_cast<std::size_t>(tail)] = dof;
  return full() && sum_ > limit();
}

double WindowedNis::limit() const {
  if (dof_ <= 0) return 0.0;
  if (dof_ != cached_dof_) {
    cached_limit_ = receiver::chi_square_upper_quantile(dof_, opt_.probability);
    cached_dof_ = dof_;
  }
  return cached_limit_;
}

}  // namespace ultratrack::fusion
