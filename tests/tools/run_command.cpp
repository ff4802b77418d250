// SPDX-License-Identifier: GPL-3.0-or-later
#include "run_command.hpp"

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace ultratrack::test_support {

void run_program(const std::vector<std::string>& args) {
  CLI::App app{"ultratrack"};
  app.require_subcommand(1);
  ultratrack::tools::add_all_commands(app);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses a reversed vector
  app.parse(reversed);
}

void run_command(const std::string& command, std::vector<std::string> args, bool quiet) {
  args.insert(args.begin(), command);
  if (quiet) args.push_back("--quiet");
  run_program(args);
}

}  // namespace ultratrack::test_support
