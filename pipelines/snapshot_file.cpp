// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/snapshot_file.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>

#include "io/why_invalid.hpp"
#include "receiver/ionosphere_model.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::pipelines {

SnapshotFileResult snapshot_file(const SnapshotFileJob& job) {
  std::string why;
  if (!job.search.IsValid(&why)) throw signals::InputError("snapshot options", why);
  if (why = io::why_invalid(job.navigation); !why.empty()) throw signals::InputError("snapshot options", why);
  if (job.nav.ephemerides.empty()) throw signals::InputError("navigation data", "holds no GPS ephemeris");
  SnapshotFileResult result;
  receiver::SnapshotOptions options = job.navigation;
  options.klobuchar = job.nav.klobuchar.valid ? job.nav.klobuchar : receiver::default_klobuchar();
  result.ionosphere = job.nav.klobuchar.valid ? "nav file Klobuchar" : "default Klobuchar (RTKLIB ion_default)";

  receiver::SampleSource source(job.input, job.format, job.source);
  const std::int64_t wanted = std::llround(job.snapshot_ms * 1e-3 * job.source.fs_hz);
  const std::int64_t available = source.total_samples() - job.source.start_sample;
  std::vector<std::complex<float>> samples(
      static_cast<std::size_t>(std::max<std::int64_t>(0, std::min(wanted, available))));
  samples.resize(source.read(samples).count);
  result.used_ms = static_cast<double>(samples.size()) / job.source.fs_hz * 1e3;
  result.shortened = available < wanted;
  if (result.used_ms < 10.0)
    throw signals::InputError(job.input.string(), fmt::format("holds {:.1f} ms of signal after the start; a snapshot "
                                                              "needs >= 10 ms",
                                                              result.used_ms));

  result.detections = receiver::measure_snapshot(samples, job.prns, job.search);
  if (result.detections.empty()) throw signals::InputError(job.input.string(), "no satellite detected in the snapshot");
  std::vector<receiver::SnapshotMeasurement> measurements;
  for (const auto& d : result.detections) {
    const auto eph = signals::select_ephemeris(job.nav.ephemerides, d.prn, job.approximate_time);
    if (!eph) {
      result.without_ephemeris.push_back(d.prn);
      continue;
    }
    receiver::SnapshotMeasurement m;
    m.prn = d.prn;
    m.code_phase_chips = d.code_phase_chips;
    m.code_sigma_chips = d.code_sigma_chips;
    m.doppler_hz = d.doppler_hz;
    m.doppler_sigma_hz = d.doppler_sigma_hz;
    m.cn0_dbhz = d.cn0_dbhz;
    m.ephemeris = *eph;
    measurements.push_back(m);
  }
  if (measurements.size() < 5) {
    // The nav file's time span beside the time asked for: a nav file of another day is the usual cause.
    const auto seconds = [](const signals::Ephemeris& e) { return e.week * 604800.0 + e.toe_s; };
    const auto [first, last] = std::minmax_element(
        job.nav.ephemerides.begin(), job.nav.ephemerides.end(),
        [&](const signals::Ephemeris& a, const signals::Ephemeris& b) { return seconds(a) < seconds(b); });
    result.solution.failure = fmt::format(
        "{} satellites detected, {} with a healthy ephemeris at the time: at least 5 are needed (the time asked "
        "for: week {} TOW {:.0f}; the nav file's ephemerides: week {} TOW {:.0f} to week {} TOW {:.0f}, each valid "
        "about 2 h around its time)",
        result.detections.size(), measurements.size(), job.approximate_time.week, job.approximate_time.tow_s,
        first->week, first->toe_s, last->week, last->toe_s);
  } else
    result.solution =
        receiver::solve_snapshot(measurements, job.approximate_time, job.approximate_position_e_m, options);
  return result;
}

}  // namespace ultratrack::pipelines
