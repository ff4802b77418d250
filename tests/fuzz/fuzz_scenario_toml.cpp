// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: scenario files (config/scenario_toml.hpp), parsed from text, and the scenario written back
// and read again when it parses (to_toml must round-trip whatever the reader accepts).
#include "config/scenario_toml.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  fuzz::expect_input_error_or_success([&] {
    const sim::Scenario s = config::parse_scenario(fuzz::as_text(data, size), "/fuzz/scenario.toml");
    const std::string echo = config::to_toml(s);
    if (config::to_toml(config::parse_scenario(echo, "/fuzz/scenario.toml")) != echo) __builtin_trap();
  });
  return 0;
}
