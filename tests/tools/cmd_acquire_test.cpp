// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack acquire` through CLI11 as main() runs it: bad input is an InputError (exit 2 in main); a real
// recording gives a JSON row for each satellite the data README lists; synthetic files written with
// signals::SampleWriter (2.6 MHz complex i16, 6.5 MHz real r16 at an IF) give their satellites' truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "commands.hpp"
#include "receiver/synthetic_ca_signal.hpp"
#include "run_command.hpp"
#include "signals/input_error.hpp"
#include "signals/sample_writer.hpp"
#include "support/test_data.hpp"

using ultratrack::signals::SampleFormat;

namespace {

void run(std::vector<std::string> args) {
  ultratrack::test_support::run_command("acquire", std::move(args), /*quiet=*/false);
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

namespace {

struct Written {
  std::string path;
  std::vector<ultratrack::test::CaSignal> satellites;
};

// Synthetic recordings written with signals::SampleWriter: complex i16 baseband, or real r16 at an IF
// (real part of the signal moved to the IF, real noise of the same per-sample power).
Written write_recording(const std::filesystem::path& path, SampleFormat format, double fs_hz, double if_hz,
                        double seconds) {
  Written w{path.string(),
            {{.prn = 7, .code_phase_chips = 123.4, .doppler_hz = -3333.0, .cn0_dbhz = 46.0},
             {.prn = 13, .code_phase_chips = 999.9, .doppler_hz = 1500.0, .cn0_dbhz = 44.0},
             {.prn = 30, .code_phase_chips = 0.6, .doppler_hz = 4321.0, .cn0_dbhz = 42.0}}};
  const auto n = static_cast<std::size_t>(fs_hz * seconds);
  auto x = ultratrack::test::complex_noise(n, 21);
  for (const auto& s : w.satellites) ultratrack::test::add_ca_signal(x, fs_hz, s);
  if (!ultratrack::signals::is_complex(format)) {
    // Real IF: sqrt(2) Re(x e^{j 2 pi IF t}) keeps C/N0 (the receiver's mixing halves the signal and the
    // noise alike); the noise's real part has the same power per sample.
    for (std::size_t i = 0; i < n; ++i) {
      const double phase = 2.0 * std::numbers::pi * if_hz * static_cast<double>(i) / fs_hz;
      const std::complex<double> y = std::complex<double>(x[i]) * std::polar(std::sqrt(2.0), phase);
      x[i] = {static_cast<float>(y.real()), 0.0f};
    }
  }
  for (auto& v : x) v *= 1000.0f;  // int16 scale
  ultratrack::signals::SampleWriter writer(path, format);
  writer.write(x);
  writer.finish();
  return w;
}

void expect_rows(const std::string& out, const Written& w) {
  // Exactly the written satellites: a false alarm among the 29 others has probability 29 x pfa = 3 %.
  std::size_t rows = 0;
  for (auto at = out.find("\"prn\":"); at != std::string::npos; at = out.find("\"prn\":", at + 1)) ++rows;
  EXPECT_EQ(rows, w.satellites.size()) << out;
  for (const auto& s : w.satellites) {
    const std::string key = "\"prn\": " + std::to_string(s.prn) + ",";
    const auto at = out.find(key);
    ASSERT_NE(at, std::string::npos) << key << " missing in\n" << out;
    double doppler = 0.0, phase = 0.0;
    ASSERT_EQ(std::sscanf(out.c_str() + out.find("\"doppler_hz\":", at), "\"doppler_hz\": %lf", &doppler), 1);
    ASSERT_EQ(std::sscanf(out.c_str() + out.find("\"code_phase_chips\":", at), "\"code_phase_chips\": %lf", &phase), 1);
    EXPECT_NEAR(doppler, s.doppler_hz, 150.0) << "PRN " << s.prn;
    EXPECT_NEAR(std::remainder(phase - s.code_phase_chips, 1023.0), 0.0, 0.1) << "PRN " << s.prn;
  }
}

}  // namespace

TEST(AcquireCommand, FindsSatellitesInA2p6MHzComplexI16File) {
  const auto w = write_recording(ultratrack::test::scratch_dir() / "sky.i16", SampleFormat::i16, 2.6e6, 0.0, 0.012);
  testing::internal::CaptureStdout();
  run({"--input", w.path, "--format", "i16", "--fs", "2.6e6", "--json"});
  expect_rows(testing::internal::GetCapturedStdout(), w);
}

TEST(AcquireCommand, FindsSatellitesInARealR16FileAtAnIf) {
  const auto w = write_recording(ultratrack::test::scratch_dir() / "sky.r16", SampleFormat::r16, 6.5e6, 1.61e6, 0.012);
  testing::internal::CaptureStdout();
  run({"--input", w.path, "--format", "r16", "--fs", "6.5e6", "--if", "1.61e6", "--json"});
  expect_rows(testing::internal::GetCapturedStdout(), w);
}
