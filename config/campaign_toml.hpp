// SPDX-License-Identifier: GPL-3.0-or-later
// Campaign files (`ultratrack campaign run C.toml`): runs, what each does and computes, the report, Slurm resources.
// The runs are a product of parameter axes; each simulates a scenario template (or takes a recording) and
// receives in process. Read strictly: every key known and of the right type, or
// an io::InputError naming the file, the line and the key. Relative paths resolve against the campaign file's
// folder (or the base folder given: `campaign run` keeps a copy of the file in its output folder).
//
//   [campaign]   name = "tracking_threshold"  description = "..."
//   [[axis]]     name = "cn0_dbhz"  values = [24.0, 26.0]          (numbers or strings)   or  count = 4 (0..3)
//                further keys are zipped columns, one value per axis value: seed = [100, 101, 102, 103]
//                or linear in the axis position: seed = { start = 100, step = 1 }
//                The first axis varies slowest; a run's parameters are each axis value, then its columns in key order.
//   [simulate]   scenario = "threshold.scenario.toml"   a scenario file whose text names parameters as {name}; the
//                path may name them too ("../scenarios/ultratight_{trajectory}.toml": one file per value)
//                set = { "signal.cn0_dbhz" = "{cn0_dbhz}" }   keys changed before the scenario is read
//                (config/toml_override.hpp; values may name parameters)
//                keep_samples = false                   (the IF sample file is deleted after the receive)
//   [[recording]] instead of [simulate]: name = "a"  input = "a.bin"  format = "i8"  sample_rate_hz = 4e6
//                if_hz = 0.0  imu = "imu.csv"  truth = "truth.csv"; the recordings are the first axis, "recording"
//   [[step]]     instead of [simulate]: args = ["fuse", "--imu", "sim/imu.csv", ...]   ultratrack subcommands run in
//                order in the run's folder (tools/campaign_steps.hpp), parameters as {name}, {campaign_dir} the
//                campaign's folder; [[file]] template = "c.toml"  name = "c.toml": a file written into the run's
//                folder first, its {name} parameters filled in
//   [alignment_mc] instead of [simulate]: one run of the filter-level stationary alignment Monte Carlo
//                (pipelines/campaign_alignment_run.hpp): seed = "{seed}"  filter = "ekf"  imu = "hg1700ae"
//                gps_sigma_deg = [0.255, 0.263, 0.087]  lat_deg = 36.37  duration_s = 100.0 (all may name parameters)
//   [receive]    nav = "brdc0010.22n" (hot start)  config = "receive.toml" (`receive --config`)
//                fusion_config = "motion.toml"  coupling = "scalar"  filter = "ekf"  align = "motion"
//                threads = 1  prns = "simulated" (search the simulated satellites) or "all"
//                nav_bits = "decoded"|"oracle"|... (`receive --nav-bits`)  vector_carrier = "aided-pll"|"fll"|"pll"
//                (vector only; `--vector-carrier`); empty: the receiver's defaults
//                (nav, config, coupling, filter, align, nav_bits and vector_carrier may name parameters: coupling =
//                "{coupling}")
//   [compute]    lock_outcomes = { lock_deadline_s = 5.0, strong_s = 0.0 }   nav_z_times_s = [10.5, 11.0]
//                weak_part_from_s = 16.0 (the step protocol's position errors after the step: weak_rms_3d_m, ...)
//                json = { drift_m = "f/summary.json:outages.0.horizontal_error_m" }   run scalars from a JSON file
//                remove = ["s", "f/nav.csv"]   [[step]] runs: files or folders deleted once the scalars are read
//   [[report]]   kind = "lock_threshold" (level = "cn0_dbhz")  or "nav_consistency"  or "stats" (value = "fixes")
//                or "rms" (values = ["drift_m"])  or "table" (columns = ["preset", "drift_m:.3f"])
//                or "error_stats" (axes = ["roll"]: scalars roll_error_deg and roll_sigma_deg)
//                group = ["coupling"]   (one table per combination of these parameters)
//   [slurm]      time = "01:00:00"  cpus_per_task = 1  mem = "4G"  partition = ""  account = ""
//                runs_per_task = 1  max_parallel = 0 (array throttle; 0: none)  extra = ["--qos=normal"]
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pipelines/campaign_plan.hpp"
#include "pipelines/campaign_report.hpp"
#include "pipelines/campaign_run.hpp"

namespace ultratrack::config {

struct CampaignReceive {
  std::string nav, config, fusion_config;  // paths (nav templated), resolved against the base folder
  std::string coupling = "scalar", filter = "ekf", align = "motion";
  std::string nav_bits, vector_carrier;  // empty: the receiver's defaults (decoded bits; the aided PLL)
  int threads = 1;
  bool prns_from_simulation = true;
};

struct SlurmResources {
  std::string time = "01:00:00", mem = "4G", partition, account;
  int cpus_per_task = 1;
  int runs_per_task = 1;
  int max_parallel = 0;
  std::vector<std::string> extra;
};

// A file written into each run's folder with the run's parameters filled in ([[file]]).
struct CampaignTemplateFile {
  std::filesystem::path source;
  std::string text, name;
};

// [alignment_mc]: each value as written, parameters still named ({seed}); campaign_job fills them in.
struct CampaignAlignment {
  std::string seed = "1", filter = "ekf", imu = "hg1700ae", lat_deg = "36.37", duration_s = "100.0";
  std::vector<std::string> gps_sigma_deg = {"0.255", "0.263", "0.087"};
};

struct CampaignFile {
  std::filesystem::path source;    // the file read (errors name it)
  std::filesystem::path base_dir;  // relative paths resolve here
  std::string name, description;
  std::vector<pipelines::CampaignAxis> axes;
  std::string scenario_spec;  // [simulate] scenario as written (may name parameters); empty for recordings
  std::map<std::filesystem::path, std::string> scenario_texts;    // every template the runs name, read once
  std::vector<std::pair<std::string, std::string>> scenario_set;  // [simulate] set: dotted key, templated value
  bool keep_samples = false;
  bool recordings = false;
  std::vector<std::vector<std::string>> steps;  // [[step]] args, templated
  std::vector<CampaignTemplateFile> files;
  std::vector<std::string> remove_after;  // [compute] remove: relative to the run folder
  std::optional<CampaignAlignment> alignment;
  CampaignReceive receive;
  pipelines::CampaignMetrics metrics;
  std::vector<pipelines::CampaignReduction> reductions;
  SlurmResources slurm;
};

// Reads and checks a campaign file (and its scenario template: every {name} must be a parameter). base_dir: where
// relative paths resolve (empty: the file's folder). Throws io::InputError naming the file, the line and the key.
CampaignFile read_campaign(const std::filesystem::path& file, const std::filesystem::path& base_dir = {});

// `text` with the run's parameters and {campaign_dir} filled in; `where` names the template in the InputError.
std::string fill_in(const CampaignFile& campaign, const std::string& text, const pipelines::CampaignRun& run,
                    const std::string& where);

// What run `run` of the campaign does: the scenario template filled in and parsed, the receive's options.
// Throws io::InputError naming the campaign file or the template.
pipelines::CampaignJob campaign_job(const CampaignFile& campaign, const pipelines::CampaignRun& run);

}  // namespace ultratrack::config
