// SPDX-License-Identifier: GPL-3.0-or-later
// The running check of predicted navigation bits against the signal, and the counts summary.json reports per
// satellite. Each 20 ms epoch wiped by a predicted bit is compared with the prompt's sign (the bit as received,
// the Costas half cycle resolved by the frame polarity); over each 30-bit LNAV word the disagreements d among the
// n bits checked are set against the bit error probability at the measured C/N0,
//   p = Q(sqrt(2 C/N0 T)),  T = 20 ms,  C/N0 taken cn0_margin_db below the estimate (estimate error, PLL jitter),
// and the word is contradicted when d >= t, the smallest t with P(Binomial(n, p) >= t) <= word_false_alarm.
// trip_words contradicted words stop the source. A clean source at any C/N0 makes a word contradicted with
// probability <= word_false_alarm, so it trips within W words with probability <= C(W, 2) alpha^2: 1.8e-5 for an
// hour (6000 words) at the defaults (alpha = 1e-6, two words). t at n = 30 with the 3 dB margin, by the measured
// C/N0: 1 at 35 dB-Hz, 2 at 30 (p = 3.8e-6), 3 at 28, 5 at 25 (p = 5.9e-3): a word the source inverts (30 wrong
// bits) is caught at any checked C/N0, one with a single wrong field from ~28 dB-Hz up (a field off by one unit in
// the last place changes ~4 bits with the parity). Bits below min_cn0_dbhz (25 dB-Hz) are not checked: on our own
// clean signal at a true 20 dB-Hz (ultra-tight, 0.2 s C/N0 estimates) a 20 dB-Hz floor contradicted ~1 % of words
// (estimates several dB high, bit errors in bursts while the PLL's phase wanders), where the binomial model says
// 1e-6. Units: dB-Hz, seconds.
#pragma once

#include <cstdint>

namespace ultratrack::receiver {

// Per satellite (channels on the same PRN add up): epochs are 20 ms bits.
struct NavBitCounts {
  long long bits_wiped = 0;          // epochs that asked for their bit and were wiped by a predicted one
  long long bits_unknown = 0;        // epochs that asked and got none (integrated in the Costas form)
  long long bits_checked = 0;        // predicted bits compared with the prompt's sign
  long long bits_contradicted = 0;   // of those, where the prompt's sign disagreed
  long long words_contradicted = 0;  // words over their C/N0's threshold (see above)
  int sources_stopped = 0;           // times the check stopped the source (decoded mode only)
  // A nav file's subframe 1-3 words compared with the channel's decoded copy (same subframe, same issue of data):
  // agreed words may be used, disagreeing ones never.
  int nav_words_agreed = 0, nav_words_disagreed = 0;
  bool oracle = false;  // the bits came from the oracle source (a nav file re-encoded)

  NavBitCounts& operator+=(const NavBitCounts& o);
};

// Q(sqrt(2 c T)) with c = 10^(cn0_dbhz / 10): a coherent BPSK bit's error probability over T seconds.
double bit_error_probability(double cn0_dbhz, double bit_s = 0.02);
// Smallest t with P(Binomial(n, p) >= t) <= false_alarm; n + 1 when none (the word can never be contradicted).
int word_contradiction_threshold(int n, double p, double false_alarm);

struct NavBitCheckOptions {
  double min_cn0_dbhz = 25.0;      // bits are checked at or above this C/N0 estimate
  double cn0_margin_db = 3.0;      // p at the estimate minus this
  double word_false_alarm = 1e-6;  // a clean word's contradiction probability, (0, 0.1]
  int trip_words = 2;              // contradicted words (since arming) that stop the source, >= 1
};

class NavBitCheck {
 public:
  explicit NavBitCheck(NavBitCheckOptions options = {}) : opt_(options) {}
  // One epoch wiped by a predicted bit: word = its LNAV word number (transmit time / 0.6 s, rounded down),
  // agrees = the prompt's sign is the predicted one, cn0_dbhz the channel's estimate (NaN: not checked).
  // True exactly once per arming: when a word just completed made the trip_words-th contradiction.
  bool add(std::int64_t word, bool agrees, double cn0_dbhz);
  // Counting toward the next trip restarts (the source has new data).
  void rearm() {
    since_arm_ = 0;
    tripped_ = false;
  }
  NavBitCounts& counts() { return counts_; }
  const NavBitCounts& counts() const { return counts_; }

 private:
  bool close_word();

  NavBitCheckOptions opt_;
  NavBitCounts counts_;
  std::int64_t word_ = -1;
  int n_ = 0, d_ = 0;
  double worst_p_ = 0.0;  // the largest p over the word's checked bits
  int since_arm_ = 0;
  bool tripped_ = false;
};

}  // namespace ultratrack::receiver
