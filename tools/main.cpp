// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack`: one program, one subcommand per job (docs/cli.md lists every flag).
// Errors from the edges arrive here as exceptions and leave as one line on stderr and a non-zero exit.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <exception>

#include "command_exit.hpp"
#include "commands.hpp"
#include "ins/ins_error.hpp"
#include "interrupt_guard.hpp"
#include "io/input_error.hpp"

namespace {

// A command a signal stopped has finished its outputs up to the stop; its exit status says it was stopped.
int stopped_or(int code) {
  const int sig = ultratrack::tools::interrupt_signal();
  if (sig == 0) return code;
  fmt::print(stderr, "ultratrack: stopped by {}; the outputs cover the run up to the stop\n",
             sig == SIGINT ? "SIGINT" : "SIGTERM");
  return 128 + sig;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ultratrack: GPS L1 C/A software receiver with inertial aiding"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "ultratrack 0.1.0");
  ultratrack::tools::add_all_commands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const ultratrack::tools::CommandExit& e) {
    fmt::print(stderr, "ultratrack: {}\n", e.what());
    return stopped_or(e.code);
  } catch (const ultratrack::io::InputError& e) {
    fmt::print(stderr, "ultratrack: error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "ultratrack: error: {}\n", e.what());
    return 1;
  }
  return stopped_or(0);
}
