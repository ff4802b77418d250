// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_run.hpp"

#include <fmt/core.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "ins/imu_csv.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "pipelines/truth_lock_rule.hpp"
#include "sim/simulation_files.hpp"

namespace ultratrack::pipelines {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A number the receive's summary.json members hold, e.g. "handover_t_s": 11.120; empty when absent.
std::string json_number(const std::string& json, const std::string& key) {
  const std::string quoted = "\"" + key + "\":";
  const std::size_t at = json.find(quoted);
  if (at == std::string::npos) return "";
  std::size_t begin = at + quoted.size();
  while (begin < json.size() && json[begin] == ' ') ++begin;
  std::size_t end = begin;
  while (end < json.size() && std::string_view("+-.0123456789eE").find(json[end]) != std::string_view::npos) ++end;
  return json.substr(begin, end - begin);
}

// Receives, computes the metrics and returns the run's scalars; nothing when a stop request ended it early.
std::optional<std::map<std::string, std::string>> run(const CampaignJob& job, const fs::path& run_dir,
                                                      std::stop_token stop) {
  if (job.alignment) return campaign_alignment_scalars(*job.alignment);
  std::map<std::string, std::string> scalars;
  ReceiveFileJob rx = job.receive;
  rx.out = run_dir / "rx";
  std::vector<int> prns = rx.options.receiver.prns;
  double duration_s = 0.0;
  fs::path truth = job.truth_csv, imu = job.imu_csv;
  std::vector<fs::path> sample_files;
  int fallback_week = 0;
  if (job.scenario) {
    const sim::Scenario& scenario = *job.scenario;
    const sim::SimulationResult simulated = sim::simulate_to_folder(scenario, run_dir / "sim", job.scenario_echo, stop);
    if (simulated.interrupted) return std::nullopt;
    if (simulated.sample_files.empty())
      throw io::InputError(scenario.source.string(), "a campaign run receives IF samples: the scenario needs [signal]");
    sample_files = simulated.sample_files;
    rx.input = sample_files.front();
    rx.format = scenario.format;
    rx.source.fs_hz = scenario.sample_rate_hz;
    rx.source.if_hz = scenario.if_hz;
    rx.source.two_bit = scenario.two_bit;
    rx.options.receiver.fs_hz = scenario.sample_rate_hz;
    prns.clear();
    for (const signals::SatelliteView& s : simulated.satellites) prns.push_back(s.prn);
    if (job.prns_from_simulation) rx.options.receiver.prns = prns;
    duration_s = scenario.duration_s;
    truth = run_dir / "sim" / "truth.csv";
    imu = run_dir / "sim" / "imu.csv";
    fallback_week = scenario.gps_week;
    scalars["simulate_wall_s"] = fmt::format("{:.3f}", simulated.wall_s);
  }
  date_recording(rx.options.receiver, rx.navigation, fallback_week > 0 ? fallback_week : 2190);
  if (uses_imu(rx.options.coupling)) {
    if (job.scenario && !job.scenario->trajectory_enabled())
      throw io::InputError(
          job.scenario->source.string(),
          "the " + to_string(rx.options.coupling) + " coupling needs an IMU: the scenario has no [trajectory]");
    rx.imu = ins::read_imu_csv(imu);
    rx.options.imu_name = imu.string();
  }
  if (std::string why; !rx.options.IsValid(&why)) throw io::InputError("campaign receive", why);
  const ReceiveFileResult received = receive_file(std::move(rx), stop);
  const ReceiveSummary& s = received.summary;
  if (s.interrupted) return std::nullopt;
  if (!job.scenario) duration_s = s.processed_s;
  if (prns.empty())
    for (int prn = 1; prn <= 32; ++prn) prns.push_back(prn);

  if (job.metrics.lock_outcomes) {
    const std::vector<LockOutcome> outcomes =
        lock_outcomes(prns, run_dir / "rx" / "tracking.csv", duration_s, *job.metrics.lock_outcomes);
    write_lock_outcomes_csv(run_dir / "lock_outcomes.csv", outcomes);
    // Per run, for `stats` reports (the lock_threshold report reads the per-satellite file).
    int kept = 0, lost = 0;
    for (const LockOutcome& o : outcomes) {
      if (o.outcome == "kept") ++kept;
      if (o.outcome == "lost") ++lost;
    }
    scalars["satellites_kept"] = std::to_string(kept);
    scalars["satellites_lost"] = std::to_string(lost);
  }
  // The common rule beside the receiver's own (pipelines/truth_lock_rule.hpp), where the simulation wrote its truth.
  const fs::path satellite_truth = run_dir / "sim" / "satellite_truth.csv";
  if (job.metrics.lock_outcomes && job.scenario && fs::exists(satellite_truth) &&
      fs::exists(run_dir / "rx" / "tracking.csv")) {
    TruthLockOptions common;
    const LockOutcomeOptions& own = *job.metrics.lock_outcomes;
    common.from_s = own.strong_s > 0.0 ? own.strong_s : own.lock_deadline_s;
    common.end_s = duration_s;
    write_truth_lock_outcomes_csv(run_dir / "truth_lock_outcomes.csv",
                                  truth_lock_outcomes(satellite_truth, run_dir / "rx" / "tracking.csv", common));
  }
  if (job.metrics.nav_z_times_s && s.navigation_started) {
    if (truth.empty()) throw io::InputError("campaign", "nav z-scores need a truth file ([[recording]] truth)");
    write_nav_z_csv(run_dir / "nav_z.csv", nav_z_scores(run_dir / "rx" / "nav.csv", truth, *job.metrics.nav_z_times_s));
  }
  if (job.metrics.weak_part_from_s) {
    if (truth.empty()) throw io::InputError("campaign", "weak-part positions need a truth file ([[recording]] truth)");
    const WeakPartPositions w = weak_part_positions(run_dir / "rx" / "solution.csv", run_dir / "rx" / "nav.csv", truth,
                                                    *job.metrics.weak_part_from_s);
    // A value nothing was compared for is left out (the stats reduction counts the runs that have it).
    const auto put = [&](const char* name, double v) {
      if (std::isfinite(v)) scalars[name] = fmt::format("{:.3f}", v);
    };
    scalars["weak_fixes"] = std::to_string(w.fixes);
    put("weak_rms_3d_m", w.rms_3d_m);
    put("weak_max_3d_m", w.max_3d_m);
    if (fs::exists(run_dir / "rx" / "nav.csv")) {
      scalars["nav_weak_rows"] = std::to_string(w.nav_rows);
      put("nav_weak_rms_3d_m", w.nav_rms_3d_m);
      put("nav_weak_max_3d_m", w.nav_max_3d_m);
    }
  }
  if (!job.keep_samples)
    for (const fs::path& file : sample_files) fs::remove(file);

  scalars["coupling"] = to_string(s.coupling);
  scalars["receive_wall_s"] = fmt::format("{:.3f}", received.wall_s);
  scalars["processed_s"] = fmt::format("{:.3f}", s.processed_s);
  scalars["satellites_tracked"] = std::to_string(s.satellites_tracked);
  scalars["satellites_used"] = std::to_string(s.satellites_used);
  scalars["fixes"] = std::to_string(s.fixes);
  scalars["ttff_s"] = fmt::format("{:.3f}", s.ttff_s);
  scalars["navigation_started"] = s.navigation_started ? "1" : "0";
  scalars["handed_over"] = s.handed_over ? "1" : "0";
  if (const std::string t = json_number(s.summary_json, "handover_t_s"); !t.empty()) scalars["handover_t_s"] = t;
  return scalars;
}

}  // namespace

fs::path campaign_run_dir(const fs::path& campaign_dir, int index) {
  return campaign_dir / "runs" / campaign_run_folder(index);
}

CampaignRunStatus campaign_run_status(const fs::path& run_dir) {
  CampaignRunStatus status;
  std::error_code ec;
  if (fs::is_regular_file(run_dir / "complete.csv", ec)) {
    status.state = CampaignRunState::kComplete;
    std::ifstream in(run_dir / "complete.csv");
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      const std::size_t comma = line.find(',');
      if (comma != std::string::npos) status.scalars[line.substr(0, comma)] = line.substr(comma + 1);
    }
  } else if (fs::is_regular_file(run_dir / "failed.txt", ec)) {
    status.state = CampaignRunState::kFailed;
    status.message = read_text(run_dir / "failed.txt");
    while (!status.message.empty() && status.message.back() == '\n') status.message.pop_back();
  }
  return status;
}

void start_campaign_run_dir(const CampaignRun& run, const fs::path& run_dir) {
  fs::remove_all(run_dir);
  fs::create_directories(run_dir);
  std::string parameters = "name,value\n";
  for (const auto& [name, value] : run.parameters) parameters += name + "," + value + "\n";
  io::write_file_atomically(run_dir / "parameters.csv", parameters);
}

void complete_campaign_run(const fs::path& run_dir, const std::map<std::string, std::string>& scalars) {
  std::string text = "name,value\n";
  for (const auto& [name, value] : scalars) text += name + "," + value + "\n";
  io::write_file_atomically(run_dir / "complete.csv", text);
}

CampaignRunStatus record_campaign_run_failure(const CampaignRun& run, const fs::path& run_dir,
                                              const std::string& message) {
  start_campaign_run_dir(run, run_dir);
  io::write_file_atomically(run_dir / "failed.txt", message + "\n");
  return campaign_run_status(run_dir);
}

CampaignRunStatus run_campaign_job(const CampaignJob& job, const fs::path& run_dir, std::stop_token stop) {
  if (CampaignRunStatus done = campaign_run_status(run_dir); done.state == CampaignRunState::kComplete) return done;
  start_campaign_run_dir(job.run, run_dir);
  try {
    auto scalars = run(job, run_dir, stop);
    if (!scalars) return {};
    scalars->merge(read_campaign_json_scalars(run_dir, job.metrics.json_scalars));
    complete_campaign_run(run_dir, *scalars);
  } catch (const std::exception& e) {
    io::write_file_atomically(run_dir / "failed.txt", std::string(e.what()) + "\n");
  }
  return campaign_run_status(run_dir);
}

}  // namespace ultratrack::pipelines
