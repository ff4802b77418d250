// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/receive_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "io/why_invalid.hpp"
#include "pipelines/format_diagnosis.hpp"
#include "pipelines/receive_csv_files.hpp"
#include "receiver/receiver_outputs.hpp"
#include "receiver/receiver_summary.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::pipelines {

void date_recording(receiver::ReceiverOptions& options, const signals::RinexNavData& navigation, int fallback_week) {
  if (options.reference_week != 0) return;
  options.reference_week = navigation.ephemerides.empty() ? fallback_week : navigation.ephemerides.front().week;
  options.reference_week_is_signal_week = !navigation.ephemerides.empty();
}

namespace {

// Samples the first acquisition integrates (coherent length x non-coherent sums).
std::int64_t samples_for_one_acquisition(const receiver::ReceiverOptions& options) {
  const receiver::AcquisitionOptions& a = options.acquisition;
  return static_cast<std::int64_t>(a.noncoherent) * std::llround(a.coherent_s() * options.fs_hz);
}

receiver::RunDescription describe(const ReceiveFileJob& job, const ReceiveSummary& summary, double wall_s) {
  receiver::RunDescription run;
  run.input = job.input.string();
  run.format = std::string(signals::to_string(job.format));
  if (signals::is_two_bit(job.format))
    run.format += fmt::format(" ({}, {})", signals::to_string(job.source.two_bit.coding),
                              signals::to_string(job.source.two_bit.order));
  run.fs_hz = job.source.fs_hz;
  run.if_hz = job.source.if_hz;
  run.skip_s = static_cast<double>(job.source.start_sample) / job.source.fs_hz;
  run.wall_time_s = wall_s;
  run.interrupted = summary.interrupted;
  run.coupling = to_string(job.options.coupling);
  run.extra_json = summary.summary_json;
  return run;
}

}  // namespace

ReceiveFileResult receive_file(ReceiveFileJob job, std::stop_token stop, const ReceiveProgressCallback& progress) {
  const receiver::ReceiverOptions& rx = job.options.receiver;
  if (rx.fs_hz != job.source.fs_hz)
    throw signals::InputError("receive options", fmt::format("receiver fs {} Hz differs from the sample source's {} Hz",
                                                             rx.fs_hz, job.source.fs_hz));
  if (job.duration_s < 0.0) throw signals::InputError("receive options", "duration must not be negative");
  if (const std::string why = io::why_invalid(rx); !why.empty()) throw signals::InputError("receive options", why);
  if (std::string why; !job.options.IsValid(&why)) throw signals::InputError("receive options", why);

  receiver::SampleSource source(job.input, job.format, job.source);
  std::int64_t to_process = source.total_samples() - job.source.start_sample;
  if (job.duration_s > 0.0) to_process = std::min<std::int64_t>(to_process, std::llround(job.duration_s * rx.fs_hz));
  if (const std::int64_t needed = samples_for_one_acquisition(rx); to_process < needed)
    throw signals::InputError(job.input.string(),
                              fmt::format("holds {} samples to process, fewer than the {} that one acquisition needs "
                                          "({} x {} ms)",
                                          to_process, needed, rx.acquisition.noncoherent, rx.acquisition.coherent_ms));

  receiver::ReceiverOutputs outputs(job.out, rx.fs_hz, rx.observation_interval_s);
  ReceiveCsvFiles logs(job.out, job.options.coupling, rx.fs_hz);
  Receiver receiver(job.options, std::move(job.imu), job.navigation, outputs, logs);
  const auto wall_start = std::chrono::steady_clock::now();
  const double total_s = static_cast<double>(to_process) / rx.fs_hz;
  receiver.run(source, to_process, std::move(stop), [&](const receiver::ReceiverEngine& engine) {
    if (progress) progress({engine, total_s, false});
  });
  ReceiveFileResult result;
  result.summary = receiver.finish();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (progress) progress({receiver.engine(), total_s, true});
  // Nothing tracked: name a sample convention that would have worked, when one does (format_diagnosis.hpp).
  if (!result.summary.interrupted && result.summary.satellites_tracked == 0) {
    const std::string hint = to_sentence(diagnose_sample_format(job.input, job.format, job.source));
    if (!result.summary.satellites_found)
      throw signals::InputError(job.input.string(),
                                fmt::format("no GPS L1 C/A satellite found in {:.1f} s of signal: check --format, "
                                            "--fs, --if, --iq-swap/--q-negate.{}",
                                            result.summary.processed_s, hint));
    if (!hint.empty())
      throw signals::InputError(job.input.string(),
                                fmt::format("no satellite tracked in {:.1f} s of signal: the 2-bit packing looks "
                                            "wrong.{}",
                                            result.summary.processed_s, hint));
  }
  outputs.finish(receiver.engine(), describe(job, result.summary, result.wall_s));
  logs.commit();
  return result;
}

}  // namespace ultratrack::pipelines
