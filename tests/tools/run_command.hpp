// SPDX-License-Identifier: GPL-3.0-or-later
// Runs `ultratrack` subcommands in the test process, as the program would parse its command line (the same app
// as main.cpp: every subcommand registered). Exceptions (InputError, CommandExit, CLI::ParseError) propagate.
// CLI11 is included only by run_command.cpp: the header costs seconds of compile time in every file that sees it.
#pragma once

#include <string>
#include <vector>

namespace ultratrack::test_support {

// `ultratrack COMMAND ARGS... [--quiet]`; quiet keeps progress lines out of the test log.
void run_command(const std::string& command, std::vector<std::string> args, bool quiet = true);

// `ultratrack ARGS...`, the whole command line after the program's name, as given.
void run_program(const std::vector<std::string>& args);

}  // namespace ultratrack::test_support
