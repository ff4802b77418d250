#include "support/test_data.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

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

std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "ultratrack";
  auto dir = std::filesystem::temp_directory_path() / "ultratrack_tests" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace ultratrack::test
