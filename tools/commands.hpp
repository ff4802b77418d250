// SPDX-License-Identifier: GPL-3.0-or-later
// The subcommands of `ultratrack`. Each add_*_command registers its options and its callback on the
// CLI11 app; the callback does the work and throws on bad input (main turns that into one message).
#pragma once

namespace CLI {
class App;
}

namespace ultratrack::tools {

void add_simulate_command(CLI::App& app);
void add_demo_command(CLI::App& app);
void add_acquire_command(CLI::App& app);
void add_receive_command(CLI::App& app);
void add_ins_command(CLI::App& app);
void add_imusim_command(CLI::App& app);
void add_fuse_command(CLI::App& app);
void add_covariance_command(CLI::App& app);
void add_gnsssim_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_attitude_command(CLI::App& app);
void add_snapshot_command(CLI::App& app);
void add_campaign_command(CLI::App& app);
void add_align_command(CLI::App& app);

// Every subcommand above, in the order `--help` lists them: the program and the tests build the same app.
void add_all_commands(CLI::App& app);

}  // namespace ultratrack::tools
