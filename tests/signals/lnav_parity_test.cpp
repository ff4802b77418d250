// SPDX-License-Identifier: GPL-3.0-or-later
// LNAV word parity against independent truth: words received from real satellites, and the IS-GPS-200
// Table 20-XIV equations written out again here as bit strings.
#include "signals/lnav_parity.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace ultratrack::signals;

namespace {

// Four consecutive words of one subframe as logged by a SiRF GSD4t receiver (published in
// github.com/mnalis/gsd4t_parser, commit 3c3c98c, "50Bps raw 10 30-bit words"): each 32-bit value holds
// the previous word's D29, D30 in its two MSBs and the 30 received bits below. They are a TLM word, a HOW
// received after a word ending in D29 D30 = 1 1 (so its data bits are complemented on the air), and the
// first two words of a subframe 5 page holding a dummy SV (data ID 01, SV ID 0, alternating 1010 fill).
struct ReceivedWord {
  std::uint32_t logged;
  std::uint32_t expected_data;  // d1..d24 read from the IS-GPS-200 structure of that page
};
constexpr ReceivedWord kReceived[4] = {
    {0x22C3062Bu, 0x8B0C18u},  // preamble 10001011, TLM message, integrity, reserved
    {0xEDBA7238u, 0x491637u},  // TOW count 37420, alert 0, A-S 1, subframe ID 5, t = 11
    {0x102AAAACu, 0x40AAAAu},  // data ID 01, SV ID 000000, fill 1010...
    {0x2AAAAABCu, 0xAAAAAAu},  // fill
};

// Table 20-XIV, written as which of d1..d24 (left to right) enter D25..D30, and which previous bit.
constexpr const char* kEquations[6] = {
    "111011000111110011010010",  // D25 = D29* + d1 d2 d3 d5 d6 d10 d11 d12 d13 d14 d17 d18 d20 d23
    "011101100011111001101001",  // D26 = D30* + d2 d3 d4 d6 d7 d11 d12 d13 d14 d15 d18 d19 d21 d24
    "101110110001111100110100",  // D27 = D29* + d1 d3 d4 d5 d7 d8 d12 d13 d14 d15 d16 d19 d20 d22
    "010111011000111110011010",  // D28 = D30* + d2 d4 d5 d6 d8 d9 d13 d14 d15 d16 d17 d20 d21 d23
    "101011101100011111001101",  // D29 = D30* + d1 d3 d5 d6 d7 d9 d10 d14 d15 d16 d17 d18 d21 d22 d24
    "001011011110101000100111",  // D30 = D29* + d3 d5 d6 d8 d9 d10 d11 d13 d15 d19 d22 d23 d24
};
constexpr bool kUsesD30[6] = {false, true, false, true, true, false};

}  // namespace

TEST(LnavParity, AcceptsWordsReceivedFromSatellites) {
  for (const auto& w : kReceived) {
    const int d29 = static_cast<int>((w.logged >> 31) & 1u), d30 = static_cast<int>((w.logged >> 30) & 1u);
    const auto data = check_word(w.logged & 0x3FFFFFFFu, d29, d30);
    ASSERT_TRUE(data.has_value()) << std::hex << w.logged;
    EXPECT_EQ(*data, w.expected_data) << std::hex << w.logged;
    // And the encoder reproduces the received bits from the data.
    EXPECT_EQ(encode_lnav_word(w.expected_data, d29, d30), w.logged & 0x3FFFFFFFu) << std::hex << w.logged;
  }
}

TEST(LnavParity, RejectsEverySingleBitErrorInReceivedWords) {
  for (const auto& w : kReceived) {
    const int d29 = static_cast<int>((w.logged >> 31) & 1u), d30 = static_cast<int>((w.logged >> 30) & 1u);
    for (int b = 0; b < 30; ++b) {
      EXPECT_FALSE(check_word((w.logged & 0x3FFFFFFFu) ^ (1u << b), d29, d30).has_value()) << b;
    }
  }
}

TEST(LnavParity, ParityBitsEqualTable20XivSums) {
  std::mt19937 rng(20030);
  for (int trial = 0; trial < 20000; ++trial) {
    const std::uint32_t d = rng() & 0xFFFFFFu;
    const int p29 = static_cast<int>(rng() & 1u), p30 = static_cast<int>(rng() & 1u);
    const std::uint32_t word = encode_lnav_word(d, p29, p30);
    for (int k = 0; k < 6; ++k) {
      int sum = kUsesD30[k] ? p30 : p29;
      for (int j = 0; j < 24; ++j)
        if (kEquations[k][j] == '1') sum ^= static_cast<int>((d >> (23 - j)) & 1u);
      ASSERT_EQ(static_cast<int>((word >> (5 - k)) & 1u), sum) << "D" << 25 + k;
    }
    // D1..D24 are d1..d24 complemented when D30* = 1.
    ASSERT_EQ((word >> 6) & 0xFFFFFFu, p30 ? (~d & 0xFFFFFFu) : d);
  }
}

TEST(LnavParity, SolvedBitsGiveZeroD29D30) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5000; ++trial) {
    const int p29 = static_cast<int>(rng() & 1u), p30 = static_cast<int>(rng() & 1u);
    const std::uint32_t d = solve_lnav_parity_bits(rng() & 0xFFFFFFu, p29, p30);
    EXPECT_EQ(encode_lnav_word(d, p29, p30) & 3u, 0u);
  }
}
