// SPDX-License-Identifier: GPL-3.0-or-later
// GPS L1 C/A (coarse/acquisition) Gold codes for PRN 1-32, IS-GPS-200 section 3.3.2.3 and Table 3-Ia:
// G1 = 1 + x^3 + x^10, G2 = 1 + x^2 + x^3 + x^6 + x^8 + x^9 + x^10, the PRN selecting two G2 phase taps.
// Chips are stored as +1/-1 with logic 0 -> +1 and logic 1 -> -1 (the modulation's sign convention),
// generated once and cached; the returned references stay valid for the program's lifetime.
#pragma once

#include <array>
#include <cstdint>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals {

using CaCodeChips = std::array<std::int8_t, kCaCodeLength_chips>;

// The 1023 chips of one PRN (1..32) as +1/-1. Throws std::out_of_range for other PRNs.
const CaCodeChips& ca_code(int prn);

// The same chips as logic bits 0/1 (chip 0 first), for comparison with the standard's octal tables.
std::array<std::uint8_t, kCaCodeLength_chips> ca_code_bits(int prn);

}  // namespace ultratrack::signals
