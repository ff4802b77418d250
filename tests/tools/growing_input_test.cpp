// SPDX-License-Identifier: GPL-3.0-or-later
// Inputs that change while they are read (issue 21), with the behaviour docs/usage.md "Exit status" states:
// a recording is taken at its size when `receive` opens it (samples appended later are not read, a partial sample
// appended does not matter) and one that shrinks under the reader is one error naming the file (exit 2); a CSV
// input (imu.csv of `fuse`, every time-series CSV) is read as it is when opened, a last line still being written
// left out, never misparsed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_program.hpp"
#include "ins/imu_csv.hpp"
#include "io/input_error.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

std::string read_text(const fs::path& f) { return ultratrack::test::read_text_file(f); }

// IMU row k: t = k / 100 s, dtheta_x = k * 1e-7 rad (so that every value read can be checked against its row).
std::string imu_row(long k) {
  char b[200];
  std::snprintf(b, sizeof b, "%.2f,%.7e,0,0,0,0,-0.0981\n", 0.01 * static_cast<double>(k),
                1e-7 * static_cast<double>(k));
  return b;
}

// A logger appends rows, each in two writes cut inside a number, while the reader reads the file again and again:
// every read succeeds with whole rows 0..n-1 exactly as written (n grows), never a half-written last row.
TEST(GrowingInput, ImuCsvAppendedWhileReadGivesTheWholeRowsOnly) {
  const fs::path file = ultratrack::test::scratch_dir() / "growing_imu.csv";
  {
    std::ofstream out(file);
    out << "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n";
    for (long k = 0; k < 200; ++k) out << imu_row(k);
  }
  std::atomic<bool> done{false};
  std::thread logger([&] {
    std::FILE* f = std::fopen(file.c_str(), "a");
    for (long k = 200; !done; ++k) {
      const std::string row = imu_row(k);
      const std::size_t cut = row.size() / 3;  // inside the dtheta_x number
      std::fwrite(row.data(), 1, cut, f);
      std::fflush(f);
      std::this_thread::sleep_for(50us);
      std::fwrite(row.data() + cut, 1, row.size() - cut, f);
      std::fflush(f);
    }
    std::fclose(f);
  });
  std::size_t last_n = 0;
  int reads = 0, errors = 0;
  std::string first_error;
  const auto end = std::chrono::steady_clock::now() + 1500ms;
  while (std::chrono::steady_clock::now() < end) {
    try {
      const auto imu = ultratrack::ins::read_imu_csv(file);
      ++reads;
      EXPECT_GE(imu.size(), last_n);
      last_n = imu.size();
      for (std::size_t k = 0; k < imu.size(); ++k) {
        if (std::abs(imu[k].t_s - 0.01 * static_cast<double>(k)) > 1e-9 ||
            std::abs(imu[k].dtheta_b.x() - 1e-7 * static_cast<double>(k)) > 1e-15 || imu[k].dv_b.z() != -0.0981) {
          ADD_FAILURE() << "row " << k << " misread: t " << imu[k].t_s << " dtheta_x " << imu[k].dtheta_b.x()
                        << " dv_z " << imu[k].dv_b.z();
          break;
        }
      }
    } catch (const ultratrack::io::InputError& e) {
      if (errors++ == 0) first_error = e.what();
    }
  }
  done = true;
  logger.join();
  EXPECT_EQ(errors, 0) << "first: " << first_error;
  EXPECT_GT(reads, 5);
  EXPECT_GT(last_n, 200u);  // rows appended before a read are read
}

using Child = ultratrack::test::ChildProgram;
using ultratrack::test::start_program;

// Waits for the first progress line of `receive` (the file is open and sized by then); false if it ended first.
bool wait_for_progress(const Child& c) {
  const auto end = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < end) {
    if (read_text(c.log).find("tracking") != std::string::npos) return true;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) == c.pid) {
      ADD_FAILURE() << "receive ended before its first progress line:\n" << read_text(c.log);
      return false;
    }
    std::this_thread::sleep_for(2ms);
  }
  ADD_FAILURE() << "no progress line:\n" << read_text(c.log);
  return false;
}

class GrowingRecording : public ::testing::Test {
 protected:
  static void SetUpTestSuite();
};

int wait_end(const Child& c) {
  int status = 0;
  waitpid(c.pid, &status, 0);
  return status;
}

// 8 s of the nominal constellation at 2.6 MHz, i8 (41.6 MB).
// Copied as dir/name. Made once per build of the program, shared by the test processes.
fs::path recording(const fs::path& dir, const std::string& name) {
  static const fs::path made =
      ultratrack::test::shared_inputs(
          "growing_input",
          [](const fs::path& d) {
            std::ofstream(d / "s.toml")
                << "[signal]\nsample_rate_hz = 2.6e6\nduration_s = 8.0\n[time]\ngps_week = 2190\n"
                   "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n";
            const std::string cmd = std::string(ULTRATRACK_PROGRAM) + " simulate --quiet --scenario " +
                                    (d / "s.toml").string() + " --out " + (d / "o").string() + " > /dev/null 2>&1";
            EXPECT_EQ(std::system(cmd.c_str()), 0);
          }) /
      "o" / "antenna0.i8.bin";
  if (name.empty()) return made;
  fs::create_directories(dir);
  fs::copy_file(made, dir / name, fs::copy_options::overwrite_existing);
  return dir / name;
}

void GrowingRecording::SetUpTestSuite() { recording(fs::path(), ""); }

double summary_duration(const fs::path& summary) {
  std::smatch m;
  const std::string t = read_text(summary);
  if (!std::regex_search(t, m, std::regex("\"duration_s\": ([0-9.]+)"))) return -1.0;
  return std::stod(m[1]);
}

TEST_F(GrowingRecording, AppendedWhileReceivedIsTakenAtItsSizeWhenOpened) {
  const fs::path dir = ultratrack::test::scratch_dir() / "growing_rx";
  const fs::path input = recording(dir, "grow.i8.bin");
  const Child c = start_program({"receive", "--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--threads",
                                 "1", "--out", (dir / "rx").string()},
                                dir / "log");
  if (!wait_for_progress(c)) return;
  {
    std::ofstream out(input, std::ios::app | std::ios::binary);
    const std::vector<char> more(2 * 2'600'000 + 1, 1);  // 1 s of samples and half a sample
    out.write(more.data(), static_cast<std::streamsize>(more.size()));
  }
  const int status = wait_end(c);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_TRUE(WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 3) << read_text(c.log);  // fix or none, no error
  EXPECT_NEAR(summary_duration(dir / "rx" / "summary.json"), 8.0, 1e-3) << read_text(c.log);
}

TEST_F(GrowingRecording, ThatShrinksWhileReceivedIsOneErrorNamingIt) {
  const fs::path dir = ultratrack::test::scratch_dir() / "shrinking_rx";
  const fs::path input = recording(dir, "shrink.i8.bin");
  const Child c = start_program({"receive", "--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--threads",
                                 "1", "--out", (dir / "rx").string()},
                                dir / "log");
  if (!wait_for_progress(c)) return;
  fs::resize_file(input, 4096);
  const int status = wait_end(c);
  const std::string log = read_text(c.log);
  ASSERT_TRUE(WIFEXITED(status)) << log;
  EXPECT_EQ(WEXITSTATUS(status), 2) << log;
  EXPECT_NE(log.find(input.string()), std::string::npos) << log;
  EXPECT_NE(log.find("changed while being read"), std::string::npos) << log;
  for (const auto& f : fs::recursive_directory_iterator(dir / "rx"))
    EXPECT_EQ(f.path().filename().string().find(".part"), std::string::npos) << f.path();
}

}  // namespace
