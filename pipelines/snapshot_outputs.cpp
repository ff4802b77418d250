// SPDX-License-Identifier: GPL-3.0-or-later
// The files of a snapshot fix (pipelines/snapshot_file.hpp): snapshot.json, every field of the job, the detections
// and the solution with its sigmas and tests (null where there is no solution), and solution.csv with the fix.
#include <fmt/core.h>
#include <fmt/ostream.h>

#include <cmath>
#include <numbers>

#include "io/atomic_file.hpp"
#include "io/json_text.hpp"
#include "io/units.hpp"
#include "pipelines/snapshot_file.hpp"
#include "receiver/solution_writer.hpp"

namespace ultratrack::pipelines {

namespace {

std::string number_or_null(double v, const char* format = "{:.3f}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "null";
}

void write_snapshot_json(const std::filesystem::path& path, const SnapshotFileJob& job, const SnapshotFileResult& r,
                         const std::string& format_label, double wall_s) {
  const receiver::SnapshotSolution& s = r.solution;
  const signals::GpsTime& t0 = job.approximate_time;
  io::AtomicFile file(path);
  auto& out = file.stream();
  fmt::print(
      out,
      "{{\n  \"input\": {{\"file\": {}, \"format\": {}, \"fs_hz\": {}, \"if_hz\": {}, \"snapshot_ms\": {:.3f}}},\n",
      io::json_string(job.input.string()), io::json_string(format_label), job.source.fs_hz, job.source.if_hz,
      r.used_ms);
  fmt::print(out, "  \"approximate_time\": {{\"week\": {}, \"tow_s\": {:.6f}, \"sigma_s\": {}}},\n", t0.week, t0.tow_s,
             job.navigation.time_sigma_s);
  fmt::print(out, "  \"valid\": {},\n  \"failure\": {},\n  \"quality\": {},\n  \"a_priori\": {},\n", s.valid,
             s.valid ? "null" : io::json_string(s.failure), io::json_string(s.quality), io::json_string(s.a_priori));
  fmt::print(out, "  \"ionosphere\": {},\n", io::json_string(r.ionosphere));
  const bool solved = s.used >= 5;
  if (solved) {
    fmt::print(out, "  \"ecef_m\": [{:.3f}, {:.3f}, {:.3f}],\n", s.r_e_m.x(), s.r_e_m.y(), s.r_e_m.z());
    fmt::print(out, "  \"llh\": {{\"lat_deg\": {:.9f}, \"lon_deg\": {:.9f}, \"height_m\": {:.3f}}},\n",
               s.lat_rad * io::kDegPerRad, s.lon_rad * io::kDegPerRad, s.height_m);
    fmt::print(out, "  \"time\": {{\"week\": {}, \"tow_s\": {:.9f}}},\n  \"time_correction_s\": {:.9f},\n", s.time.week,
               s.time.tow_s, s.time_correction_s);
    fmt::print(out, "  \"clock_bias_m\": {:.3f},\n  \"clock_drift_mps\": {:.3f},\n", s.clock_bias_m, s.clock_drift_mps);
    fmt::print(out, "  \"velocity_ecef_mps\": {},\n",
               s.velocity_valid ? fmt::format("[{:.3f}, {:.3f}, {:.3f}]", s.v_e_mps.x(), s.v_e_mps.y(), s.v_e_mps.z())
                                : "null");
    fmt::print(out,
               "  \"sigma\": {{\"east_m\": {:.3f}, \"north_m\": {:.3f}, \"up_m\": {:.3f}, \"clock_m\": {:.3f}, "
               "\"time_s\": {:.9f}}},\n",
               s.sigma_enu_m.x(), s.sigma_enu_m.y(), s.sigma_enu_m.z(), s.sigma_clock_m, s.sigma_time_s);
    // 95 % of a 3-D Gaussian error lies within sqrt(7.81) = 2.8 times the root of the summed variances.
    fmt::print(out, "  \"error_bound_3d_95_m\": {:.3f},\n", 2.8 * s.sigma_enu_m.norm());
    fmt::print(out,
               "  \"residual_test\": {{\"statistic\": {:.3f}, \"threshold\": {}, \"residual_rms_m\": {:.3f}, "
               "\"doppler_statistic\": {:.3f}}},\n",
               s.test_statistic, number_or_null(s.test_threshold), s.residual_rms_m, s.doppler_statistic);
  } else {
    fmt::print(out, "  \"ecef_m\": null,\n  \"llh\": null,\n  \"time\": null,\n");
  }
  fmt::print(out, "  \"doppler_fix_ecef_m\": {},\n",
             s.doppler_fix_r_e_m ? fmt::format("[{:.1f}, {:.1f}, {:.1f}]", s.doppler_fix_r_e_m->x(),
                                               s.doppler_fix_r_e_m->y(), s.doppler_fix_r_e_m->z())
                                 : "null");
  fmt::print(out, "  \"candidates_tried\": {},\n  \"distinct_solutions\": {},\n", s.candidates_tried,
             s.distinct_solutions);
  fmt::print(out, "  \"satellites_used\": {},\n  \"excluded_prns\": [", s.used);
  for (std::size_t i = 0; i < s.excluded_prns.size(); ++i) fmt::print(out, "{}{}", i ? ", " : "", s.excluded_prns[i]);
  fmt::print(out, "],\n  \"without_ephemeris\": [");
  for (std::size_t i = 0; i < r.without_ephemeris.size(); ++i)
    fmt::print(out, "{}{}", i ? ", " : "", r.without_ephemeris[i]);
  fmt::print(out, "],\n  \"satellites\": [");
  for (std::size_t i = 0; i < r.detections.size(); ++i) {
    const auto& d = r.detections[i];
    const receiver::SnapshotSatellite* sat = nullptr;
    for (const auto& x : s.satellites)
      if (x.prn == d.prn) sat = &x;
    fmt::print(out,
               "{}\n    {{\"prn\": {}, \"cn0_dbhz\": {:.1f}, \"doppler_hz\": {:.2f}, \"code_phase_chips\": {:.4f}, "
               "\"code_sigma_m\": {:.2f}",
               i ? "," : "", d.prn, d.cn0_dbhz, d.doppler_hz, d.code_phase_chips, d.code_sigma_chips * 293.0522);
    if (sat)
      fmt::print(out,
                 ", \"used\": {}, \"elevation_deg\": {:.2f}, \"azimuth_deg\": {:.2f}, \"residual_m\": {:.3f}, "
                 "\"sigma_m\": {:.3f}, \"doppler_residual_hz\": {:.2f}",
                 sat->used, sat->elevation_rad * io::kDegPerRad, sat->azimuth_rad * io::kDegPerRad, sat->residual_m,
                 sat->sigma_m, sat->doppler_residual_hz);
    else
      fmt::print(out, ", \"used\": false");
    fmt::print(out, "}}");
  }
  fmt::print(out, "\n  ],\n  \"wall_time_s\": {:.3f}\n}}\n", wall_s);
  file.commit();
}

}  // namespace

void write_snapshot_outputs(const std::filesystem::path& dir, const SnapshotFileJob& job,
                            const SnapshotFileResult& result, const std::string& format_label, double wall_s) {
  std::filesystem::create_directories(dir);
  write_snapshot_json(dir / "snapshot.json", job, result, format_label, wall_s);
  const receiver::SnapshotSolution& solution = result.solution;
  receiver::SolutionCsvWriter csv(dir / "solution.csv");
  if (result.solution.valid) {
    receiver::PvtSolution fix;
    fix.valid = true;
    fix.time = solution.time;
    fix.r_e_m = solution.r_e_m;
    fix.lat_rad = solution.lat_rad;
    fix.lon_rad = solution.lon_rad;
    fix.height_m = solution.height_m;
    fix.clock_bias_m = solution.clock_bias_m;
    fix.clock_drift_mps = solution.clock_drift_mps;
    for (const auto& s : solution.satellites)
      if (s.used) fix.used_prns.push_back(s.prn);
    if (!solution.excluded_prns.empty()) fix.excluded_prn = solution.excluded_prns.front();
    csv.write(fix);
  }
  csv.finish();
}

}  // namespace ultratrack::pipelines
