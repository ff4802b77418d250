// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: RINEX 2/3 navigation files (signals/rinex_nav.hpp).
#include "fuzz_input.hpp"
#include "signals/rinex_nav.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  const auto file = fuzz::as_file(data, size, "nav.rnx");
  fuzz::expect_input_error_or_success([&] { signals::read_rinex_nav(file); });
  return 0;
}
