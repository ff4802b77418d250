// SPDX-License-Identifier: GPL-3.0-or-later
// Set-up shared by the vector FLL and PLL end-to-end tests (receive_vector_fll_test.cpp,
// receive_vector_pll_test.cpp): their scenarios (tests/support/vector_carrier_scenarios.hpp), one vector-coupled
// receive per carrier mode through the library, and the lock losses summary.json reports.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "support/simulated_receive.hpp"
#include "support/test_data.hpp"
#include "support/vector_carrier_scenarios.hpp"

namespace ultratrack::test {

// The receive of sim/antenna0.i8.bin with vector coupling and the named carrier mode ("aided-pll", "fll", "pll")
// into out, hot (the nav file), troposphere off, through the library.
inline void receive_vector_carrier(const std::filesystem::path& sim, const std::filesystem::path& brdc,
                                   const std::filesystem::path& out, const std::string& carrier) {
  const fusion::VectorCarrier mode = carrier == "fll"   ? fusion::VectorCarrier::kFll
                                     : carrier == "pll" ? fusion::VectorCarrier::kPll
                                                        : fusion::VectorCarrier::kAidedPll;
  receive_simulated({.input = sim / "antenna0.i8.bin",
                     .nav = brdc,
                     .out = out,
                     .coupling = pipelines::Coupling::kVector,
                     .troposphere = false,
                     .vector_carrier = mode});
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
