// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack receive --vector-carrier`: an unknown carrier mode, and a carrier mode without --coupling vector, are
// bad input on the command line. The vector loops themselves: tests/pipelines/receive_vector*_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/input_error.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

TEST(ReceiveVectorCli, RejectsUnknownCarrierModesAndOneWithoutVectorCoupling) {
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "x.bin", std::ios::binary) << std::string(400000, '\0');
  const auto receive = [&](const std::vector<std::string>& extra, const std::string& out) {
    std::vector<std::string> args = {"--input", (dir / "x.bin").string(), "--format", "i8", "--fs", "2.0e6",
                                     "--out",   (dir / out).string()};
    args.insert(args.end(), extra.begin(), extra.end());
    ultratrack::test_support::run_command("receive", args);
  };
  for (const char* bad : {"vpll", "PLL", "pll2"})
    EXPECT_THROW(receive({"--coupling", "vector", "--vector-carrier", bad}, "rx"), ultratrack::io::InputError) << bad;
  EXPECT_THROW(receive({"--vector-carrier", "fll"}, "ry"), ultratrack::io::InputError);
  EXPECT_THROW(receive({"--vector-carrier", "pll"}, "rz"), ultratrack::io::InputError);
  EXPECT_THROW(receive({"--coupling", "ultra"}, "rw"), ultratrack::io::InputError);
}
