// SPDX-License-Identifier: GPL-3.0-or-later
// The windowed NIS test of the filters: the sum of the normalised innovation squares (NIS) of the last `window`
// updates against the upper quantile, at false-alarm probability `probability`, of the chi-square distribution whose
// degrees of freedom are the updates' summed measurement sizes. For a consistent filter the innovations of
// successive (and of sequentially processed) updates are independent and each NIS is chi-square(dof), so the sum
// over a full window is chi-square(sum of dof): a full window passes its limit with probability `probability`.
// Each NIS enters capped at cap_per_dof x dof (a non-finite one at the cap), so that one huge outlier (a rejected
// update's NIS can reach 10^4) counts as a bounded share of the budget. Used by the loose/tight filters' lock-out
// recovery (fusion/lockout_recovery.hpp) and the vector and ultra-tight loops' channel releases
// (fusion/nis_release.hpp). Allocates only at construction.
#pragma once

#include <string>
#include <vector>

namespace ultratrack::fusion {

struct WindowedNisOptions {
  int window = 20;             // updates summed, >= 1
  double probability = 1e-6;   // false-alarm probability of one full window, in (0, 1)
  double cap_per_dof = 100.0;  // an update's NIS counts at most this x its dof, > 0
  bool IsValid(std::string* why = nullptr) const;
};

class WindowedNis final {
 public:
  // Throws std::invalid_argument for invalid options.
  explicit WindowedNis(const WindowedNisOptions& options);

  // One update's NIS and measurement size (dof >= 1). Returns true when the window is full and its sum is above
  // limit(); the window is kept (reset() restarts it).
  bool add(double nis, int dof);
  void reset();

  bool full() const { return count_ == opt_.window; }
  int updates() const { return count_; }
  double sum() const { return sum_; }
  int dof() const { return dof_; }
  // The chi-square upper quantile at `probability` for the window's summed dof (0 while empty).
  double limit() const;
  const WindowedNisOptions& options() const { return opt_; }

 private:
  WindowedNisOptions opt_;
  std::vector<double> nis_;  // ring buffer of the capped NIS, window entries
  std::vector<int> dofs_;
  int head_ = 0;   // oldest entry
  int count_ = 0;  // entries held
  double sum_ = 0.0;
  int dof_ = 0;
  mutable int cached_dof_ = -1;  // the quantile is costly (an incomplete gamma inversion): one per dof sum
  mutable double cached_limit_ = 0.0;
};

}  // namespace ultratrack::fusion
