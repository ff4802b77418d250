// SPDX-License-Identifier: GPL-3.0-or-later
// Bit synchronisation for GPS LNAV (50 bit/s, 20 code periods per bit): a histogram of prompt sign changes
// between successive 1 ms epochs over the 20 possible bit-edge positions, and the maximum-likelihood test on the
// energy of 20 ms prompt sums at the 20 candidate offsets (whichever decides first); then assembly of 20 ms bits
// (+1/-1 with a soft value) from epochs aligned to the found edge, for the LNAV decoder. Code periods are the
// channel's.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <optional>

#include "receiver/correlation_epoch.hpp"

namespace ultratrack::receiver {

// The edge is decided, once the winning bin holds min_edges, by either test: the ratio (fast at high C/N0, where
// noise flips are rare) or the lead. A sign change between 1 ms prompts is a DPSK decision: noise flips it with
// p = exp(-C/N0 T) / 2 (0.30 at 27 dB-Hz, 0.14 at 31), so the non-edge bins grow at p per bit while the edge bin
// grows at 1/2 (random data). The ratio of their counts tends to 1 / (2 p), below 3 under ~31 dB-Hz: a ratio
// test alone never decides there. The lead test asks that the winner lead the runner-up by min_lead_sigma
// standard deviations of a difference of two counts, sqrt(best + runner-up) (Poisson): it decides at any C/N0
// where 1/2 > p, in ~(z / (1/2 - p))^2 bits (7 s at 27 dB-Hz, 15 s at 25 with z = 4), and picks a wrong bin
// only with the probability of a 4-sigma excursion against a bin that is ahead on average.
//
// The energy test: for each candidate offset c the sum E_c over bits of |sum of the 20 prompts of a window starting
// at c|^2 (the maximum-likelihood edge for random +-1 data is the argmax at moderate SNR). A window shifted m ms
// from the true edge loses 2 m (20 - m) A^2 per bit on average (A: 1 ms prompt amplitude): 38 A^2 at m = 1, against
// a per-bit spread of ~26 sigma^2 at 25 dB-Hz, i.e. ~0.45 sigma per bit instead of the sign test's ~0.14 at 25
// dB-Hz. It decides once the best candidate leads every other one by min_energy_sigma standard deviations of
// their summed difference, its variance estimated from the bits themselves (per-bit variance plus the lag-1
// covariance of neighbouring bits, whose windows overlap).
struct BitSyncOptions {
  int min_edges = 10;             // transitions counted in the winning bin before deciding; [3, 1000]
  double min_ratio = 3.0;         // winning bin / runner-up bin; [1.5, 100]
  double min_lead_sigma = 4.0;    // (winning - runner-up) / sqrt(winning + runner-up); [3, 100]
  int max_periods = 10000;        // give up (failed()) after this many 1 ms epochs; >= 200
  bool energy_test = true;        // also run the energy (maximum-likelihood) test
  int min_energy_bits = 25;       // complete 20-window sets before the energy test may decide; [10, 1000]
  double min_energy_sigma = 5.0;  // lead over every other offset, in standard deviations; [3, 100]
};

class BitSynchronizer final {
 public:
  explicit BitSynchronizer(const BitSyncOptions& options = {}) : options_(options) {}
  // One 1 ms prompt with its code period index (consecutive calls should be consecutive periods; a gap only
  // suppresses the comparison across it). Sign change = Re(P_k conj(P_k-1)) < 0, valid without phase lock.
  void add(std::int64_t code_period, std::complex<float> prompt);
  bool synchronised() const { return synchronised_; }
  bool failed() const { return !synchronised_ && periods_ >= options_.max_periods; }
  // Once synchronised: a code period at which a bit starts; edges are every 20 periods from it.
  std::int64_t edge_period() const { return edge_; }
  const std::array<int, 20>& histogram() const { return bins_; }
  // Energy test state: per offset (period index modulo 20 at which a window starts) the summed energy of complete
  // 20-window sets, and the number of sets. Its argmax is the maximum-likelihood edge.
  const std::array<double, 20>& energies() const { return energy_; }
  int energy_bits() const { return energy_sets_; }
  void reset() { *this = BitSynchronizer(options_); }

 private:
  void add_energy(std::int64_t code_period, std::complex<float> prompt);
  bool energy_decides(int* best) const;

  BitSyncOptions options_;
  // energy test: the last 20 prompts, how many consecutive ones are held, the current set of window energies
  std::array<std::complex<double>, 20> ring_{};
  int consecutive_ = 0;
  std::array<double, 20> window_{};
  int window_count_ = 0;  // windows of the current set filled (consecutively)
  std::array<double, 20> energy_{};
  std::array<std::array<double, 20>, 20> cross_{};  // sums of window_j * window_k over sets
  // sums of previous set's window_j * this set's window_k: windows of neighbouring sets overlap, so the summed
  // difference of two offsets has a lag-1 covariance (large for offsets near 19, whose windows overlap the
  // next set's offset 0 more than this set's)
  std::array<std::array<double, 20>, 20> lag_{};
  std::array<double, 20> previous_window_{};
  bool have_previous_set_ = false;
  int lag_sets_ = 0;
  int energy_sets_ = 0;
  std::array<int, 20> bins_{};
  int periods_ = 0;
  bool have_previous_ = false;
  std::int64_t previous_period_ = 0;
  std::complex<float> previous_{};
  bool synchronised_ = false;
  std::int64_t edge_ = 0;
};

// One navigation bit: value +1/-1 (sign of the in-phase prompt; a Costas loop leaves a 180 degree ambiguity that
// the LNAV preamble resolves), soft = I / (mean |P| of recent bits), about +-1 when clean.
struct NavBit {
  std::int64_t first_sample = 0;       // receiver sample index where the bit starts
  std::int64_t first_code_period = 0;  // channel code period where the bit starts (an edge period)
  int value = 0;
  float soft = 0.0f;
};

// Sums prompts of epochs lying inside one bit (1, 2, 4, 5, 10 or 20 periods each, aligned to the edges) into bits.
class BitAssembler final {
 public:
  explicit BitAssembler(std::int64_t edge_period) : edge_(edge_period) {}
  std::optional<NavBit> add(const CorrelationEpoch& epoch);
  // Differential detection (a carrier that is frequency- but not phase-locked: vector FLL): each bit's value is
  // the previous bit's times the sign of Re(sum conj(previous sum)), its soft value that projection over the
  // previous sum's magnitude and the running amplitude. The chain starts from the last coherently detected bit (so
  // a switch from a phase-locked carrier keeps the polarity); after a gap the first bit is decided coherently
  // (sign of the real part: arbitrary polarity, which the decoder's preamble search resolves). A differential
  // error inverts all later bits (BER 0.5 exp(-Eb/N0), 1e-9 at 30 dB-Hz, 1e-3 at 25).
  void set_differential(bool differential) { differential_ = differential; }

 private:
  bool differential_ = false;
  bool have_previous_ = false;  // previous_ is the bit just before the current one
  std::complex<double> previous_sum_{};
  int previous_value_ = 1;
  std::int64_t previous_period_ = 0;
  std::int64_t edge_;
  bool active_ = false;
  NavBit current_{};
  std::complex<double> sum_{};
  int periods_ = 0;
  double amplitude_ = 0.0;
};

}  // namespace ultratrack::receiver
