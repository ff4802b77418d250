// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: the other TOML files a user writes: fuse/receive-fusion configuration, receive configuration
// and the attitude receiver's antenna file (config/), and `ultratrack align`'s alignment.json as fuse and receive
// read it back (--align file:). The first byte picks the reader.
#include "config/antenna_config_toml.hpp"
#include "config/fuse_config_toml.hpp"
#include "config/receive_config_toml.hpp"
#include "fuzz_input.hpp"
#include "pipelines/alignment_run.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace ultratrack;
  if (size < 1) return 0;
  const auto file = fuzz::as_file(data + 1, size - 1, "config.toml");
  fuzz::expect_input_error_or_success([&] {
    switch (data[0] % 4) {
      case 0:
        config::read_fuse_config(file);
        break;
      case 1: {
        receiver::ReceiverOptions options;
        config::apply_receive_config(file, options);
        break;
      }
      case 3: {
        pipelines::FuseConfig config;
        pipelines::apply_alignment_file(config, file);
        break;
      }
      default:
        config::read_antenna_config(file);
    }
  });
  return 0;
}
