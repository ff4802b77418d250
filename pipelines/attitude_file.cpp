// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/attitude_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <span>

#include "io/why_invalid.hpp"
#include "pipelines/receive_file.hpp"
#include "receiver/multi_sample_source.hpp"
#include "receiver/receiver_summary.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::pipelines {

AttitudeFileResult attitude_file(AttitudeFileJob job, std::stop_token stop, const AttitudeProgressCallback& progress) {
  const std::size_t n_ant = job.solver.array.lever_arm_body_m.size();
  if (job.inputs.size() != n_ant)
    throw signals::InputError("inputs",
                              fmt::format("{} files for the {} antennas of the array", job.inputs.size(), n_ant));
  receiver::ReceiverOptions& options = job.options;
  options.num_antennas = static_cast<int>(n_ant);
  if (options.reference_week == 0 && job.navigation.ephemerides.empty())
    throw signals::InputError("options",
                              "give navigation data or a reference week (the full GPS week of the recording)");
  date_recording(options, job.navigation, 0);
  if (const std::string why = io::why_invalid(options); !why.empty()) throw signals::InputError("options", why);
  if (job.duration_s < 0.0) throw signals::InputError("options", "duration: must not be negative");

  receiver::MultiSampleSource source(job.inputs, job.format, job.source);
  std::int64_t to_process = source.total_samples();
  if (job.duration_s > 0.0)
    to_process = std::min<std::int64_t>(to_process, std::llround(job.duration_s * options.fs_hz));

  receiver::AttitudeOutputs outputs(job.out, options.fs_hz, options.observation_interval_s, job.solver,
                                    job.line_bias_cycles);
  receiver::ReceiverEngine engine(options, outputs);
  if (!job.navigation.ephemerides.empty())
    engine.add_navigation(job.navigation.ephemerides, job.navigation.klobuchar, job.navigation.utc);

  const auto block_size = static_cast<std::size_t>(std::max<std::int64_t>(1, std::llround(0.05 * options.fs_hz)));
  std::vector<std::vector<std::complex<float>>> blocks(n_ant, std::vector<std::complex<float>>(block_size));
  std::vector<std::span<std::complex<float>>> out(n_ant);
  std::vector<std::span<const std::complex<float>>> in(n_ant);
  const auto wall_start = std::chrono::steady_clock::now();
  std::int64_t done = 0;
  while (done < to_process && !stop.stop_requested()) {
    const auto want = static_cast<std::size_t>(std::min<std::int64_t>(block_size, to_process - done));
    for (std::size_t a = 0; a < n_ant; ++a) out[a] = std::span(blocks[a].data(), want);
    const receiver::SampleBlock got = source.read(out);
    if (got.count == 0) break;
    for (std::size_t a = 0; a < n_ant; ++a) in[a] = std::span<const std::complex<float>>(blocks[a].data(), got.count);
    engine.process(std::span<const std::span<const std::complex<float>>>(in), got.first_sample);
    done += static_cast<std::int64_t>(got.count);
    if (progress) progress(engine, outputs.stats());
  }
  AttitudeFileResult result;
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  result.interrupted = stop.stop_requested();

  receiver::RunDescription run;
  run.input = job.inputs.front().string();
  run.format = std::string(signals::to_string(job.format));
  run.fs_hz = options.fs_hz;
  run.if_hz = job.source.if_hz;
  run.wall_time_s = result.wall_s;
  run.interrupted = result.interrupted;
  std::vector<std::string> inputs;
  for (const auto& p : job.inputs) inputs.push_back(p.string());
  outputs.finish(engine, run, inputs);

  result.stats = outputs.stats();
  result.processed_s = receiver::processed_seconds(engine);
  result.threads = engine.threads();
  return result;
}

}  // namespace ultratrack::pipelines
