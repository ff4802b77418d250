// `ultratrack acquire` through CLI11 as main() runs it: bad input is an InputError (exit 2 in main), and a
// real recording gives a JSON row for each satellite the data README lists.
#include <gtest/gtest.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "signals/input_error.hpp"
#include "support/test_data.hpp"

namespace {

void run(std::vector<std::string> args) {
  CLI::App app;
  ultratrack::tools::add_acquire_command(app);
  args.insert(args.begin(), "acquire");
  std::reverse(args.begin(), args.end());  // CLI11 takes the vector in reverse order
  app.parse(args);
}

}  // namespace

TEST(AcquireCommand, BadInputIsInputError) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string file = (dir / "noise.i8").string();
  { std::ofstream(file, std::ios::binary) << std::string(8000 * 2, '\1'); }
  using ultratrack::signals::InputError;
  EXPECT_THROW(run({"--input", file, "--format", "i9", "--fs", "4e6"}), InputError);
  EXPECT_THROW(run({"--input", file, "--format", "i8", "--fs", "4MHz"}), InputError);
  EXPECT_THROW(run({"--input", file, "--format", "i8", "--fs", "4e6", "--prn", "0-40"}), InputError);
  EXPECT_THROW(run({"--input", file, "--format", "i8", "--fs", "4e6", "--ms", "20"}), InputError);
  EXPECT_THROW(run({"--input", file, "--format", "r8", "--fs", "4e6"}), InputError);  // real needs --if
  EXPECT_THROW(run({"--input", (dir / "absent.i8").string(), "--format", "i8", "--fs", "4e6"}), InputError);
  EXPECT_THROW(run({"--input", file, "--format", "i8", "--fs", "4e6", "--ms", "5"}), InputError);  // < one block
}

TEST(AcquireCommand, JsonListsTheSatellitesOfARecording) {
  ULTRATRACK_REQUIRE_SHARED_FILE(path, "gnsssdr_cttc_4MHz_f32_4ms.dat");
  testing::internal::CaptureStdout();
  run({"--input", path.string(), "--format", "f32", "--fs", "4e6", "--doppler-max", "14000", "--prn", "2,12,25,29,31",
       "--json"});
  const std::string out = testing::internal::GetCapturedStdout();
  for (const char* prn : {"\"prn\": 2,", "\"prn\": 12,", "\"prn\": 25,", "\"prn\": 29,", "\"prn\": 31,"})
    EXPECT_NE(out.find(prn), std::string::npos) << prn << " missing in\n" << out;
  EXPECT_NE(out.find("\"noncoherent\": 4"), std::string::npos);  // the 4 ms file holds 4 blocks
}
