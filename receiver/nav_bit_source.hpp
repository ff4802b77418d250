// SPDX-License-Identifier: GPL-3.0-or-later
// Which navigation bits data wipe-off may use (receive --nav-bits, ReceiverOptions::nav_bits).
// kDecoded (the default): what a real receiver can know, bits decoded from the signal itself (subframes 1-3 of
// the next frames while their issue of data stays, the TLM and HOW of every subframe), a nav file's subframe
// 1-3 words only once they agree with a decoded copy, subframe 4/5 page content never; a running check
// against the prompt's sign stops a contradicted source (receiver/nav_bit_check.hpp).
// kOracle: a supplied nav file re-encoded exactly as `ultratrack simulate` encodes it, every bit including the
// subframe 4/5 pages no nav file holds: right only for our own simulations; for simulation studies, never the
// default; contradictions are counted, never acted on.
#pragma once

#include <string>
#include <string_view>

namespace ultratrack::receiver {

enum class NavBitSource { kDecoded, kOracle };

const char* to_string(NavBitSource source);
// "decoded" or "oracle"; io::InputError naming `where` (a file, "command line") otherwise.
NavBitSource parse_nav_bit_source(const std::string& where, std::string_view text);

}  // namespace ultratrack::receiver
