// SPDX-License-Identifier: GPL-3.0-or-later
#include "campaign_steps.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "io/atomic_file.hpp"

extern char** environ;

namespace ultratrack::tools {
namespace {

namespace fs = std::filesystem;

std::string command_line(const std::vector<std::string>& argv) {
  std::string text;
  for (const std::string& a : argv) text += (text.empty() ? "" : " ") + a;
  return text;
}

// The last `lines` lines of a file.
std::string tail_of(const fs::path& file, std::size_t lines) {
  std::ifstream in(file);
  std::vector<std::string> kept;
  for (std::string line; std::getline(in, line);) {
    kept.push_back(line);
    if (kept.size() > lines) kept.erase(kept.begin());
  }
  std::string text;
  for (const std::string& line : kept) text += "\n  " + line;
  return text;
}

// Runs argv in `dir` with stdout and stderr appended to `log`. The exit status (128 + signal when killed); nothing
// when a stop request ended it.
std::optional<int> run_child(const std::vector<std::string>& argv, const fs::path& dir, const fs::path& log,
                             std::stop_token stop) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The log is opened before the chdir: its path may be relative to ours.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0)
    throw std::runtime_error("cannot start " + argv[0] + " in " + dir.string() + ": " + std::strerror(error));
  bool stopped = false;
  for (;;) {
    int status = 0;
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) {
      if (stopped) return std::nullopt;
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    if (done < 0) throw std::runtime_error("waiting for " + argv[0] + ": " + std::strerror(errno));
    if (stop.stop_requested() && !stopped) {
      kill(pid, SIGTERM);  // the step's own InterruptGuard ends it; its run stays without a marker
      stopped = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

pipelines::CampaignRunStatus run_campaign_steps(const config::CampaignFile& campaign, const pipelines::CampaignRun& run,
                                                const fs::path& run_dir, const fs::path& program,
                                                std::stop_token stop) {
  if (pipelines::CampaignRunStatus done = pipelines::campaign_run_status(run_dir);
      done.state == pipelines::CampaignRunState::kComplete)
    return done;
  pipelines::start_campaign_run_dir(run, run_dir);
  const fs::path log = run_dir / "steps.log";
  try {
    for (const config::CampaignTemplateFile& f : campaign.files)
      io::write_file_atomically(run_dir / f.name, config::fill_in(campaign, f.text, run, f.source.string()));
    for (std::size_t k = 0; k < campaign.steps.size(); ++k) {
      std::vector<std::string> argv{program.string()};
      for (const std::string& arg : campaign.steps[k])
        argv.push_back(config::fill_in(campaign, arg, run, campaign.source.string() + ": [[step]]"));
      std::ofstream(log, std::ios::app) << "$ " << command_line(argv) << "\n";
      const std::optional<int> status = run_child(argv, run_dir, log, stop);
      if (!status) return {};
      if (*status != 0)
        throw std::runtime_error(fmt::format("step {} (ultratrack {}) exited with status {}; the end of {}:{}", k + 1,
                                             command_line(campaign.steps[k]), *status, log.string(), tail_of(log, 5)));
    }
    const auto scalars = pipelines::read_campaign_json_scalars(run_dir, campaign.metrics.json_scalars);
    for (const std::string& path : campaign.remove_after) fs::remove_all(run_dir / path);
    pipelines::complete_campaign_run(run_dir, scalars);
  } catch (const std::exception& e) {
    io::write_file_atomically(run_dir / "failed.txt", std::string(e.what()) + "\n");
  }
  return pipelines::campaign_run_status(run_dir);
}

}  // namespace ultratrack::tools
