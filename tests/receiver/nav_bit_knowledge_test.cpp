// SPDX-License-Identifier: GPL-3.0-or-later
// Bit knowledge a real receiver has (receiver/nav_bit_source.hpp, nav_bit_predictor.hpp, nav_bit_check.hpp),
// against signals' LnavTransmitter as the truth on the air. The signal is encoded from one ephemeris; the nav file
// holds the same one with Crs one unit (2^-5 m) off in the last place, as another generator's quantisation makes
// it, so some of its subframe 2 words differ from the signal's. By default no nav-file word that disagrees with
// the decoded copy, and no subframe 4/5 page bit, is ever predicted; the oracle reproduces the nav file's every
// bit (today's `--nav` behaviour) whatever was decoded. The contradiction check's threshold against exact binomial
// tails, its false trips on a clean source by simulation, and its trip on a corrupted one.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "receiver/nav_bit_check.hpp"
#include "receiver/nav_bit_predictor.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/lnav_subframe.hpp"
#include "signals/lnav_test_ephemerides.hpp"
#include "signals/lnav_transmitter.hpp"

using namespace ultratrack;
using namespace ultratrack::receiver;
using signals::GpsTime;

namespace {

constexpr int kWeek = 2190;

// The sets selected at `at` (as the simulator and the predictor select them), with PRN prn's Crs moved by `dcrs_m`.
std::vector<signals::Ephemeris> sets_with_crs_offset(int prn, double dcrs_m) {
  auto all = test::brdc_2022_001_ephemerides();
  for (auto& e : all)
    if (e.prn == prn) e.crs_m += dcrs_m;
  return all;
}

struct Air {  // what the satellite transmits: the transmitter as `simulate` builds it from the given sets
  explicit Air(int prn, const std::vector<signals::Ephemeris>& sets, const GpsTime& at) {
    std::vector<signals::Ephemeris> selected;
    signals::Ephemeris own;
    for (int p = 1; p <= 32; ++p)
      if (auto e = signals::select_ephemeris(sets, p, at)) {
        selected.push_back(*e);
        if (p == prn) own = *e;
      }
    tx.emplace(own, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), selected);
  }
  int bit(const GpsTime& t) { return tx->data_symbol_at(signals::add_seconds(t, 0.01)) < 0 ? 1 : 0; }
  std::optional<signals::LnavTransmitter> tx;
};

// The signal from the broadcast sets, the nav file with Crs one unit off for its PRN.
struct OneUnitOff {
  GpsTime frame{kWeek, 518400.0 + 30.0 * 7};
  int prn = test::brdc_2022_001_ephemerides()[3].prn;
  Air signal{prn, test::brdc_2022_001_ephemerides(), frame};
  std::vector<signals::Ephemeris> nav_file = sets_with_crs_offset(prn, std::ldexp(1.0, -5));
  Air nav_file_air{prn, nav_file, frame};
};

void decode_frame(NavBitPredictor& p, Air& air, const GpsTime& frame_start) {
  for (int k = 0; k < 5; ++k) {
    const GpsTime t = signals::add_seconds(frame_start, 6.0 * k);
    const auto decoded = signals::decode_lnav_subframe(air.tx->subframe_starting_at(t));
    ASSERT_EQ(decoded.status, signals::LnavStatus::kOk);
    p.add_subframe(decoded.subframe, t);
  }
}

double binomial_tail(int n, double p, int t) {  // P(X >= t), X ~ Binomial(n, p), by direct summation
  double tail = 0.0;
  for (int k = t; k <= n; ++k) {
    double c = 1.0;
    for (int j = 1; j <= k; ++j) c = c * (n - k + j) / j;
    tail += c * std::pow(p, k) * std::pow(1.0 - p, n - k);
  }
  return tail;
}

}  // namespace

TEST(NavBitKnowledge, ANavFileWordThatDisagreesWithTheDecodedCopyIsNeverUsed) {
  OneUnitOff c;
  const GpsTime& frame = c.frame;
  const int prn = c.prn;
  Air &signal = c.signal, &nav_file_air = c.nav_file_air;
  const auto& nav_file = c.nav_file;

  NavBitPredictor predictor;  // the default source
  EXPECT_EQ(predictor.source(), NavBitSource::kDecoded);
  ASSERT_TRUE(
      predictor.supply_navigation(prn, nav_file, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), frame));
  // The nav file alone: nothing predicted.
  for (int b = 0; b < 1500; b += 7) EXPECT_FALSE(predictor.bit_at(signals::add_seconds(frame, 0.02 * b))) << b;

  decode_frame(predictor, signal, frame);
  // Crs sits in subframe 2 word 3 (with the IODE): that word's data differ, and on the air its parity, which sets
  // the polarity and parity of the words after it: a word agrees when its data and the two bits before it do.
  int differ = 0;
  for (int sf = 0; sf < 3; ++sf) {
    const GpsTime t = signals::add_seconds(frame, 6.0 * sf);
    const auto a = signal.tx->subframe_starting_at(t), b = nav_file_air.tx->subframe_starting_at(t);
    for (int w = 2; w < 10; ++w) {
      bool same = true;
      for (int i = 30 * w - 2; i < 30 * w + (w == 9 ? 22 : 24); ++i) same = same && a[i] == b[i];
      differ += !same;
    }
  }
  EXPECT_GE(differ, 1);
  EXPECT_EQ(predictor.nav_words_disagreed(), differ);
  EXPECT_EQ(predictor.nav_words_agreed(), 3 * 8 - differ);

  int nav_file_differs = 0, known = 0;
  for (int bit = 0; bit < 2 * 1500; ++bit) {
    const GpsTime t = signals::add_seconds(frame, 30.0 + 0.02 * bit);
    const int id = (bit / 300) % 5 + 1, index = bit % 300;
    const auto predicted = predictor.bit_at(t);
    const int truth = signal.bit(t);
    nav_file_differs += nav_file_air.bit(t) != truth;
    if (id <= 3 || index < 60) {
      ASSERT_TRUE(predicted.has_value()) << bit;
      ASSERT_EQ(*predicted, truth) << "bit " << bit << " subframe " << id << " index " << index;
      ++known;
    } else {
      ASSERT_FALSE(predicted.has_value()) << "subframe " << id << " page bit " << index;  // pages: unknown
    }
  }
  EXPECT_GT(nav_file_differs, 0);  // word 3 (and word 4 where word 3's D30 changed), each frame
  EXPECT_EQ(known, 2 * (900 + 120));
}

// Words read one by one (their own parity held; the subframe around them need not): the nav file's words they
// confirm are known from the next frame on, the others not; subframe 2's issue-of-data word (with Crs) disagrees,
// which withdraws the whole subframe.
TEST(NavBitKnowledge, NavFileWordsConfirmedOneByOneAreKnownAndOnlyThose) {
  const GpsTime frame{kWeek, 518400.0 + 30.0 * 9};
  const int prn = test::brdc_2022_001_ephemerides()[2].prn;
  Air signal(prn, test::brdc_2022_001_ephemerides(), frame);
  const auto nav_file = sets_with_crs_offset(prn, std::ldexp(1.0, -5));
  NavBitPredictor predictor;
  ASSERT_TRUE(
      predictor.supply_navigation(prn, nav_file, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), frame));
  // Subframe 4 decoded whole (TLM, HOW flags); of subframes 1-3 single words only, subframe 3's word 5 missed.
  const GpsTime sf4 = signals::add_seconds(frame, 18.0);
  predictor.add_subframe(signals::decode_lnav_subframe(signal.tx->subframe_starting_at(sf4)).subframe, sf4);
  for (int sf = 1; sf <= 3; ++sf) {
    const GpsTime t = signals::add_seconds(frame, 6.0 * (sf - 1));
    const auto words = signal.tx->subframe_data(t);
    const auto bits = signal.tx->subframe_starting_at(t);
    for (int w = 2; w < 10; ++w) {
      if (sf == 3 && w == 4) continue;
      std::uint32_t data = words[static_cast<std::size_t>(w)];
      if (w == 9) data = signals::decode_lnav_subframe(bits).subframe.words[9];  // with its parity-solving bits
      predictor.add_word(t, w, data, bits[static_cast<std::size_t>(30 * w - 2)],
                         bits[static_cast<std::size_t>(30 * w - 1)]);
    }
  }
  EXPECT_GE(predictor.nav_words_disagreed(), 1);
  for (int sf = 1; sf <= 3; ++sf) {
    int known = 0;
    for (int index = 0; index < 300; ++index) {
      const GpsTime t = signals::add_seconds(frame, 30.0 + 6.0 * (sf - 1) + 0.02 * index);
      const auto predicted = predictor.bit_at(t);
      if (!predicted) continue;
      ++known;
      ASSERT_EQ(*predicted, signal.bit(t)) << "subframe " << sf << " bit " << index;
    }
    EXPECT_EQ(known, sf == 1 ? 300 : sf == 2 ? 60 : 270) << "subframe " << sf;
  }
}

TEST(NavBitKnowledge, SubframeFourAndFivePagesAreUnknownByDefaultEvenWithANavFile) {
  const GpsTime frame{kWeek, 518400.0 + 30.0 * 11};
  const int prn = test::brdc_2022_001_ephemerides()[0].prn;
  Air signal(prn, test::brdc_2022_001_ephemerides(), frame);
  NavBitPredictor predictor;
  ASSERT_TRUE(predictor.supply_navigation(prn, test::brdc_2022_001_ephemerides(), test::brdc_2022_001_klobuchar(),
                                          test::brdc_2022_001_utc(), frame));
  decode_frame(predictor, signal, frame);
  EXPECT_EQ(predictor.nav_words_agreed(), 24);
  EXPECT_EQ(predictor.nav_words_disagreed(), 0);
  for (int frame_k = 1; frame_k <= 25; frame_k += 6)  // several pages
    for (int sf = 4; sf <= 5; ++sf)
      for (int index = 0; index < 300; ++index) {
        const GpsTime t = signals::add_seconds(frame, 30.0 * frame_k + 6.0 * (sf - 1) + 0.02 * index);
        EXPECT_EQ(predictor.bit_at(t).has_value(), index < 60) << "subframe " << sf << " bit " << index;
      }
}

TEST(NavBitKnowledge, OracleReproducesTheNavFilesEveryBitWhateverWasDecoded) {
  OneUnitOff c;
  const GpsTime& frame = c.frame;
  const int prn = c.prn;
  Air &signal = c.signal, &nav_file_air = c.nav_file_air;
  const auto& nav_file = c.nav_file;
  NavBitPredictor oracle(NavBitSource::kOracle);
  ASSERT_TRUE(
      oracle.supply_navigation(prn, nav_file, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), frame));
  decode_frame(oracle, signal, frame);
  int differs_from_signal = 0;
  for (int bit = 0; bit < 25 * 1500 / 10; ++bit) {  // 75 s: every subframe, several pages
    const GpsTime t = signals::add_seconds(frame, 0.02 * bit);
    const auto predicted = oracle.bit_at(t);
    ASSERT_TRUE(predicted.has_value()) << bit;
    ASSERT_EQ(*predicted, nav_file_air.bit(t)) << bit;
    differs_from_signal += *predicted != signal.bit(t);
  }
  EXPECT_GT(differs_from_signal, 0);  // the oracle wipes with the nav file's words, wrong ones included
}

TEST(NavBitKnowledge, AStoppedDecodedSourceKnowsNothingUntilNewData) {
  const GpsTime frame{kWeek, 518400.0 + 30.0 * 3};
  const auto all = test::brdc_2022_001_ephemerides();
  const int prn = all[4].prn;
  Air first(prn, all, frame);
  NavBitPredictor predictor;
  decode_frame(predictor, first, frame);
  EXPECT_TRUE(predictor.take_new_data());
  const GpsTime next = signals::add_seconds(frame, 30.0);
  ASSERT_TRUE(predictor.bit_at(next).has_value());
  predictor.stop();
  EXPECT_FALSE(predictor.bit_at(next).has_value());
  EXPECT_FALSE(predictor.bit_at(signals::add_seconds(next, 0.02 * 400)).has_value());
  decode_frame(predictor, first, next);  // the same data again: still stopped
  EXPECT_FALSE(predictor.take_new_data());
  EXPECT_FALSE(predictor.bit_at(signals::add_seconds(next, 30.0)).has_value());
  auto changed = all;
  for (auto& e : changed)
    if (e.prn == prn) e.crs_m += 1.0;
  Air second(prn, changed, frame);
  decode_frame(predictor, second, signals::add_seconds(next, 30.0));
  EXPECT_TRUE(predictor.take_new_data());
  EXPECT_TRUE(predictor.bit_at(signals::add_seconds(next, 60.0)).has_value());
}

TEST(NavBitCheck, BitErrorProbabilityAndThresholdAgainstClosedForms) {
  // 20 dB-Hz over 20 ms: 2 C/N0 T = 4, Q(2).
  EXPECT_NEAR(bit_error_probability(20.0), 0.022750131948179, 1e-14);
  EXPECT_NEAR(bit_error_probability(20.0 + 10.0 * std::log10(2.0), 0.01), 0.022750131948179, 1e-12);
  // p = 1/2 over 30 bits: P(X >= 28) = 466 / 2^30 = 4.3e-7 <= 1e-6 < P(X >= 27) = 4526 / 2^30.
  EXPECT_EQ(word_contradiction_threshold(30, 0.5, 1e-6), 28);
  EXPECT_EQ(word_contradiction_threshold(30, 0.5, 4527.0 / 1073741824.0), 27);
  // The smallest t with the tail at or below alpha, by direct binomial sums, over C/N0 and word lengths.
  for (int n : {1, 10, 30})
    for (double cn0 = 12.0; cn0 <= 40.0; cn0 += 0.5) {
      const double p = bit_error_probability(cn0);
      const int t = word_contradiction_threshold(n, p, 1e-6);
      if (t <= n) {
        EXPECT_LE(binomial_tail(n, p, t), 1e-6 * (1 + 1e-9)) << n << " " << cn0;
      }
      if (t >= 1) {
        EXPECT_GT(binomial_tail(n, p, t - 1), 1e-6) << n << " " << cn0;
      }
    }
  EXPECT_EQ(word_contradiction_threshold(30, 0.9, 1e-6), 31);  // never
}

// The check on 20 ms bits at a true and measured C/N0 (bit errors drawn with p = Q(sqrt(2 C/N0 T))).
// Clean source: a word is contradicted with probability <= alpha = 1e-6 (the threshold's definition, with the
// 3 dB margin making it far smaller), so two of W = 50 000 words (8.3 h) trip with probability
// <= C(W, 2) alpha^2 = 1.25e-3: none expected. Corrupted source: one word per frame (every 50th) with 4 wrong bits
// (a field one unit off with its parity) at 30 dB-Hz is contradicted every frame (t = 2 there) and trips at the
// second; one word per frame inverted trips at 25 dB-Hz as well (t = 5 of 30), where the 4-bit word is not seen.
TEST(NavBitCheck, TripsOnACorruptedSourceAndNotOnACleanOne) {
  std::mt19937_64 rng(27);
  const auto run = [&rng](double cn0_dbhz, int words, int wrong_bits_every_50th) {
    NavBitCheck check;
    const double p = bit_error_probability(cn0_dbhz);
    std::bernoulli_distribution error(p);
    int tripped_at = -1;
    for (int w = 0; w < words; ++w)
      for (int b = 0; b < 30; ++b) {
        bool agrees = !error(rng);
        if (w % 50 == 7 && b < wrong_bits_every_50th) agrees = !agrees;
        if (check.add(w, agrees, cn0_dbhz) && tripped_at < 0) tripped_at = w;
      }
    check.add(words, true, NAN);  // closes the last word (an unchecked bit)
    return std::pair{tripped_at, check.counts()};
  };
  for (const double cn0 : {25.0, 27.0, 30.0, 40.0}) {
    const auto [tripped, counts] = run(cn0, 50000, 0);
    EXPECT_EQ(tripped, -1) << cn0;
    EXPECT_EQ(counts.words_contradicted, 0) << cn0;
    EXPECT_EQ(counts.bits_checked, 50000LL * 30);
  }
  {
    const auto [tripped, counts] = run(30.0, 500, 4);
    EXPECT_EQ(tripped, 58);  // the second corrupted word (57) closes when word 58 begins
    EXPECT_EQ(counts.words_contradicted, 10);
  }
  {
    const auto [tripped, counts] = run(25.0, 500, 30);
    EXPECT_EQ(tripped, 58);
    EXPECT_EQ(counts.words_contradicted, 10);
  }
  {  // below min_cn0_dbhz nothing is checked
    const auto [tripped, counts] = run(24.0, 500, 30);
    EXPECT_EQ(tripped, -1);
    EXPECT_EQ(counts.bits_checked, 0);
  }
}

TEST(NavBitSource, ParsesItsTwoNamesAndNamesTheBadOne) {
  EXPECT_EQ(parse_nav_bit_source("x", "decoded"), NavBitSource::kDecoded);
  EXPECT_EQ(parse_nav_bit_source("x", "oracle"), NavBitSource::kOracle);
  EXPECT_STREQ(to_string(NavBitSource::kOracle), "oracle");
  try {
    parse_nav_bit_source("cfg.toml", "guess");
    FAIL();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cfg.toml: nav bits 'guess'"), std::string::npos);
  }
}
