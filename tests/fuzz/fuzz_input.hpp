// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the libFuzzer targets (tests/fuzz/fuzz_*.cpp): the fuzzer's bytes as a file that a reader opens by
// path (one scratch file per process and target), and the one outcome a reader may have on bad input besides
// success: io::InputError. Any other exception escapes, and libFuzzer reports it with its input as a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "io/input_error.hpp"

namespace ultratrack::fuzz {

// The bytes written to <temp>/ultratrack_fuzz_<pid>/<name> (rewritten on every call).
inline std::filesystem::path as_file(const std::uint8_t* data, std::size_t size, const std::string& name) {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("ultratrack_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Runs f; an io::InputError is the expected answer to bad input (its message must name something).
template <typename F>
void expect_input_error_or_success(F&& f) {
  try {
    f();
  } catch (const io::InputError& e) {
    if (std::string_view(e.what()).empty()) __builtin_trap();  // an error that says nothing is a finding too
  }
}

}  // namespace ultratrack::fuzz
