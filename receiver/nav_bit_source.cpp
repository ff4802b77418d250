// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/nav_bit_source.hpp"

#include "io/input_error.hpp"

namespace ultratrack::receiver {

const char* to_string(NavBitSource source) { return source == NavBitSource::kOracle ? "oracle" : "decoded"; }

NavBitSource parse_nav_bit_source(const std::string& where, std::string_view text) {
  if (text == "decoded") return NavBitSource::kDecoded;
  if (text == "oracle") return NavBitSource::kOracle;
  throw io::InputError(where, "nav bits '" + std::string(text) + "': must be decoded or oracle");
}

}  // namespace ultratrack::receiver
