// SPDX-License-Identifier: GPL-3.0-or-later
// Runs one `ultratrack` subcommand in the test process, as the program would parse its command line
// (the same app as main.cpp: every subcommand registered). Exceptions (InputError, CommandExit) propagate.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "commands.hpp"

namespace ultratrack::test_support {

// `ultratrack COMMAND ARGS... [--quiet]`; quiet keeps progress lines out of the test log.
inline void run_command(const std::string& command, std::vector<std::string> args, bool quiet = true) {
  CLI::App app;
  ultratrack::tools::add_all_commands(app);
  args.insert(args.begin(), command);
  if (quiet) args.push_back("--quiet");
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses a reversed vector
  app.parse(reversed);
}

}  // namespace ultratrack::test_support
