// SPDX-License-Identifier: GPL-3.0-or-later
// Test helper: a call that must throw io::InputError naming a file, a line and a phrase of the problem.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/input_error.hpp"

namespace ultratrack::test {

// Runs f and expects an InputError whose file is `file`, whose line is `line` and whose message holds what_part.
template <typename F>
void expect_error_at(F&& f, const std::filesystem::path& file, int line, const std::string& what_part) {
  try {
    f();
    ADD_FAILURE() << "no error for " << file << " line " << line;
  } catch (const io::InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(std::string(e.what()).find(what_part), std::string::npos) << e.what();
  }
}

}  // namespace ultratrack::test
