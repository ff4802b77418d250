// SPDX-License-Identifier: GPL-3.0-or-later
// Changes to a TOML document before it is read: `simulate --set signal.cn0_dbhz=35` and a campaign's
// [simulate] set = { "signal.cn0_dbhz" = "{cn0_dbhz}" } run one scenario file at other values without copying it.
//
// A change is a dotted key (tables, then the key: "signal.cn0_dbhz", "receiver.llh_deg_m") and a value written as
// TOML ("35.0", "[35.0, 137.0, 100.0]", "\"tcxo\""); text that is not a TOML value is taken as a string
// (signal.format=i8). A missing table is created; the key's old value, of any type, is replaced. The reader of the
// document then checks the result as it checks a file (unknown keys, types, ranges), so a misspelt key fails there.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <vector>

namespace ultratrack::config {

struct TomlOverride {
  std::string key;    // dotted: section.key (at least one dot)
  std::string value;  // TOML value text, or a bare string
};

// "KEY=VALUE" (the first '=' splits; spaces around either side are dropped). std::invalid_argument naming the
// text when there is no '=', the key is not dotted, or a part of it is empty.
TomlOverride parse_toml_override(const std::string& text);

// Applies the changes in order. std::invalid_argument naming the key when a part of its path is a value, not a
// table (e.g. "signal.cn0_dbhz.x"), or lies inside an array of tables.
void apply_toml_overrides(toml::table& root, const std::vector<TomlOverride>& overrides);

}  // namespace ultratrack::config
