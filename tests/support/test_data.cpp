// SPDX-License-Identifier: GPL-3.0-or-later
#include "support/test_data.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace ultratrack::test {

std::optional<std::filesystem::path> shared_data_dir() {
  if (const char* env = std::getenv("ULTRATRACK_SHARED_DATA"); env && *env) {
    if (std::filesystem::is_directory(env)) return std::filesystem::path(env);
    return std::nullopt;
  }
  std::filesystem::path dir(ULTRATRACK_SHARED_DATA_DEFAULT);
  if (std::filesystem::is_directory(dir)) return dir;
  return std::nullopt;
}

std::filesystem::path scenarios_dir() {
  if (const char* env = std::getenv("ULTRATRACK_SCENARIOS"); env && *env) return env;
  return ULTRATRACK_SCENARIOS_DIR;
}

std::filesystem::path shipped_nav_file() {
  return std::filesystem::path(ULTRATRACK_TEST_DATA_DIR) / "brdc3540_0000-0200.14n";
}

namespace {

// A number as hexadecimal digits (a folder name).
std::string to_hex(std::size_t v) {
  std::ostringstream out;
  out << std::hex << v;
  return out.str();
}

// Folders made for a whole test suite (SetUpTestSuite) are private to this process: ctest runs each test in its
// own process, in parallel, and two processes of one suite must not share (and delete) each other's files.
// They are removed when the process ends.
std::vector<std::filesystem::path>& suite_dirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}

void remove_suite_dirs() {
  std::error_code ignored;
  for (const auto& dir : suite_dirs()) std::filesystem::remove_all(dir, ignored);
}

// A test's folder is removed when the test passed and kept, for inspection, when it failed (or with
// ULTRATRACK_KEEP_TEST_DIRS set): a whole run otherwise leaves gigabytes of samples in the temp folder. Removal waits
// for the end of the program: a test may leave data that later tests of the same process read (a simulation made
// once per process in the first test's folder), and ctest runs one test per process anyway.
class RemovePassedTestFolders : public ::testing::EmptyTestEventListener {
 public:
  void watch(std::filesystem::path dir) { dirs_.push_back(std::move(dir)); }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    const bool keep = !info.result()->Passed() || std::getenv("ULTRATRACK_KEEP_TEST_DIRS") != nullptr;
    if (!keep) passed_.insert(passed_.end(), dirs_.begin(), dirs_.end());
    dirs_.clear();
  }
  void OnTestProgramEnd(const ::testing::UnitTest&) override {
    std::error_code ignored;
    for (const auto& dir : passed_) std::filesystem::remove_all(dir, ignored);
    passed_.clear();
  }

 private:
  std::vector<std::filesystem::path> dirs_, passed_;
};

// Registered with GoogleTest on first use; GoogleTest owns (and deletes) it.
RemovePassedTestFolders& test_folder_janitor() {
  static RemovePassedTestFolders* janitor = [] {
    auto* listener = new RemovePassedTestFolders;
    ::testing::UnitTest::GetInstance()->listeners().Append(listener);
    return listener;
  }();
  return *janitor;
}

}  // namespace

std::filesystem::path scratch_dir() {
  auto* unit = ::testing::UnitTest::GetInstance();
  const auto* info = unit->current_test_info();
  // One root per checkout: two checkouts' suites running at once on one machine (CI beside a developer, two
  // worktrees) must not share a test's folder; runs of one checkout still reuse (and first clear) theirs.
  const std::string checkout = ULTRATRACK_SCENARIOS_DIR;
  const auto root =
      std::filesystem::temp_directory_path() / "ultratrack_tests" / to_hex(std::hash<std::string>{}(checkout));
  std::filesystem::path dir;
  if (info) {
    dir = root / (std::string(info->test_suite_name()) + "." + info->name());
    test_folder_janitor().watch(dir);
  } else {
    const auto* suite = unit->current_test_suite();
    dir = root / ((suite ? std::string(suite->name()) : std::string("suite")) + ".pid" + std::to_string(::getpid()));
    if (suite_dirs().empty()) std::atexit(remove_suite_dirs);
    suite_dirs().push_back(dir);
  }
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_text_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream s(line);
  std::string f;
  while (std::getline(s, f, ',')) fields.push_back(f);
  return fields;
}

std::size_t csv_column(const std::vector<std::string>& header, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) throw std::runtime_error("CSV column " + name + " not in the header");
  return static_cast<std::size_t>(it - header.begin());
}

}  // namespace ultratrack::test
