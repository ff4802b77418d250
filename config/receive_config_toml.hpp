// SPDX-License-Identifier: GPL-3.0-or-later
// The `receive` command's TOML configuration (--config): sections [receiver], [acquisition], [tracking] and
// [pvt] set ReceiverOptions fields by their names (angles in degrees with _deg, booleans for on/off switches).
// Unknown sections or keys and wrong value types are InputErrors naming the file and the key.
#pragma once

#include <filesystem>

#include "receiver/receiver_options.hpp"

namespace ultratrack::config {

// Applies the file's settings over `options` (fields not in the file keep their values).
void apply_receive_config(const std::filesystem::path& path, receiver::ReceiverOptions& options);

}  // namespace ultratrack::config
