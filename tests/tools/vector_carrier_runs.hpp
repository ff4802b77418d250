// Set-up shared by the vector FLL and PLL end-to-end tests (receive_vector_fll_test.cpp,
// receive_vector_pll_test.cpp): their scenarios (tests/support/vector_carrier_scenarios.hpp), one
// `receive --coupling vector --vector-carrier` run, and the lock losses summary.json reports.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "run_command.hpp"
#include "support/test_data.hpp"
#include "support/vector_carrier_scenarios.hpp"

namespace ultratrack::test {

// receive of sim/antenna0.i8.bin with --coupling vector --vector-carrier carrier into out (hot: --nav).
inline void receive_vector_carrier(const std::filesystem::path& sim, const std::filesystem::path& brdc,
                                   const std::filesystem::path& out, const char* carrier) {
  test_support::run_command("receive", {"--input", (sim / "antenna0.i8.bin").string(), "--format", "i8", "--fs",
                                        "2.0e6", "--nav", brdc.string(), "--troposphere", "off", "--coupling", "vector",
                                        "--vector-carrier", carrier, "--out", out.string()});
}

// The sum of summary.json's per-satellite "losses"; satellites (if given): how many satellites it lists.
inline int total_losses(const std::filesystem::path& out, int* satellites = nullptr) {
  const std::string summary = read_text_file(out / "summary.json");
  int total = 0, count = 0;
  for (auto at = summary.find("\"losses\": "); at != std::string::npos; at = summary.find("\"losses\": ", at + 1)) {
    total += std::stoi(summary.substr(at + 10));
    ++count;
  }
  if (satellites) *satellites = count;
  return total;
}

}  // namespace ultratrack::test
