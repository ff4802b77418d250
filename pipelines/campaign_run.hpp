// SPDX-License-Identifier: GPL-3.0-or-later
// One campaign run into its own folder, its completion marker written last. It simulates a scenario (or takes a
// recording), receives it in process (pipelines/receive_file.hpp) and computes what the campaign asks
// (pipelines/campaign_metrics.hpp). A run folder holds
//   parameters.csv    the run's parameters (name,value), written first
//   sim/              the simulation's files (the IF sample file deleted after the receive unless kept)
//   rx/               the receive's outputs
//   lock_outcomes.csv, nav_z.csv   the metrics asked for ([compute] json and weak-part scalars go into complete.csv);
//   with
//                     lock_outcomes of a simulated run also truth_lock_outcomes.csv (pipelines/truth_lock_rule.hpp)
//   complete.csv      the marker, written last (atomically, by rename): the run's scalars (name,value)
//   failed.txt        instead of complete.csv when the run threw: the message (a failed run is redone on resume)
// A run found complete is not redone; any other folder is cleared and run again.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <stop_token>
#include <string>
#include <vector>

#include "pipelines/campaign_alignment_run.hpp"
#include "pipelines/campaign_json_scalars.hpp"
#include "pipelines/campaign_metrics.hpp"
#include "pipelines/campaign_plan.hpp"
#include "pipelines/receive_file.hpp"
#include "sim/scenario.hpp"

namespace ultratrack::pipelines {

struct CampaignMetrics {
  std::optional<LockOutcomeOptions> lock_outcomes;
  std::optional<std::vector<double>> nav_z_times_s;  // nav z-scores at these times (needs a truth.csv and nav.csv)
  // The step protocol's weak part from this time on (s since the first sample; needs a truth.csv): scalars weak_fixes,
  // weak_rms_3d_m, weak_max_3d_m and, with a nav.csv, nav_weak_rows, nav_weak_rms_3d_m, nav_weak_max_3d_m.
  std::optional<double> weak_part_from_s;
  std::vector<CampaignJsonScalar> json_scalars;  // run scalars read from the run's JSON files
};

// Everything one run does, resolved (config/campaign_toml.hpp builds it from the campaign file and the run).
struct CampaignJob {
  CampaignRun run;
  // Simulated runs: the scenario and its echo (scenario.toml). Empty for a recording.
  std::optional<sim::Scenario> scenario;
  std::string scenario_echo;
  bool keep_samples = false;
  // The receive. For a simulated run input, format and source (fs, IF, 2-bit layout) come from the scenario and
  // out is set by the runner; `receive.imu` is read from the simulation's imu.csv for the couplings that use one.
  ReceiveFileJob receive;
  bool prns_from_simulation = true;  // search only the satellites the simulation put in the signal
  std::filesystem::path truth_csv;   // recordings: the truth for nav z-scores (simulated runs: sim/truth.csv)
  std::filesystem::path imu_csv;     // recordings: the IMU file of the GNSS/INS couplings
  CampaignMetrics metrics;
  // A run of the alignment Monte Carlo instead of a simulate-and-receive (no scenario, no receive).
  std::optional<CampaignAlignmentJob> alignment;
};

enum class CampaignRunState { kMissing, kComplete, kFailed };

struct CampaignRunStatus {
  CampaignRunState state = CampaignRunState::kMissing;
  std::string message;                         // kFailed: the error
  std::map<std::string, std::string> scalars;  // kComplete: complete.csv
};

std::filesystem::path campaign_run_dir(const std::filesystem::path& campaign_dir, int index);
CampaignRunStatus campaign_run_status(const std::filesystem::path& run_dir);

// Runs the job into run_dir (created; cleared first unless complete). Returns the final status: kComplete, or
// kFailed with the exception's message (also written to failed.txt): a failure is recorded, never thrown, so
// that one bad run does not stop a campaign. A stop request ends the receive early: the run is then left
// without a marker (missing, redone on resume).
CampaignRunStatus run_campaign_job(const CampaignJob& job, const std::filesystem::path& run_dir,
                                   std::stop_token stop = {});

// A fresh run folder (cleared) holding parameters.csv: how every kind of run starts.
void start_campaign_run_dir(const CampaignRun& run, const std::filesystem::path& run_dir);
// The completion marker, complete.csv (name,value), written atomically: how every kind of run ends.
void complete_campaign_run(const std::filesystem::path& run_dir, const std::map<std::string, std::string>& scalars);

// Records a run that failed before run_campaign_job could start (e.g. its job could not be built): parameters.csv
// and failed.txt with the message. Returns the kFailed status.
CampaignRunStatus record_campaign_run_failure(const CampaignRun& run, const std::filesystem::path& run_dir,
                                              const std::string& message);

}  // namespace ultratrack::pipelines
