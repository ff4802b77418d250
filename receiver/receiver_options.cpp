// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/receiver_options.hpp"

#include <fmt/core.h>

#include <cmath>

#include "io/why_invalid.hpp"

namespace ultratrack::receiver {

bool ReceiverOptions::IsValid(std::string* why) const {
  const std::string problem = [&]() -> std::string {
    if (!(fs_hz > 1.1e6)) return fmt::format("sample rate {} Hz: must exceed 1.1 MHz", fs_hz);
    if (channels < 1 || channels > 32) return fmt::format("channels = {}: must be within 1..32", channels);
    for (int prn : prns)
      if (prn < 1 || prn > 32) return fmt::format("PRN {} outside 1..32", prn);
    if (num_antennas < 1 || num_antennas > kMaxAntennas)
      return fmt::format("num_antennas = {}: must be within 1..{}", num_antennas, kMaxAntennas);
    if (reference_week < 0) return fmt::format("reference week {} is negative", reference_week);
    if (!(observation_interval_s >= 0.001 && observation_interval_s <= 60.0))
      return fmt::format("observation interval {} s outside [0.001, 60]", observation_interval_s);
    if (!(reacquisition_interval_s >= 0.1 && reacquisition_interval_s <= 3600.0))
      return fmt::format("re-acquisition interval {} s outside [0.1, 3600]", reacquisition_interval_s);
    if (!(reacquisition_latency_s >= 0.0 && reacquisition_latency_s <= 10.0))
      return fmt::format("re-acquisition latency {} s outside [0, 10]", reacquisition_latency_s);
    if (blind_prns_per_snapshot < 0 || blind_prns_per_snapshot > 32)
      return fmt::format("blind PRNs per snapshot {} outside 0..32", blind_prns_per_snapshot);
    if (!(blind_revisit_s >= 0.0 && blind_revisit_s <= 3600.0))
      return fmt::format("blind revisit time {} s outside [0, 3600]", blind_revisit_s);
    if (!(hidden_prn_check_interval_s >= 1.0 && hidden_prn_check_interval_s <= 3600.0))
      return fmt::format("hidden PRN check interval {} s outside [1, 3600]", hidden_prn_check_interval_s);
    if (threads < 0 || threads > 256) return fmt::format("threads = {}: must be within 0..256", threads);
    if (!(assisted_doppler_half_width_hz > 0.0 && assisted_doppler_half_width_hz <= 5000.0))
      return fmt::format("assisted Doppler half width {} Hz outside (0, 5000]", assisted_doppler_half_width_hz);
    if (!(initial_travel_time_s >= 0.06 && initial_travel_time_s <= 0.09))
      return fmt::format("initial travel time {} s outside [0.06, 0.09]", initial_travel_time_s);
    if (!(clock_jump_threshold_s > 0.0)) return "clock jump threshold must be positive";
    if (!(tracking_record_interval_s >= 0.001 && tracking_record_interval_s <= 60.0))
      return fmt::format("tracking record interval {} s outside [0.001, 60]", tracking_record_interval_s);
    if (!(smoothing_window_s >= 0.0 && smoothing_window_s <= 1000.0))
      return fmt::format("smoothing window {} s outside [0, 1000]", smoothing_window_s);
    AcquisitionOptions acq = acquisition;
    acq.fs_hz = fs_hz;
    std::string why;
    if (!acq.IsValid(&why)) return "acquisition: " + why;
    why = io::why_invalid(tracking);
    if (!why.empty()) return "tracking: " + why;
    why = io::why_invalid(pvt);
    if (!why.empty()) return "pvt: " + why;
    return {};
  }();
  if (why) *why = problem;
  return problem.empty();
}

}  // namespace ultratrack::receiver
