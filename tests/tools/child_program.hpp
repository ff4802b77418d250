// SPDX-License-Identifier: GPL-3.0-or-later
// Test helper: the real `ultratrack` program (ULTRATRACK_PROGRAM, the build's binary) run as a child process, its
// stdout and stderr in a log file, for tests that signal it, or change its inputs, while it runs.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include "support/test_data.hpp"

namespace ultratrack::test {

struct ChildProgram {
  pid_t pid = -1;
  std::filesystem::path log;  // stdout and stderr
};

// Starts `ultratrack ARGS...` with SIGINT and SIGTERM at their default action (as from a shell).
inline ChildProgram start_program(const std::vector<std::string>& args, const std::filesystem::path& log) {
  ChildProgram c{-1, log};
  std::vector<std::string> argv_s{ULTRATRACK_PROGRAM};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  c.pid = fork();
  if (c.pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return c;
}

// A folder of inputs that `make` fills once per build of the program and that every test process then shares (ctest
// runs each test in its own process): made under a temporary name and renamed, so that two processes making it at
// once both end with one whole folder. Older builds' folders of that name are removed. Call from SetUpTestSuite.
inline std::filesystem::path shared_inputs(const std::string& name,
                                           const std::function<void(const std::filesystem::path&)>& make) {
  namespace fs = std::filesystem;
  const fs::path root = scratch_dir().parent_path();
  const auto build = fs::last_write_time(ULTRATRACK_PROGRAM).time_since_epoch().count();
  const fs::path dir = root / (name + ".inputs." + std::to_string(build));
  if (fs::exists(dir)) return dir;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec))
    if (e.path().filename().string().rfind(name + ".inputs.", 0) == 0) fs::remove_all(e.path(), ec);
  const fs::path making = root / (name + ".making." + std::to_string(getpid()));
  fs::remove_all(making);
  fs::create_directories(making);
  make(making);
  fs::rename(making, dir, ec);
  if (ec) fs::remove_all(making);  // another process made it first
  return dir;
}

}  // namespace ultratrack::test
