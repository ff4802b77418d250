// SPDX-License-Identifier: GPL-3.0-or-later
// One run of a [[step]] campaign: ultratrack subcommands run in the run's folder, their JSON scalars its results.
// In order (config/campaign_toml.hpp): the run's parameters.csv, its [[file]] templates filled in and written there,
// then each step `ultratrack ARGS...` as a child process in the run folder (relative paths are the run's; stdout and
// stderr appended to steps.log), then the [compute] json scalars into complete.csv, after the [compute] remove paths
// are deleted (what a run need not keep). The campaign scripts that chain commands (imusim -> gnsssim -> fuse) become
// campaigns this way, and each step is exactly the command a user would type.
#pragma once

#include <filesystem>
#include <stop_token>

#include "config/campaign_toml.hpp"
#include "pipelines/campaign_run.hpp"

namespace ultratrack::tools {

// Runs `run` into run_dir (cleared first unless complete). A step that exits non-zero or cannot start: failed.txt
// names the step, its exit status and the last lines of steps.log (kFailed). A stop request sends the running step
// SIGTERM and leaves the run without a marker (missing, redone on resume). program: the ultratrack to run.
pipelines::CampaignRunStatus run_campaign_steps(const config::CampaignFile& campaign, const pipelines::CampaignRun& run,
                                                const std::filesystem::path& run_dir,
                                                const std::filesystem::path& program, std::stop_token stop = {});

}  // namespace ultratrack::tools
