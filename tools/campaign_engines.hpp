// SPDX-License-Identifier: GPL-3.0-or-later
// Where a campaign's runs execute (`ultratrack campaign run --engine local|slurm`): threads here, or a Slurm array. The
// output folder keeps a copy of the campaign file (campaign.toml) and the folder its relative paths resolve against
// (campaign_base.txt), so that `campaign run-one DIR INDEX` on any node and `campaign report DIR` read the same
// campaign. Runs already complete are never redone (resume).
//   local  the pending runs on this machine, `jobs` at a time (threads in this process);
//   slurm  slurm/campaign.sbatch, an array job whose task k runs pending runs k*R .. k*R+R-1 (slurm/pending.txt,
//          R = [slurm] runs_per_task) through `ultratrack campaign run-one`, submitted with `sbatch --parsable`;
//          then squeue is polled until the job has left the queue (unless no_wait).
#pragma once

#include <cstdio>
#include <filesystem>
#include <stop_token>
#include <string>
#include <vector>

#include "config/campaign_toml.hpp"

namespace ultratrack::tools {

// Copies the campaign file into out (created) and returns the campaign as read from there. An out that already
// holds a different campaign file is an InputError (its runs would mix).
config::CampaignFile prepare_campaign_dir(const std::filesystem::path& campaign_file, const std::filesystem::path& out);
// The campaign of a prepared folder.
config::CampaignFile load_campaign_dir(const std::filesystem::path& out);

// The runs not complete yet, in index order.
std::vector<int> pending_runs(const config::CampaignFile& campaign, const std::filesystem::path& out);

// Runs one run (building its job; a job that cannot be built is recorded as failed). True when complete.
// program: the ultratrack that the steps of a [[step]] campaign run (tools/campaign_steps.hpp).
bool run_campaign_index(const config::CampaignFile& campaign, const std::filesystem::path& out, int index,
                        const std::filesystem::path& program, std::stop_token stop = {});

// The local engine: returns the number of runs that failed. log: one line per finished run (nullptr: silent).
int run_campaign_local(const config::CampaignFile& campaign, const std::filesystem::path& out, int jobs,
                       const std::filesystem::path& program, std::FILE* log, std::stop_token stop = {});

// The sbatch script for `pending` runs; program: the ultratrack the tasks run (an absolute path).
std::string slurm_script(const config::CampaignFile& campaign, const std::filesystem::path& out, std::size_t pending,
                         const std::filesystem::path& program);

struct SlurmSubmission {
  std::string job_id;  // empty when nothing was pending
  std::size_t runs = 0, tasks = 0;
};

// Writes slurm/pending.txt and slurm/campaign.sbatch, submits with sbatch (PATH), and unless no_wait polls squeue
// every poll_s until the job is gone. Throws std::runtime_error when sbatch fails or says no job id.
SlurmSubmission run_campaign_slurm(const config::CampaignFile& campaign, const std::filesystem::path& out,
                                   const std::filesystem::path& program, bool no_wait, double poll_s, std::FILE* log);

}  // namespace ultratrack::tools
