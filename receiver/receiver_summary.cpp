// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/receiver_summary.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <cmath>

#include "io/atomic_file.hpp"
#include "io/json_text.hpp"
#include "io/units.hpp"

namespace ultratrack::receiver {
namespace {

std::string prn_list(const std::vector<int>& prns) {
  std::string out = "[";
  for (std::size_t i = 0; i < prns.size(); ++i) out += (i ? ", " : "") + std::to_string(prns[i]);
  return out + "]";
}

}  // namespace

double processed_seconds(const ReceiverEngine& engine) {
  return static_cast<double>(engine.stats().samples_processed) / engine.options().fs_hz;
}

double ttff_seconds(const ReceiverEngine& engine) {
  const auto& s = engine.stats();
  if (!s.first_fix_sample) return -1.0;
  return static_cast<double>(*s.first_fix_sample - s.first_sample) / engine.options().fs_hz;
}

void write_summary_json(const std::filesystem::path& path, const ReceiverEngine& engine, const RunDescription& run) {
  const ReceiverStats& s = engine.stats();
  const double duration = processed_seconds(engine);
  std::vector<int> acquired, tracked, used;
  for (int prn = 1; prn <= 32; ++prn) {
    const SatelliteStats& sat = s.satellites[static_cast<std::size_t>(prn)];
    if (sat.acquisitions > 0) acquired.push_back(prn);
    if (engine.tracked_time_s(prn) > 0.0) tracked.push_back(prn);
    if (sat.used_in_fixes > 0) used.push_back(prn);
  }
  io::AtomicFile file(path);
  auto& out = file.stream();
  fmt::print(out, "{{\n  \"input\": {{\"file\": {}, \"format\": {}, \"fs_hz\": {}, \"if_hz\": {}, \"skip_s\": {}}},\n",
             io::json_string(run.input), io::json_string(run.format), run.fs_hz, run.if_hz, run.skip_s);
  fmt::print(out, "  \"duration_s\": {:.6f},\n  \"wall_time_s\": {:.3f},\n  \"realtime_factor\": {:.3f},\n", duration,
             run.wall_time_s, run.wall_time_s > 0.0 ? duration / run.wall_time_s : 0.0);
  fmt::print(out, "  \"interrupted\": {},\n", run.interrupted);
  fmt::print(out, "  \"coupling\": \"{}\",\n", run.coupling);
  const bool fix = s.fixes > 0;
  fmt::print(out, "  \"fix\": {},\n  \"ttff_s\": {},\n", fix,
             fix ? fmt::format("{:.3f}", ttff_seconds(engine)) : "null");
  fmt::print(out,
             "  \"fixes\": {},\n  \"fixes_rejected_gdop\": {},\n  \"observation_epochs\": {},\n  \"clock_jumps\": "
             "{},\n",
             s.fixes, s.fixes_rejected_gdop, s.observation_epochs, s.clock_jumps);
  fmt::print(out, "  \"satellites_acquired\": {},\n  \"satellites_tracked\": {},\n  \"satellites_used\": {},\n",
             prn_list(acquired), prn_list(tracked), prn_list(used));
  if (fix) {
    const double n = s.fixes;
    fmt::print(out,
               "  \"mean_llh\": {{\"lat_deg\": {:.9f}, \"lon_deg\": {:.9f}, \"height_m\": {:.3f}}},\n"
               "  \"mean_ecef_m\": [{:.3f}, {:.3f}, {:.3f}],\n",
               s.sum_lat_rad / n * io::kDegPerRad, s.sum_lon_rad / n * io::kDegPerRad, s.sum_height_m / n,
               s.sum_r_e_m.x() / n, s.sum_r_e_m.y() / n, s.sum_r_e_m.z() / n);
  } else {
    fmt::print(out, "  \"mean_llh\": null,\n  \"mean_ecef_m\": null,\n");
  }
  fmt::print(out, "  \"ephemerides_decoded\": {},\n", engine.decoded_ephemerides().size());
  fmt::print(out, "  \"ionosphere\": {{\"applied\": {}, \"models\": [", engine.options().pvt.ionosphere);
  const auto& iono = engine.ionosphere().history();
  for (std::size_t i = 0; i < iono.size(); ++i)
    fmt::print(out, "{}{{\"model\": \"{} Klobuchar\", \"from_s\": {:.3f}}}", i ? ", " : "",
               ionosphere_source_name(iono[i].source),
               ionosphere_change_seconds(iono[i], s.first_sample, engine.options().fs_hz));
  fmt::print(out, "]}},\n");
  fmt::print(out, "  \"tracking_oscillator\": {{\"class\": \"{}\", \"h0\": {:.4g}, \"h_minus2\": {:.4g}}},\n",
             tracking_oscillator_name(engine.options().tracking), engine.options().tracking.oscillator_h0,
             engine.options().tracking.oscillator_h_minus2);
  // One line, so that a comparison across the change that added it can leave it out.
  fmt::print(out, "  \"nav_bits\": {{\"mode\": \"{}\", \"per_satellite\": [", to_string(engine.options().nav_bits));
  bool first_bits = true;
  for (int prn = 1; prn <= 32; ++prn) {
    if (s.satellites[static_cast<std::size_t>(prn)].acquisitions == 0) continue;
    const NavBitCounts b = engine.nav_bit_counts(prn);
    fmt::print(out,
               "{}{{\"prn\": {}, \"source\": \"{}\", \"bits_wiped\": {}, \"bits_unknown\": {}, \"bits_checked\": {}, "
               "\"bits_contradicted\": {}, \"words_contradicted\": {}, \"sources_stopped\": {}, "
               "\"nav_words_agreed\": {}, \"nav_words_disagreed\": {}}}",
               first_bits ? "" : ", ", prn, b.oracle ? "oracle" : "decoded", b.bits_wiped, b.bits_unknown,
               b.bits_checked, b.bits_contradicted, b.words_contradicted, b.sources_stopped, b.nav_words_agreed,
               b.nav_words_disagreed);
    first_bits = false;
  }
  fmt::print(out, "]}},\n");
  fmt::print(out, "  \"per_satellite\": [");
  bool first = true;
  for (int prn = 1; prn <= 32; ++prn) {
    const SatelliteStats& sat = s.satellites[static_cast<std::size_t>(prn)];
    if (sat.acquisitions == 0) continue;
    fmt::print(
        out,
        "{}\n    {{\"prn\": {}, \"acquisitions\": {}, \"losses\": {}, \"tracked_s\": {:.3f}, "
        "\"mean_cn0_dbhz\": {}, \"tracking_cn0_dbhz\": {}, \"observations\": {}, \"used_in_fixes\": {}, "
        "\"frame_synced\": {}, "
        "\"ephemeris_decoded\": {}}}",
        first ? "" : ",", prn, sat.acquisitions, sat.losses, engine.tracked_time_s(prn),
        sat.observations ? fmt::format("{:.2f}", sat.cn0_sum_dbhz / sat.observations) : "null",
        sat.tracking_cn0_count ? fmt::format("{:.2f}", sat.tracking_cn0_sum_dbhz / sat.tracking_cn0_count) : "null",
        sat.observations, sat.used_in_fixes, sat.frame_synced, sat.ephemeris_decoded);
    first = false;
  }
  fmt::print(out, "\n  ]{}\n}}\n", run.extra_json.empty() ? std::string() : ",\n  " + run.extra_json);
  file.commit();
}

}  // namespace ultratrack::receiver
