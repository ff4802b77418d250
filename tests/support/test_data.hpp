// SPDX-License-Identifier: GPL-3.0-or-later
// Test helpers: where the optional shared recordings and the shipped test data are, a scratch folder per test,
// and reading outputs back.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace ultratrack::test {

// The folder of shared real recordings (../shared/data), or nothing when it is absent.
std::optional<std::filesystem::path> shared_data_dir();
// The checkout's scenarios/ folder (ULTRATRACK_SCENARIOS in the environment overrides).
std::filesystem::path scenarios_dir();

// The broadcast ephemeris shipped with the tests (tests/data/brdc3540_0000-0200.14n; source and cut in
// tests/data/README.md): IGS broadcast orbits of 2014-12-20 with records at 00:00-02:00 GPST, valid from
// 2014-12-19 22:00 to 2014-12-20 04:00. Always present, so a test that only needs "an ephemeris" runs on a
// bare clone. Scenarios on it start at (shipped_nav_week, shipped_nav_tow_s), the toe of its first records.
std::filesystem::path shipped_nav_file();
inline constexpr int shipped_nav_week = 1823;          // full GPS week of 2014-12-20
inline constexpr double shipped_nav_tow_s = 518400.0;  // 2014-12-20 00:00:00 GPST
// A fresh empty folder under the system temp dir, unique to the calling test and removed at the end of the program
// when the test passed (kept when it failed, or with ULTRATRACK_KEEP_TEST_DIRS set); called outside a test (in
// SetUpTestSuite) unique to the suite and this process, and removed when the process exits.
std::filesystem::path scratch_dir();

// A whole text file as one string (empty when it cannot be read).
std::string read_text_file(const std::filesystem::path& file);
// The comma-separated fields of one CSV line, as written (no quoting).
std::vector<std::string> split_csv_line(const std::string& line);
// The index of column `name` in a CSV header; std::runtime_error naming it when absent.
std::size_t csv_column(const std::vector<std::string>& header, const std::string& name);

}  // namespace ultratrack::test

// Skips the current test with a clear message when the shared data folder (or one file in it) is absent.
#define ULTRATRACK_REQUIRE_SHARED_FILE(var, name)                                        \
  std::filesystem::path var;                                                             \
  {                                                                                      \
    auto dir_ = ::ultratrack::test::shared_data_dir();                                   \
    if (!dir_ || !std::filesystem::exists(*dir_ / (name)))                               \
      GTEST_SKIP() << "shared data file " << (name)                                      \
                   << " not found (../shared/data or $ULTRATRACK_SHARED_DATA): skipped"; \
    var = *dir_ / (name);                                                                \
  }
