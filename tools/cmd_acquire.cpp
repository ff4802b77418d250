// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack acquire`: FFT acquisition of the first K x T_coh of a recording (receiver/acquisition.hpp
// on receiver/sample_source.hpp); one row per detected PRN as a table, or JSON with --json.
// Every bad input (numbers, format, PRN list, file, options out of range) is an InputError (exit 2).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "commands.hpp"
#include "format_options.hpp"
#include "receiver/acquisition.hpp"
#include "receiver/sample_source.hpp"
#include "signals/input_error.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::tools {

namespace {

// Numbers are taken as text and parsed by cli_parse.hpp so that a malformed one is an InputError like any other.
struct AcquireArgs {
  std::string input, fs = "", if_hz = "0", ms = "1", noncoh = "10", prns = "1-32";
  std::string doppler_max = "5000", doppler_step = "0", pfa = "1e-3";
  FormatArgs format;
  bool iq_swap = false, q_negate = false, json = false, all = false;
};

void run_acquire(const AcquireArgs& args) {
  const auto format = parse_format(args.format);
  receiver::SampleSourceOptions source_options =
      parse_sample_source_options(args.format, args.fs, args.if_hz, args.iq_swap, args.q_negate);

  receiver::AcquisitionOptions options;
  options.fs_hz = source_options.fs_hz;
  options.coherent_ms = parse_int_option("--ms", args.ms);
  options.noncoherent = parse_int_option("--noncoh", args.noncoh);
  options.doppler_max_hz = parse_double_option("--doppler-max", args.doppler_max);
  options.doppler_step_hz = parse_double_option("--doppler-step", args.doppler_step);
  options.pfa = parse_double_option("--pfa", args.pfa);
  const std::vector<int> prns = parse_prn_list_option("--prn", args.prns);
  std::string why;
  if (!options.IsValid(&why)) throw signals::InputError("command line", why);

  receiver::SampleSource source(args.input, format, source_options);
  // A recording shorter than K blocks is searched with the whole blocks it holds (said on stderr).
  const auto block = static_cast<std::int64_t>(std::llround(options.fs_hz * options.coherent_s()));
  const std::int64_t blocks_in_file = source.total_samples() / block;
  if (blocks_in_file < 1)
    throw signals::InputError(args.input, fmt::format("holds {} samples, fewer than one {} ms coherent block ({})",
                                                      source.total_samples(), options.coherent_ms, block));
  if (blocks_in_file < options.noncoherent) {
    fmt::print(stderr, "ultratrack acquire: the file holds {} blocks of {} ms; using K = {} instead of {}\n",
               blocks_in_file, options.coherent_ms, blocks_in_file, options.noncoherent);
    options.noncoherent = static_cast<int>(blocks_in_file);
  }

  receiver::Acquisition acquisition(options);
  std::vector<std::complex<float>> samples(acquisition.samples_needed());
  const receiver::SampleBlock got = source.read(samples);
  if (got.count != samples.size()) throw signals::InputError(args.input, "ended before the samples it reported");
  const auto results = acquisition.search(samples, prns);

  std::vector<receiver::AcquisitionResult> shown;
  for (const auto& r : results)
    if (r.detected || args.all) shown.push_back(r);
  if (args.json) {
    fmt::print(
        "{{\"input\": \"{}\", \"format\": \"{}\", \"fs_hz\": {}, \"if_hz\": {}, \"coherent_ms\": {}, "
        "\"noncoherent\": {}, \"pfa\": {}, \"satellites\": [",
        args.input, args.format.format, options.fs_hz, source_options.if_hz, options.coherent_ms, options.noncoherent,
        options.pfa);
    for (std::size_t i = 0; i < shown.size(); ++i) {
      const auto& r = shown[i];
      fmt::print(
          "{}\n  {{\"prn\": {}, \"detected\": {}, \"doppler_hz\": {:.1f}, \"code_phase_chips\": {:.3f}, "
          "\"code_phase_samples\": {:.3f}, \"cn0_dbhz\": {:.1f}, \"metric\": {:.2f}, \"threshold\": {:.2f}}}",
          i ? "," : "", r.prn, r.detected, r.doppler_hz, r.code_phase_chips, r.code_phase_samples, r.cn0_dbhz, r.metric,
          r.threshold);
    }
    fmt::print("\n]}}\n");
    return;
  }
  fmt::print("# {}: {} x {} ms, pfa {:g}, threshold {:.2f} (peak / mean noise)\n", args.input, options.noncoherent,
             options.coherent_ms, options.pfa, results.empty() ? 0.0 : results.front().threshold);
  fmt::print("{:>4} {:>11} {:>17} {:>9} {:>8}{}\n", "prn", "doppler_hz", "code_phase_chips", "cn0_dbhz", "metric",
             args.all ? "  detected" : "");
  for (const auto& r : shown)
    fmt::print("{:>4} {:>11.1f} {:>17.3f} {:>9.1f} {:>8.2f}{}\n", r.prn, r.doppler_hz, r.code_phase_chips, r.cn0_dbhz,
               r.metric, args.all ? (r.detected ? "  yes" : "  no") : "");
  if (shown.empty()) fmt::print("# no satellite detected\n");
}

}  // namespace

void add_acquire_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("acquire", "Search a recording for GPS L1 C/A satellites (FFT acquisition)");
  auto args = std::make_shared<AcquireArgs>();
  cmd->add_option("--input", args->input, "IF sample file")->required();
  add_format_options(cmd, args->format);
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--ms", args->ms, "coherent integration, ms (1-10)")->capture_default_str();
  cmd->add_option("--noncoh", args->noncoh, "coherent blocks summed non-coherently")->capture_default_str();
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15")->capture_default_str();
  cmd->add_option("--doppler-max", args->doppler_max, "Doppler search range +-, Hz")->capture_default_str();
  cmd->add_option("--doppler-step", args->doppler_step, "Doppler bin, Hz (0: 2/(3 T_coh))")->capture_default_str();
  cmd->add_option("--pfa", args->pfa, "false-alarm probability per PRN")->capture_default_str();
  cmd->add_flag("--iq-swap", args->iq_swap, "exchange I and Q (complex formats)");
  cmd->add_flag("--q-negate", args->q_negate, "negate Q (complex) / invert the spectrum (real IF)");
  cmd->add_flag("--json", args->json, "machine-readable output");
  cmd->add_flag("--all", args->all, "also list PRNs that were not detected");
  cmd->callback([args] { run_acquire(*args); });
}

}  // namespace ultratrack::tools
