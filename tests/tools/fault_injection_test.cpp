// SPDX-License-Identifier: GPL-3.0-or-later
// Faults around `ultratrack receive`: an input that is a directory, an input without read permission, an output
// folder that cannot be made (its parent is a file, or a folder without write permission), an output folder whose
// files cannot be created, and a disk that fills mid-run (a file-size limit, RLIMIT_FSIZE, with SIGXFSZ ignored so
// that the write fails as on a full disk). Each gives one error naming the path and the problem (the system's
// reason where there is one); the file being written is removed, never left half-written under its final name or
// as a .partial. The permission cases run in a child process without the capabilities that let root ignore
// permission bits (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH), so they bind there as they bind any user.
#include <gtest/gtest.h>
#include <linux/capability.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/input_error.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

void run(const std::string& command, std::vector<std::string> args) {
  ultratrack::test_support::run_command(command, std::move(args));
}

// 2 s at 2.6 MHz of the nominal constellation (10 MB): tracking.csv of a receive is ~55 kB.
fs::path simulate(const fs::path& dir) {
  std::ofstream(dir / "s.toml") << "[signal]\nsample_rate_hz = 2.6e6\nduration_s = 2.0\n[time]\ngps_week = 2190\n"
                                   "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n";
  run("simulate", {"--scenario", (dir / "s.toml").string(), "--out", (dir / "sim").string()});
  return dir / "sim" / "antenna0.i8.bin";
}

// 0.1 s of zeros at 2.6 MHz i8: a valid recording (with nothing in it) for faults met before the first sample.
fs::path zeros_recording(const fs::path& dir) {
  const fs::path file = dir / "zeros.i8.bin";
  std::ofstream(file, std::ios::binary) << std::string(520000, '\0');
  return file;
}

std::string error_of(const std::vector<std::string>& args) {
  try {
    run("receive", args);
  } catch (const ultratrack::io::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// Drops CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH from this process's effective set (a no-op for a user without
// them). True on success.
bool drop_permission_override() {
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2]{};
  if (syscall(SYS_capget, &header, data) != 0) return false;
  data[0].effective &= ~((1u << CAP_DAC_OVERRIDE) | (1u << CAP_DAC_READ_SEARCH));
  return syscall(SYS_capset, &header, data) == 0;
}

// error_of(args) in a forked child that has dropped the permission override; its message comes back by a pipe.
std::string error_without_permission_override(const std::vector<std::string>& args) {
  int fds[2];
  if (pipe(fds) != 0) return "(pipe failed)";
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    const std::string message = drop_permission_override() ? error_of(args) : "(capset failed)";
    const ssize_t written = write(fds[1], message.data(), message.size());
    _exit(written == static_cast<ssize_t>(message.size()) ? 0 : 1);
  }
  close(fds[1]);
  std::string message;
  char buffer[512];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) message.append(buffer, static_cast<std::size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? message : "(child failed) " + message;
}

TEST(FaultInjection, InputThatIsADirectoryIsNamed) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string e =
      error_of({"--input", dir.string(), "--format", "i8", "--fs", "2.6e6", "--out", (dir / "rx").string()});
  EXPECT_NE(e.find(dir.string()), std::string::npos) << e;
  EXPECT_NE(e.find("not a regular file"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir / "rx"));
}

TEST(FaultInjection, OutputFolderUnderAFileIsNamed) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = zeros_recording(dir);
  const fs::path out = input / "rx";  // a folder inside a regular file
  const std::string e = error_of({"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  EXPECT_NE(e.find(out.string()), std::string::npos) << e;
  EXPECT_NE(e.find("cannot create the output folder"), std::string::npos) << e;
}

TEST(FaultInjection, UnreadableInputIsNamedWithTheReason) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = zeros_recording(dir);
  fs::permissions(input, fs::perms::none);
  const std::string e = error_without_permission_override(
      {"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", (dir / "rx").string()});
  fs::permissions(input, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_NE(e.find(input.string() + ": cannot open the sample file for reading: Permission denied"), std::string::npos)
      << e;
  EXPECT_FALSE(fs::exists(dir / "rx"));
}

TEST(FaultInjection, OutputFolderInAFolderWithoutWritePermissionIsNamed) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = zeros_recording(dir);
  const fs::path locked = dir / "locked";
  fs::create_directory(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  const fs::path out = locked / "rx";
  const std::string e = error_without_permission_override(
      {"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  EXPECT_NE(e.find(out.string() + ": cannot create the output folder: Permission denied"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(out));
  fs::permissions(locked, fs::perms::owner_all);
}

TEST(FaultInjection, OutputFolderWithoutWritePermissionIsNamedAndLeavesNothing) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = zeros_recording(dir);
  const fs::path out = dir / "rx";
  fs::create_directory(out);
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string e = error_without_permission_override(
      {"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  fs::permissions(out, fs::perms::owner_all);
  EXPECT_NE(e.find(": cannot open for writing: Permission denied"), std::string::npos) << e;
  EXPECT_NE(e.find(out.string() + "/"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(FaultInjection, DiskFullMidRunLeavesNoHalfWrittenFile) {
  const auto dir = ultratrack::test::scratch_dir();
  const fs::path input = simulate(dir);
  const fs::path out = dir / "rx";
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  const auto previous_xfsz = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = before;
  limited.rlim_cur = 20 * 1024;  // tracking.csv outgrows it; the small outputs fit
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  const std::string e = error_of({"--input", input.string(), "--format", "i8", "--fs", "2.6e6", "--out", out.string()});
  setrlimit(RLIMIT_FSIZE, &before);
  std::signal(SIGXFSZ, previous_xfsz);
  EXPECT_NE(e.find((out / "tracking.csv").string()), std::string::npos) << e;
  EXPECT_NE(e.find("write failed"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(out / "tracking.csv"));
  for (const auto& f : fs::directory_iterator(out))
    EXPECT_NE(f.path().extension(), ".partial") << f.path();  // no temporary left behind
}

}  // namespace
