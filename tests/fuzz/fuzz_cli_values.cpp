// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: command-line values parsed as text (tools/cli_parse.hpp: numbers, integers, PRN lists, on/off
// switches). The first byte picks the parser; the rest is the value.
#include <string>

#include "cli_parse.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  if (size < 1) return 0;
  const std::string value(fuzz::as_text(data + 1, size - 1));
  fuzz::expect_input_error_or_success([&] {
    switch (data[0] % 4) {
      case 0:
        tools::parse_double_option("--x", value);
        break;
      case 1:
        tools::parse_int_option("--n", value);
        break;
      case 2: {
        const auto prns = tools::parse_prn_list_option("--prn", value);
        for (int prn : prns)
          if (prn < 1 || prn > 32) __builtin_trap();  // a list that parses holds only valid PRNs
        break;
      }
      default:
        tools::parse_on_off_option("--switch", value, "on", "off");
    }
  });
  return 0;
}
