// SPDX-License-Identifier: GPL-3.0-or-later
// A command that ran to its end but produced nothing useful (e.g. `receive` on a file with no fix) leaves with
// this exception: main prints the message and exits with `code` (3 for "no result"), after the command has
// written whatever outputs it could.
#pragma once

#include <stdexcept>
#include <string>

namespace ultratrack::tools {

struct CommandExit : std::runtime_error {
  CommandExit(int exit_code, const std::string& message) : std::runtime_error(message), code(exit_code) {}
  int code;
};

}  // namespace ultratrack::tools
