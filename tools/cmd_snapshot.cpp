// `ultratrack snapshot`: a position from a short recording (tens to hundreds of ms) with broadcast ephemerides and
// an approximate time: acquisition and fine code/Doppler of every satellite (receiver/snapshot_measurement.hpp),
// then coarse-time navigation (receiver/snapshot_navigation.hpp). Writes DIR/snapshot.json and DIR/solution.csv
// (one row, the receive command's columns).
// Exit: 0 fix; 2 bad input or no satellite detected (nothing written); 3 no fix (snapshot.json says why).
#include <fmt/core.h>
#include <fmt/ostream.h>

#include <CLI/CLI.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_parse.hpp"
#include "command_exit.hpp"
#include "commands.hpp"
#include "format_options.hpp"
#include "io/atomic_file.hpp"
#include "io/json_text.hpp"
#include "receiver/ionosphere_model.hpp"
#include "receiver/sample_source.hpp"
#include "receiver/snapshot_measurement.hpp"
#include "receiver/snapshot_navigation.hpp"
#include "receiver/solution_writer.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::tools {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

struct SnapshotArgs {
  std::string input, fs, if_hz = "0", nav, time, time_sigma = "10", approx_llh, ms = "100", out;
  std::string prns = "1-32", doppler_max = "5000", pfa = "1e-3", skip = "0", spacing = "0.5";
  FormatArgs format;
  bool iq_swap = false, q_negate = false, quiet = false;
};

// "WEEK:TOW" -> GpsTime (full week, TOW in [0, 604800)).
signals::GpsTime parse_time(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw signals::InputError("command line", "--time: expected WEEK:TOW (e.g. 2190:518403.5), got '" + text + "'");
  const int week = parse_int_option("--time (week)", text.substr(0, colon));
  const double tow = parse_double_option("--time (tow)", text.substr(colon + 1));
  if (week < 0 || !(tow >= 0.0 && tow < 604800.0))
    throw signals::InputError("command line", "--time: week must be >= 0 and TOW in [0, 604800)");
  return signals::GpsTime{week, tow};
}

// "LAT,LON,H" (degrees, degrees, metres) -> ECEF.
Eigen::Vector3d parse_llh(const std::string& text) {
  std::vector<double> v;
  std::size_t start = 0;
  while (true) {
    const auto comma = text.find(',', start);
    v.push_back(parse_double_option("--approx-llh", text.substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 3 || std::fabs(v[0]) > 90.0 || std::fabs(v[1]) > 360.0)
    throw signals::InputError("command line", "--approx-llh: expected LAT,LON,H in degrees and metres, got '" + text + "'");
  double x = 0, y = 0, z = 0;
  GeographicLib::Geocentric::WGS84().Forward(v[0], v[1], v[2], x, y, z);
  return {x, y, z};
}

std::string number_or_null(double v, const char* format = "{:.3f}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "null";
}

void write_snapshot_json(const std::filesystem::path& path, const SnapshotArgs& args, double fs_hz, double used_ms,
                         const signals::GpsTime& t0, const std::vector<receiver::SnapshotDetection>& detections,
                         const std::vector<int>& without_ephemeris, const receiver::SnapshotSolution& s,
                         const std::string& iono_model, double wall_s) {
  io::AtomicFile file(path);
  auto& out = file.stream();
  fmt::print(out, "{{\n  \"input\": {{\"file\": {}, \"format\": {}, \"fs_hz\": {}, \"if_hz\": {}, \"snapshot_ms\": {:.3f}}},\n",
             io::json_string(args.input), io::json_string(args.format.format), fs_hz, args.if_hz, used_ms);
  fmt::print(out, "  \"approximate_time\": {{\"week\": {}, \"tow_s\": {:.6f}, \"sigma_s\": {}}},\n", t0.week, t0.tow_s,
             args.time_sigma);
  fmt::print(out, "  \"valid\": {},\n  \"failure\": {},\n  \"quality\": {},\n  \"a_priori\": {},\n", s.valid,
             s.valid ? "null" : io::json_string(s.failure), io::json_string(s.quality), io::json_string(s.a_priori));
  fmt::print(out, "  \"ionosphere\": {},\n", io::json_string(iono_model));
  const bool solved = s.used >= 5;
  if (solved) {
    fmt::print(out, "  \"ecef_m\": [{:.3f}, {:.3f}, {:.3f}],\n", s.r_e_m.x(), s.r_e_m.y(), s.r_e_m.z());
    fmt::print(out, "  \"llh\": {{\"lat_deg\": {:.9f}, \"lon_deg\": {:.9f}, \"height_m\": {:.3f}}},\n", s.lat_rad * kDeg,
               s.lon_rad * kDeg, s.height_m);
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
  for (std::size_t i = 0; i < without_ephemeris.size(); ++i)
    fmt::print(out, "{}{}", i ? ", " : "", without_ephemeris[i]);
  fmt::print(out, "],\n  \"satellites\": [");
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const auto& d = detections[i];
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
                 sat->used, sat->elevation_rad * kDeg, sat->azimuth_rad * kDeg, sat->residual_m, sat->sigma_m,
                 sat->doppler_residual_hz);
    else
      fmt::print(out, ", \"used\": false");
    fmt::print(out, "}}");
  }
  fmt::print(out, "\n  ],\n  \"wall_time_s\": {:.3f}\n}}\n", wall_s);
  file.commit();
}

void run_snapshot(const SnapshotArgs& args) {
  const auto started = std::chrono::steady_clock::now();
  const auto format = parse_format(args.format);
  receiver::SampleSourceOptions source_options =
      parse_sample_source_options(args.format, args.fs, args.if_hz, args.iq_swap, args.q_negate);
  const double skip_s = parse_double_option("--skip", args.skip);
  if (!(skip_s >= 0.0)) throw signals::InputError("command line", "--skip must be >= 0");
  source_options.start_sample = std::llround(skip_s * source_options.fs_hz);
  const signals::GpsTime t0 = parse_time(args.time);
  receiver::SnapshotOptions options;
  options.time_sigma_s = parse_double_option("--time-sigma-s", args.time_sigma);
  const std::optional<Eigen::Vector3d> approx =
      args.approx_llh.empty() ? std::nullopt : std::optional<Eigen::Vector3d>(parse_llh(args.approx_llh));
  const double ms = parse_double_option("--ms", args.ms);
  if (!(ms >= 2.0 && ms <= 10000.0)) throw signals::InputError("command line", "--ms must be in [2, 10000]");
  receiver::SnapshotSearchOptions search;
  search.fs_hz = source_options.fs_hz;
  search.doppler_max_hz = parse_double_option("--doppler-max", args.doppler_max);
  search.pfa = parse_double_option("--pfa", args.pfa);
  search.spacing_chips = parse_double_option("--spacing-chips", args.spacing);
  const std::vector<int> prns = parse_prn_list_option("--prn", args.prns);
  std::string why;
  if (!search.IsValid(&why)) throw signals::InputError("command line", why);
  if (why = options.validate(); !why.empty()) throw signals::InputError("command line", why);

  const signals::RinexNavData nav = signals::read_rinex_nav(args.nav);
  if (nav.ephemerides.empty()) throw signals::InputError(args.nav, "holds no GPS ephemeris");
  options.klobuchar = nav.klobuchar.valid ? nav.klobuchar : receiver::default_klobuchar();
  const std::string iono_model = nav.klobuchar.valid ? "nav file Klobuchar" : "default Klobuchar (RTKLIB ion_default)";

  receiver::SampleSource source(args.input, format, source_options);
  const std::int64_t wanted = std::llround(ms * 1e-3 * source_options.fs_hz);
  const std::int64_t available = source.total_samples() - source_options.start_sample;
  std::vector<std::complex<float>> samples(static_cast<std::size_t>(std::max<std::int64_t>(0, std::min(wanted, available))));
  const receiver::SampleBlock got = source.read(samples);
  samples.resize(got.count);
  const double used_ms = static_cast<double>(samples.size()) / source_options.fs_hz * 1e3;
  if (used_ms < 10.0)
    throw signals::InputError(args.input, fmt::format("holds {:.1f} ms of signal after --skip; a snapshot needs >= 10 ms",
                                                      used_ms));
  if (available < wanted)
    fmt::print(stderr, "ultratrack snapshot: {} holds {:.1f} ms; using all of it instead of {:g} ms\n", args.input,
               used_ms, ms);

  const auto detections = receiver::measure_snapshot(samples, prns, search);
  if (detections.empty()) throw signals::InputError(args.input, "no satellite detected in the snapshot");
  std::vector<receiver::SnapshotMeasurement> measurements;
  std::vector<int> without_ephemeris;
  for (const auto& d : detections) {
    const auto eph = signals::select_ephemeris(nav.ephemerides, d.prn, t0);
    if (!eph) {
      without_ephemeris.push_back(d.prn);
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
  receiver::SnapshotSolution solution;
  if (measurements.size() < 5)
    solution.failure = fmt::format("{} satellites detected, {} with a healthy ephemeris at the time: at least 5 are needed",
                                   detections.size(), measurements.size());
  else
    solution = receiver::solve_snapshot(measurements, t0, approx, options);

  std::filesystem::create_directories(args.out);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  write_snapshot_json(std::filesystem::path(args.out) / "snapshot.json", args, source_options.fs_hz, used_ms, t0,
                      detections, without_ephemeris, solution, iono_model, wall_s);
  receiver::SolutionCsvWriter csv(std::filesystem::path(args.out) / "solution.csv");
  if (solution.valid) {
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
  if (!solution.valid) throw CommandExit(3, "ultratrack snapshot: no fix: " + solution.failure);
  if (args.quiet) return;
  fmt::print("{} satellites detected, {} used; ", detections.size(), solution.used);
  fmt::print("fix {:.7f} {:.7f} {:.1f} m, time correction {:+.3f} s, quality {} (residual rms {:.1f} m)\n",
             solution.lat_rad * kDeg, solution.lon_rad * kDeg, solution.height_m, solution.time_correction_s,
             solution.quality, solution.residual_rms_m);
}

}  // namespace

void add_snapshot_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "snapshot", "Position from a short recording (coarse-time navigation: ephemerides + approximate time)");
  auto args = std::make_shared<SnapshotArgs>();
  cmd->add_option("--input", args->input, "IF sample file")->required();
  add_format_options(cmd, args->format);
  cmd->add_option("--fs", args->fs, "sample rate, Hz")->required();
  cmd->add_option("--if", args->if_hz, "intermediate frequency, Hz (0: complex baseband)")->capture_default_str();
  cmd->add_option("--nav", args->nav, "RINEX navigation file (broadcast ephemerides)")->required();
  cmd->add_option("--time", args->time, "approximate GPS time of the snapshot's first sample, WEEK:TOW")->required();
  cmd->add_option("--time-sigma-s", args->time_sigma, "1-sigma of --time, s (solutions beyond 3 sigma are refused)")
      ->capture_default_str();
  cmd->add_option("--approx-llh", args->approx_llh,
                  "approximate position LAT,LON,H (deg, deg, m); without it a Doppler fix and a grid search");
  cmd->add_option("--ms", args->ms, "snapshot length, ms (the file's length when shorter)")->capture_default_str();
  cmd->add_option("--skip", args->skip, "seconds of the file to skip before the snapshot")->capture_default_str();
  cmd->add_option("--prn", args->prns, "PRNs to search, e.g. 1-32 or 3,7,12-15")->capture_default_str();
  cmd->add_option("--doppler-max", args->doppler_max, "Doppler search range +-, Hz")->capture_default_str();
  cmd->add_option("--pfa", args->pfa, "false-alarm probability per PRN")->capture_default_str();
  cmd->add_option("--spacing-chips", args->spacing, "early-late spacing of the fine code phase, chips (0, 1.5]")
      ->capture_default_str();
  cmd->add_flag("--iq-swap", args->iq_swap, "exchange I and Q (complex formats)");
  cmd->add_flag("--q-negate", args->q_negate, "negate Q (complex) / invert the spectrum (real IF)");
  cmd->add_option("--out", args->out, "output folder (snapshot.json, solution.csv)")->required();
  cmd->add_flag("--quiet", args->quiet, "no summary line on stdout");
  cmd->callback([args] { run_snapshot(*args); });
}

}  // namespace ultratrack::tools
