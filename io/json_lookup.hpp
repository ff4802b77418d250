// SPDX-License-Identifier: GPL-3.0-or-later
// One scalar of a JSON document, found by its dotted path: what a campaign reads from a command's summary.json.
// Paths are keys joined by dots, a number indexing an array from 0 ("odometer.horizontal_error_max_m",
// "outages.0.horizontal_error_m"). The document is checked as
// JSON on the way (objects, arrays, strings, numbers, true/false/null). The value comes back as written (a number's
// text, a string's content unescaped only for \" and \\, true/false/null as words), so that nothing is lost to a
// conversion.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace ultratrack::io {

// The scalar at `path` (keys separated by '.'); nothing when a key is absent or the value there is an object or an
// array. Throws std::invalid_argument for text that is not JSON (the message says where).
std::optional<std::string> json_scalar_at(std::string_view json, std::string_view path);

}  // namespace ultratrack::io
