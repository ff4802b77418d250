#include <CLI/CLI.hpp>

#include <stdexcept>

#include "commands.hpp"

namespace ultratrack::tools {

void add_simulate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Synthesise IF samples, truth and navigation data from a scenario");
  cmd->callback([] { throw std::runtime_error("simulate: the synthesiser is being built (issue 2)"); });
}

}  // namespace ultratrack::tools
