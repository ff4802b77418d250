// SPDX-License-Identifier: GPL-3.0-or-later
// Text for the JSON files we write by hand (summary.json): a string's content escaped as JSON requires
// (quote, backslash and control characters; everything else, UTF-8 included, passes through).
#pragma once

#include <string>
#include <string_view>

namespace ultratrack::io {

// The escaped content, without the surrounding quotes.
std::string json_escape(std::string_view text);
// The escaped content in quotes: a JSON string value.
std::string json_string(std::string_view text);

}  // namespace ultratrack::io
