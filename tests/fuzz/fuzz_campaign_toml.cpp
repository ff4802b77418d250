// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: campaign files (config/campaign_toml.hpp), read as `ultratrack campaign run` reads them. The
// seeds list recordings (a [simulate] seed would stop at its missing scenario template).
#include "config/campaign_toml.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  const auto file = fuzz::as_file(data, size, "campaign.toml");
  fuzz::expect_input_error_or_success([&] { config::read_campaign(file); });
  return 0;
}
