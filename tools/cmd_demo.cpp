#include <CLI/CLI.hpp>

#include <stdexcept>

#include "commands.hpp"

namespace ultratrack::tools {

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run the built-in default scenario end to end and print a summary");
  cmd->callback([] { throw std::runtime_error("demo: the synthesiser is being built (issue 2)"); });
}

}  // namespace ultratrack::tools
