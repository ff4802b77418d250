// SPDX-License-Identifier: GPL-3.0-or-later
// Frame sync of a bit-at-a-time LNAV stream: lock on the first full subframe wherever the stream starts,
// either polarity; parity failures reported while locked; relock after a bit slip.
#include "signals/lnav_frame_sync.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "lnav_test_ephemerides.hpp"
#include "signals/lnav_decoder.hpp"
#include "signals/lnav_transmitter.hpp"

using namespace ultratrack::signals;

namespace {

constexpr int kWeek = 2190;

LnavTransmitter make_transmitter() {
  const auto all = ultratrack::test::brdc_2022_001_ephemerides();
  return LnavTransmitter(all[1], ultratrack::test::brdc_2022_001_klobuchar(), ultratrack::test::brdc_2022_001_utc(),
                         all);
}

// n bits on the air from `start` (sampled mid-bit), as 0/1.
std::vector<std::uint8_t> on_air(LnavTransmitter& tx, GpsTime start, int n) {
  std::vector<std::uint8_t> bits;
  for (int i = 0; i < n; ++i) bits.push_back(tx.data_symbol_at(add_seconds(start, 0.02 * i + 0.01)) < 0 ? 1 : 0);
  return bits;
}

}  // namespace

TEST(LnavFrameSync, LocksOnFirstFullSubframeFromAnyStartAndPolarity) {
  for (const bool invert : {false, true}) {
    LnavTransmitter tx = make_transmitter();
    std::mt19937 rng(invert ? 11 : 12);
    std::vector<std::uint8_t> stream;
    for (int i = 0; i < 137; ++i) stream.push_back(static_cast<std::uint8_t>(rng() & 1u));  // before lock-in
    // The signal joins 2.3 s (115 bits) into the subframe starting at 518406 s (subframe 2).
    const std::vector<std::uint8_t> sig = on_air(tx, {kWeek, 518406.0 + 2.3}, 115 + 300 * 8);
    stream.insert(stream.end(), sig.begin(), sig.end());
    if (invert)
      for (auto& b : stream) b ^= 1;

    LnavDecoder decoder(2, kWeek);
    std::vector<LnavFrameSyncOutput> outs;
    int bits_when_ephemeris = -1;
    for (std::size_t i = 0; i < stream.size(); ++i) {
      if (auto out = decoder.add_bit(stream[i])) {
        outs.push_back(*out);
        if (decoder.last_update().ephemeris && bits_when_ephemeris < 0) bits_when_ephemeris = static_cast<int>(i + 1);
      }
    }
    ASSERT_EQ(outs.size(), 7u) << invert;  // first full subframe starts at 518412 s: 7 whole ones follow
    for (std::size_t k = 0; k < outs.size(); ++k) {
      EXPECT_EQ(outs[k].result.status, LnavStatus::kOk);
      EXPECT_EQ(outs[k].first_bit_index, 137 + (300 - 115) + 300 * static_cast<std::int64_t>(k));
      EXPECT_EQ(outs[k].result.subframe.start_tow_s(), 518412.0 + 6.0 * k);
      EXPECT_EQ(outs[k].result.subframe.inverted, invert);
    }
    // Subframes 3, 4, 5, 1, 2: the ephemeris completes with the fifth (subframe 2 of the next frame).
    EXPECT_EQ(bits_when_ephemeris, 137 + (300 - 115) + 300 * 5);
    ASSERT_TRUE(decoder.ephemeris().has_value());
    EXPECT_EQ(decoder.ephemeris()->iode, 41);
    EXPECT_EQ(decoder.counters().parity_errors, 0);
  }
}

TEST(LnavFrameSync, ParityFailureWhileLockedIsReportedAndLockKept) {
  LnavTransmitter tx = make_transmitter();
  std::vector<std::uint8_t> stream = on_air(tx, {kWeek, 518400.0}, 300 * 6);
  stream[300 * 2 + 77] ^= 1;  // one bit error in the third subframe
  LnavDecoder decoder(2, kWeek);
  std::vector<LnavFrameSyncOutput> outs;
  for (auto b : stream)
    if (auto out = decoder.add_bit(b)) outs.push_back(*out);
  ASSERT_EQ(outs.size(), 6u);
  EXPECT_EQ(outs[2].result.status, LnavStatus::kParityError);
  EXPECT_EQ(outs[2].result.failed_word, 3);
  EXPECT_EQ(outs[3].result.status, LnavStatus::kOk);
  EXPECT_TRUE(decoder.frame_locked());
  EXPECT_EQ(decoder.counters().parity_errors, 1);
  EXPECT_EQ(decoder.counters().accepted, 5);
  EXPECT_FALSE(decoder.ephemeris().has_value());  // subframe 3 was lost; the next one is in the next frame
}

TEST(LnavFrameSync, RelocksAfterBitSlip) {
  LnavTransmitter tx = make_transmitter();
  std::vector<std::uint8_t> stream = on_air(tx, {kWeek, 518400.0}, 300 * 10);
  stream.insert(stream.begin() + 300 * 2 + 40, 1);  // the bit synchroniser slips: one extra bit
  LnavFrameSync sync;
  std::vector<LnavFrameSyncOutput> outs;
  for (auto b : stream)
    if (auto out = sync.push(b)) outs.push_back(*out);
  // Subframes 1, 2 fine; 3 (holding the extra bit) fails, and so does the block 300 bits later, which is
  // one bit early for subframe 4; the lock is dropped and the search finds subframe 4 one bit on.
  ASSERT_EQ(outs.size(), 11u);  // 2 + 2 failed + 7 after relock (subframes 4..10)
  EXPECT_EQ(outs[0].result.status, LnavStatus::kOk);
  EXPECT_EQ(outs[1].result.status, LnavStatus::kOk);
  EXPECT_NE(outs[2].result.status, LnavStatus::kOk);
  EXPECT_NE(outs[3].result.status, LnavStatus::kOk);
  EXPECT_EQ(outs[4].result.status, LnavStatus::kOk);
  EXPECT_EQ(outs[4].first_bit_index, 300 * 3 + 1);
  EXPECT_EQ(outs[4].result.subframe.start_tow_s(), 518418.0);
  for (std::size_t k = 5; k < outs.size(); ++k) EXPECT_EQ(outs[k].result.status, LnavStatus::kOk);
  EXPECT_TRUE(sync.locked());
}
