// SPDX-License-Identifier: GPL-3.0-or-later
// The one list of `ultratrack`'s subcommands (main.cpp and the command tests register them all from here).
#include "commands.hpp"

namespace ultratrack::tools {

void add_all_commands(CLI::App& app) {
  add_simulate_command(app);
  add_demo_command(app);
  add_acquire_command(app);
  add_receive_command(app);
  add_snapshot_command(app);
  add_ins_command(app);
  add_imusim_command(app);
  add_fuse_command(app);
  add_covariance_command(app);
  add_gnsssim_command(app);
  add_compare_command(app);
  add_attitude_command(app);
  add_align_command(app);
  add_campaign_command(app);
}

}  // namespace ultratrack::tools
