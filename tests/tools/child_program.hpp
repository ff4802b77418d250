// SPDX-License-Identifier: GPL-3.0-or-later
// Test helper: the real `ultratrack` program (ULTRATRACK_PROGRAM, the build's binary) run as a child process, its
// stdout and stderr in a log file, for tests that signal it, or change its inputs, while it runs.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

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

}  // namespace ultratrack::test
