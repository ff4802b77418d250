// SPDX-License-Identifier: GPL-3.0-or-later
// io/json_text: escaping as RFC 8259 section 7 requires (quote, backslash, U+0000-U+001F), the rest untouched.
#include "io/json_text.hpp"

#include <gtest/gtest.h>

#include <string>

TEST(JsonText, EscapesQuoteBackslashAndControlCharactersOnly) {
  using ultratrack::io::json_escape;
  EXPECT_EQ(json_escape("plain /path/file.bin"), "plain /path/file.bin");
  EXPECT_EQ(json_escape("a\"b\\c"), "a\\\"b\\\\c");
  EXPECT_EQ(json_escape(std::string("x\ny\t\x01", 5)), "x\\u000ay\\u0009\\u0001");
  EXPECT_EQ(json_escape(std::string(1, '\0')), "\\u0000");
  EXPECT_EQ(json_escape("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 passes through
  EXPECT_EQ(ultratrack::io::json_string("a\"b"), "\"a\\\"b\"");
}
