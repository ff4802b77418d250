// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/nav_bit_check.hpp"

#include <cmath>

namespace ultratrack::receiver {

NavBitCounts& NavBitCounts::operator+=(const NavBitCounts& o) {
  bits_wiped += o.bits_wiped;
  bits_unknown += o.bits_unknown;
  bits_checked += o.bits_checked;
  bits_contradicted += o.bits_contradicted;
  words_contradicted += o.words_contradicted;
  sources_stopped += o.sources_stopped;
  nav_words_agreed += o.nav_words_agreed;
  nav_words_disagreed += o.nav_words_disagreed;
  oracle = oracle || o.oracle;
  return *this;
}

double bit_error_probability(double cn0_dbhz, double bit_s) {
  const double snr = 2.0 * std::pow(10.0, cn0_dbhz / 10.0) * bit_s;
  return 0.5 * std::erfc(std::sqrt(snr) / std::sqrt(2.0));
}

int word_contradiction_threshold(int n, double p, double false_alarm) {
  // Tail sums from the top: each is a sum of small positive terms (no 1 - cdf cancellation).
  double tail = 0.0;
  int t = n + 1;
  for (int k = n; k >= 0; --k) {
    const double log_pmf = std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) +
                           (k > 0 ? k * std::log(p) : 0.0) + (n - k > 0 ? (n - k) * std::log1p(-p) : 0.0);
    tail += std::exp(log_pmf);
    if (tail > false_alarm) break;
    t = k;
  }
  return t;
}

bool NavBitCheck::close_word() {
  const bool contradicted = n_ > 0 && d_ >= word_contradiction_threshold(n_, worst_p_, opt_.word_false_alarm);
  n_ = d_ = 0;
  worst_p_ = 0.0;
  if (!contradicted) return false;
  ++counts_.words_contradicted;
  if (++since_arm_ < opt_.trip_words || tripped_) return false;
  tripped_ = true;
  return true;
}

bool NavBitCheck::add(std::int64_t word, bool agrees, double cn0_dbhz) {
  bool trip = false;
  if (word != word_) {
    trip = close_word();
    word_ = word;
  }
  if (!(cn0_dbhz >= opt_.min_cn0_dbhz)) return trip;
  ++counts_.bits_checked;
  ++n_;
  if (!agrees) {
    ++counts_.bits_contradicted;
    ++d_;
  }
  const double p = bit_error_probability(cn0_dbhz - opt_.cn0_margin_db);
  if (p > worst_p_) worst_p_ = p;
  return trip;
}

}  // namespace ultratrack::receiver
