// SPDX-License-Identifier: GPL-3.0-or-later
// C/A codes against IS-GPS-200 Table 3-Ia (first 10 chips, octal) and the Gold-code correlation property.
#include "signals/ca_code.hpp"

#include <gtest/gtest.h>

#include <set>

using namespace ultratrack::signals;

namespace {
// IS-GPS-200 Table 3-Ia, "First 10 Chips C/A" in octal (MSB = first chip), PRN 1..32.
constexpr int kFirstTenChipsOctal[32] = {
    01440, 01620, 01710, 01744, 01133, 01455, 01131, 01454, 01626, 01504, 01642, 01750, 01764, 01772, 01775, 01776,
    01156, 01467, 01633, 01715, 01746, 01763, 01063, 01706, 01743, 01761, 01770, 01774, 01127, 01453, 01625, 01712,
};
}  // namespace

TEST(CaCode, FirstTenChipsMatchIsGps200Table3Ia) {
  for (int prn = 1; prn <= 32; ++prn) {
    const auto bits = ca_code_bits(prn);
    int value = 0;
    for (int i = 0; i < 10; ++i) value = (value << 1) | bits[i];
    EXPECT_EQ(value, kFirstTenChipsOctal[prn - 1]) << "PRN " << prn;
  }
}

TEST(CaCode, ChipsAreSignedBits) {
  for (int prn = 1; prn <= 32; ++prn) {
    const auto bits = ca_code_bits(prn);
    const auto& chips = ca_code(prn);
    for (int i = 0; i < 1023; ++i) ASSERT_EQ(chips[i], bits[i] ? -1 : 1);
  }
}

TEST(CaCode, GoldCodeCorrelationTakesOnlyThreeValues) {
  // Gold codes of degree 10: the periodic auto-correlation off peak and every cross-correlation take
  // only the values -65, -1 and 63; the auto-correlation peak is 1023.
  const std::set<int> allowed{-65, -1, 63};
  for (int a = 1; a <= 32; ++a) {
    const auto& ca = ca_code(a);
    for (int b = a; b <= 32; ++b) {
      const auto& cb = ca_code(b);
      for (int shift = 0; shift < 1023; ++shift) {
        int sum = 0;
        for (int i = 0; i < 1023; ++i) sum += ca[i] * cb[(i + shift) % 1023];
        if (a == b && shift == 0) {
          ASSERT_EQ(sum, 1023) << "PRN " << a;
        } else {
          ASSERT_TRUE(allowed.count(sum)) << "PRN " << a << " x " << b << " shift " << shift << ": " << sum;
        }
      }
    }
  }
}

TEST(CaCode, RejectsPrnOutOfRange) {
  EXPECT_THROW(ca_code(0), std::out_of_range);
  EXPECT_THROW(ca_code(33), std::out_of_range);
}
