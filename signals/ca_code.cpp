// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/ca_code.hpp"

#include <stdexcept>
#include <string>

namespace ultratrack::signals {
namespace {

// G2 output taps (1-based register stages) per PRN, IS-GPS-200 Table 3-Ia "code phase selection".
constexpr int kG2Taps[kMaxPrn][2] = {
    {2, 6}, {3, 7}, {4, 8}, {5, 9}, {1, 9},  {2, 10}, {1, 8}, {2, 9}, {3, 10}, {2, 3}, {3, 4},
    {5, 6}, {6, 7}, {7, 8}, {8, 9}, {9, 10}, {1, 4},  {2, 5}, {3, 6}, {4, 7},  {5, 8}, {6, 9},
    {1, 3}, {4, 6}, {5, 7}, {6, 8}, {7, 9},  {8, 10}, {1, 6}, {2, 7}, {3, 8},  {4, 9},
};

std::array<std::uint8_t, kCaCodeLength_chips> generate_bits(int prn) {
  std::array<std::uint8_t, 10> g1, g2;
  g1.fill(1);
  g2.fill(1);
  const int tap_a = kG2Taps[prn - 1][0] - 1, tap_b = kG2Taps[prn - 1][1] - 1;
  std::array<std::uint8_t, kCaCodeLength_chips> bits{};
  for (int i = 0; i < kCaCodeLength_chips; ++i) {
    bits[i] = g1[9] ^ g2[tap_a] ^ g2[tap_b];
    const std::uint8_t g1_in = g1[2] ^ g1[9];
    const std::uint8_t g2_in = g2[1] ^ g2[2] ^ g2[5] ^ g2[7] ^ g2[8] ^ g2[9];
    for (int k = 9; k > 0; --k) {
      g1[k] = g1[k - 1];
      g2[k] = g2[k - 1];
    }
    g1[0] = g1_in;
    g2[0] = g2_in;
  }
  return bits;
}

struct CodeTable {
  std::array<CaCodeChips, kMaxPrn> chips{};
  CodeTable() {
    for (int prn = kMinPrn; prn <= kMaxPrn; ++prn) {
      const auto bits = generate_bits(prn);
      for (int i = 0; i < kCaCodeLength_chips; ++i) chips[prn - 1][i] = bits[i] ? -1 : 1;
    }
  }
};

void check_prn(int prn) {
  if (prn < kMinPrn || prn > kMaxPrn) throw std::out_of_range("C/A code: PRN " + std::to_string(prn) + " not in 1..32");
}

}  // namespace

const CaCodeChips& ca_code(int prn) {
  check_prn(prn);
  static const CodeTable table;  // thread-safe one-time initialisation
  return table.chips[prn - 1];
}

std::array<std::uint8_t, kCaCodeLength_chips> ca_code_bits(int prn) {
  check_prn(prn);
  return generate_bits(prn);
}

}  // namespace ultratrack::signals
