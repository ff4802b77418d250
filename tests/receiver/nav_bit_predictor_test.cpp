// SPDX-License-Identifier: GPL-3.0-or-later
// The bit predictor against the simulator's transmitted bits (signals::LnavTransmitter built as `simulate`
// builds it: ephemeris per PRN selected at the start, the selected set for the almanac pages): from decoded
// subframes, subframes 1-3 of the next frames and the TLM/HOW of subframes 4-5; from a supplied nav source,
// every bit.
#include "receiver/nav_bit_predictor.hpp"

#include <gtest/gtest.h>

#include "signals/ephemeris_selection.hpp"
#include "signals/lnav_subframe.hpp"
#include "signals/lnav_test_ephemerides.hpp"
#include "signals/lnav_transmitter.hpp"

using namespace ultratrack;
using namespace ultratrack::receiver;
using signals::GpsTime;

namespace {

constexpr int kWeek = 2190;

struct Simulated {
  std::vector<signals::Ephemeris> selected;
  signals::Ephemeris own;
};

// What tools/simulation.cpp (load_navigation) hands the synthesiser: per PRN the set selected at the start.
Simulated simulated(int prn, const GpsTime& start) {
  Simulated s;
  for (int p = 1; p <= 32; ++p)
    if (auto e = signals::select_ephemeris(test::brdc_2022_001_ephemerides(), p, start)) {
      s.selected.push_back(*e);
      if (p == prn) s.own = *e;
    }
  return s;
}

}  // namespace

TEST(NavBitPredictor, FromDecodedSubframesKnowsSubframes1To3AndEveryTlmHow) {
  const GpsTime start{kWeek, 518400.0 + 30.0 * 7};  // a frame start (subframe 1)
  const auto all = test::brdc_2022_001_ephemerides();
  const int prn = all[3].prn;
  const Simulated sim = simulated(prn, start);
  signals::LnavTransmitter tx(sim.own, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), sim.selected);
  NavBitPredictor predictor;
  EXPECT_FALSE(predictor.bit_at(start).has_value());
  // One frame received and decoded (as the channel's frame sync hands subframes over).
  for (int k = 0; k < 5; ++k) {
    const GpsTime t = signals::add_seconds(start, 6.0 * k);
    const auto decoded = signals::decode_lnav_subframe(tx.subframe_starting_at(t));
    ASSERT_EQ(decoded.status, signals::LnavStatus::kOk);
    predictor.add_subframe(decoded.subframe, t);
  }
  // The next three frames (different TOW counts, subframe 4/5 pages) against the bits on the air.
  int known = 0, unknown = 0;
  for (int bit = 0; bit < 3 * 1500; ++bit) {
    const GpsTime t = signals::add_seconds(start, 30.0 + 0.02 * bit);
    const int in_subframe = bit % 300;
    const int subframe_id = (bit / 300) % 5 + 1;
    const auto predicted = predictor.bit_at(t);
    const int truth = tx.data_symbol_at(signals::add_seconds(t, 0.01)) < 0 ? 1 : 0;
    if (subframe_id <= 3 || in_subframe < 60) {
      ASSERT_TRUE(predicted.has_value()) << "bit " << bit;
      ASSERT_EQ(*predicted, truth) << "bit " << bit << " subframe " << subframe_id << " index " << in_subframe;
      ++known;
    } else {
      EXPECT_FALSE(predicted.has_value()) << "bit " << bit;
      ++unknown;
    }
  }
  EXPECT_EQ(known, 3 * (900 + 120));
  EXPECT_EQ(unknown, 3 * 480);
  // A time a few ns off the edge reads the same bit (the caller's code-period arithmetic in double).
  const GpsTime edge = signals::add_seconds(start, 30.0 + 0.02 * 77);
  EXPECT_EQ(predictor.bit_at(signals::add_seconds(edge, -3e-9)), predictor.bit_at(edge));
}

TEST(NavBitPredictor, NewIssueOfDataReplacesThePredictedSubframes) {
  const GpsTime start{kWeek, 518400.0 + 30.0 * 3};
  const auto all = test::brdc_2022_001_ephemerides();
  signals::Ephemeris first = all[4], second = all[4];
  second.iode = (first.iode + 7) % 256;
  second.iodc = second.iode;
  second.crs_m = first.crs_m + 8.0;
  signals::LnavTransmitter tx1(first, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), {first});
  signals::LnavTransmitter tx2(second, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), {second});
  NavBitPredictor predictor;
  for (int k = 0; k < 3; ++k) {
    const GpsTime t = signals::add_seconds(start, 6.0 * k);
    predictor.add_subframe(signals::decode_lnav_subframe(tx1.subframe_starting_at(t)).subframe, t);
  }
  // Subframe 2 of the next frame differs from the old data under the new IODE, and follows it once decoded.
  const GpsTime next_sf2 = signals::add_seconds(start, 36.0);
  int differ_old = 0;
  for (int b = 0; b < 300; ++b) {
    const GpsTime t = signals::add_seconds(next_sf2, 0.02 * b);
    const int truth2 = tx2.data_symbol_at(signals::add_seconds(t, 0.01)) < 0 ? 1 : 0;
    differ_old += *predictor.bit_at(t) != truth2;
  }
  EXPECT_GT(differ_old, 0);
  predictor.add_subframe(
      signals::decode_lnav_subframe(tx2.subframe_starting_at(signals::add_seconds(start, 6.0))).subframe,
      signals::add_seconds(start, 6.0));
  for (int b = 0; b < 300; ++b) {
    const GpsTime t = signals::add_seconds(next_sf2, 0.02 * b);
    ASSERT_EQ(*predictor.bit_at(t), tx2.data_symbol_at(signals::add_seconds(t, 0.01)) < 0 ? 1 : 0) << b;
  }
}

TEST(NavBitPredictor, SuppliedNavigationKnowsEveryBitTheSimulatorSends) {
  const GpsTime start{kWeek, 518400.0 + 1234.0};  // a simulated file's start (any time)
  const auto all = test::brdc_2022_001_ephemerides();
  for (const int index : {0, 4}) {
    const int prn = all[static_cast<std::size_t>(index)].prn;
    const Simulated sim = simulated(prn, start);
    signals::LnavTransmitter tx(sim.own, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), sim.selected);
    NavBitPredictor predictor(NavBitSource::kOracle);
    // the receiver selects a few seconds after the file's start (its first time tag)
    ASSERT_TRUE(predictor.supply_navigation(prn, all, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(),
                                            signals::add_seconds(start, 7.3)));
    const GpsTime first_edge{kWeek, 518400.0 + 1236.0};
    for (int bit = 0; bit < 25 * 1500 / 10; ++bit) {  // 75 s: every subframe kind, several 4/5 pages
      const GpsTime t = signals::add_seconds(first_edge, 0.02 * bit);
      const auto predicted = predictor.bit_at(t);
      ASSERT_TRUE(predicted.has_value());
      ASSERT_EQ(*predicted, tx.data_symbol_at(signals::add_seconds(t, 0.01)) < 0 ? 1 : 0)
          << "PRN " << prn << " bit " << bit;
    }
  }
  NavBitPredictor none;
  EXPECT_FALSE(none.supply_navigation(33, all, test::brdc_2022_001_klobuchar(), test::brdc_2022_001_utc(), start));
  EXPECT_FALSE(none.supplied());
}
