#include "simulation.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <csignal>
#include <numbers>
#include <optional>
#include <span>
#include <stdexcept>

#include "imu_simulation.hpp"
#include "ins/attitude.hpp"
#include "ins_motion.hpp"
#include "io/atomic_file.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/input_error.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/sample_writer.hpp"
#include "io/json_text.hpp"

namespace ultratrack::tools {
namespace {

using signals::InputError;
constexpr double kDeg = std::numbers::pi / 180.0;

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_sigint(int) { g_interrupted = 1; }

// Installs the Ctrl-C handler for the lifetime of a run and restores the previous one.
class SigintGuard {
 public:
  SigintGuard() {
    g_interrupted = 0;
    previous_ = std::signal(SIGINT, on_sigint);
  }
  ~SigintGuard() { std::signal(SIGINT, previous_ == SIG_ERR ? SIG_DFL : previous_); }

 private:
  void (*previous_)(int) = SIG_DFL;
};

// Rows of ECEF -> local frame rotations at a geodetic position.
Eigen::Matrix3d ned_from_ecef(double lat_rad, double lon_rad) {
  const double sl = std::sin(lat_rad), cl = std::cos(lat_rad), so = std::sin(lon_rad), co = std::cos(lon_rad);
  Eigen::Matrix3d C;
  C << -sl * co, -sl * so, cl, -so, co, 0.0, -cl * co, -cl * so, -sl;
  return C;
}

}  // namespace

NavigationSource load_navigation(const Scenario& s) {
  NavigationSource nav;
  const signals::GpsTime start{s.gps_week, s.tow_s};
  std::vector<signals::Ephemeris> sets;
  if (!s.rinex.empty()) {
    const auto path = resolve_path(s, s.rinex);
    auto data = signals::read_rinex_nav(path);
    nav.name = path.string();
    sets = std::move(data.ephemerides);
    nav.klobuchar = data.klobuchar;
    nav.utc = data.utc;
  } else {
    auto c = signals::nominal_constellation(start);
    nav.name = "nominal";
    sets = std::move(c.ephemerides);
    nav.klobuchar = c.klobuchar;
    nav.utc = c.utc;
  }
  signals::EphemerisSelectionOptions opt;
  opt.include_unhealthy = s.include_unhealthy;
  for (int prn = signals::kMinPrn; prn <= signals::kMaxPrn; ++prn)
    if (auto e = signals::select_ephemeris(sets, prn, start, opt)) nav.ephemerides.push_back(*e);
  if (nav.ephemerides.empty()) {
    throw InputError(nav.name, fmt::format("no ephemeris is valid at GPS week {} tow {} s (scenario {})", s.gps_week,
                                           s.tow_s, s.source.string()));
  }
  return nav;
}

ins::TrajectorySpec trajectory_spec(const Scenario& s) {
  if (!s.trajectory_enabled()) throw InputError(s.source.string(), "the scenario has no [trajectory]");
  const double lat = s.llh_deg_m[0] * kDeg, lon = s.llh_deg_m[1] * kDeg, h = s.llh_deg_m[2];
  ins::TrajectorySpec spec;
  if (!s.trajectory_profile.empty()) {
    try {
      spec = ins::profile_spec(s.trajectory_profile, s.trajectory_duration_s, lat, lon, h);
    } catch (const InputError& e) {
      throw InputError(s.source.string(), std::string("[trajectory]: ") + e.what());
    }
    if (s.trajectory_profile == "static") {
      spec.roll0_rad = s.attitude_deg[0] * kDeg;
      spec.pitch0_rad = s.attitude_deg[1] * kDeg;
      spec.heading0_rad = s.attitude_deg[2] * kDeg;
    }
  } else {
    ins::TrajectorySpec start;
    start.lat0_rad = lat;
    start.lon0_rad = lon;
    start.height0_m = h;
    start.speed0_mps = s.start_speed_mps;
    start.heading0_rad = s.start_heading_deg * kDeg;
    start.coordinated_turns = s.coordinated_turns;
    start.ramp_s = s.ramp_s;
    const auto file = resolve_path(s, s.trajectory_file);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      throw InputError(s.source.string(), "key trajectory.file: no such segment file " + file.string());
    spec = ins::read_segments_csv(file, start);  // errors in the file name it and the line
  }
  return spec;
}

ins::ImuErrorSpec imu_error_spec(const Scenario& s) {
  ins::ImuErrorSpec e;
  try {
    e = ins::imu_preset(s.imu_preset);
  } catch (const InputError& err) {
    throw InputError(s.source.string(), std::string("[imu]: ") + err.what());
  }
  constexpr double kDph = kDeg / 3600.0;  // deg/h -> rad/s
  constexpr double kDpsh = kDeg / 60.0;   // deg/sqrt(h) -> rad/sqrt(s)
  constexpr double kMg = 9.80665e-3;      // milli-g -> m/s^2
  if (s.gyro_bias_dph) e.gyro.bias_sigma = *s.gyro_bias_dph * kDph;
  if (s.accel_bias_mg) e.accel.bias_sigma = *s.accel_bias_mg * kMg;
  if (s.gyro_arw_dpsh) e.gyro.random_walk = *s.gyro_arw_dpsh * kDpsh;
  if (s.accel_vrw_mpspsh) e.accel.random_walk = *s.accel_vrw_mpspsh / 60.0;  // m/s/sqrt(h) -> m/s/sqrt(s)
  return e;
}

std::shared_ptr<const signals::ReceiverMotion> make_motion(const Scenario& s,
                                                           std::shared_ptr<const ins::TruthInterpolator> truth) {
  if (s.trajectory_enabled()) {
    if (!truth) throw std::invalid_argument("make_motion: an inertial scenario needs its truth");
    std::vector<Eigen::Vector3d> levers;
    for (const auto& l : s.lever_arms_body_m) levers.emplace_back(l[0], l[1], l[2]);
    return std::make_shared<InsTruthMotion>(std::move(truth), std::move(levers));
  }
  if (!s.trajectory.empty()) {
    const auto path = resolve_path(s, s.trajectory);
    auto samples = signals::read_trajectory_csv(path);
    if (samples.front().t_s > 1e-9 || samples.back().t_s < s.duration_s - 1e-9) {
      throw InputError(path.string(),
                       fmt::format("the trajectory covers t = {} .. {} s but the scenario needs 0 .. {} s",
                                   samples.front().t_s, samples.back().t_s, s.duration_s));
    }
    return std::make_shared<signals::TrajectoryMotion>(std::move(samples));
  }
  Eigen::Vector3d r0;
  GeographicLib::Geocentric::WGS84().Forward(s.llh_deg_m[0], s.llh_deg_m[1], s.llh_deg_m[2], r0.x(), r0.y(), r0.z());
  const Eigen::Matrix3d C_ned_e = ned_from_ecef(s.llh_deg_m[0] * kDeg, s.llh_deg_m[1] * kDeg);
  std::vector<Eigen::Vector3d> antennas;
  for (const auto& o : s.antenna_offsets_enu_m) {
    const Eigen::Vector3d d_ned(o[1], o[0], -o[2]);
    antennas.push_back(r0 + C_ned_e.transpose() * d_ned);
  }
  return std::make_shared<signals::StaticMotion>(std::move(antennas));
}

signals::SynthesiserOptions synthesiser_options(const Scenario& s, const NavigationSource& nav) {
  signals::SynthesiserOptions o;
  o.sample_rate_hz = s.sample_rate_hz;
  o.if_hz = s.if_hz;
  o.real_output = !signals::is_complex(s.format);
  // Automatic gain: noise plus signals at RMS = full scale / 4 per component (clipping beyond 4 sigma); the
  // 2-bit formats rescale to the noise alone in run_simulation (quantiser threshold at 1 noise sigma).
  o.output_rms = signals::nominal_rms(s.format);
  o.start = {s.gps_week, s.tow_s};
  o.default_cn0_dbhz = s.cn0_dbhz;
  o.cn0_dbhz_by_prn = s.cn0_dbhz_by_prn;
  o.elevation_mask_rad = s.elevation_mask_deg * kDeg;
  o.include_unhealthy = s.include_unhealthy;
  o.ionosphere = s.ionosphere;
  o.troposphere = s.troposphere;
  o.klobuchar = nav.klobuchar;
  o.utc = nav.utc;
  o.nav_data = s.nav_data;
  o.noise = s.noise;
  o.clock.bias_s = s.clock_bias_m / signals::kSpeedOfLight_mps;
  o.clock.drift_sps = s.clock_drift_mps / signals::kSpeedOfLight_mps;
  o.clock.bias_noise_s_per_sqrt_s = s.clock_bias_noise_m_per_sqrt_s / signals::kSpeedOfLight_mps;
  o.clock.drift_noise_sps_per_sqrt_s = s.clock_drift_noise_mps_per_sqrt_s / signals::kSpeedOfLight_mps;
  o.seed = s.seed;
  o.antenna_impairments = s.antenna_impairments;
  o.cycle_slips = s.cycle_slips;
  o.blockages = s.blockages;
  o.cn0_steps = s.cn0_steps;
  if (const auto err = signals::validate(o); !err.empty()) throw InputError(s.source.string(), err);
  return o;
}

namespace {

// The inertial part of a run: imu.csv (and odometer.csv) written, truth kept for interpolation.
struct InertialRun {
  std::shared_ptr<const ins::TruthInterpolator> truth;
  ImuSimulationResult imu;
  double duration_s = 0.0;
};

InertialRun run_inertial(const Scenario& s, const std::filesystem::path& out_dir) {
  const ins::TrajectorySpec spec = trajectory_spec(s);
  if (s.signal && spec.duration_s() < s.duration_s - 1e-9) {
    throw InputError(s.source.string(), fmt::format("the trajectory lasts {} s but [signal] duration_s is {} s",
                                                    spec.duration_s(), s.duration_s));
  }
  std::vector<ins::TruthSample> samples;
  samples.reserve(static_cast<std::size_t>(std::llround(spec.duration_s() * s.imu_rate_hz)) + 1);
  InertialRun run;
  run.imu = simulate_imu(
      spec, s.imu_rate_hz, imu_error_spec(s), s.imu_seed, out_dir / "imu.csv",
      [&](const ins::TruthSample& t) { samples.push_back(t); }, "simulate");
  if (s.odometer) write_odometer_csv(out_dir / "odometer.csv", samples, s.odometer_scale_factor_error);
  run.duration_s = spec.duration_s();
  run.truth = std::make_shared<ins::TruthInterpolator>(std::move(samples));
  return run;
}

const char* const kTruthHeader =
    "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
    "clock_bias_m,clock_drift_mps";

// One truth.csv row: t_s on its line, true GPS time, position/velocity, clock, attitude when known.
std::string truth_row(double t_s, const signals::GpsTime& gps, const signals::AntennaState& st, double clock_bias_m,
                      double clock_drift_mps, const Eigen::Quaterniond* q_nb) {
  double lat = 0, lon = 0, h = 0;
  GeographicLib::Geocentric::WGS84().Reverse(st.r_e_m.x(), st.r_e_m.y(), st.r_e_m.z(), lat, lon, h);
  const Eigen::Vector3d v_n = ned_from_ecef(lat * kDeg, lon * kDeg) * st.v_e_mps;
  std::string row =
      fmt::format("{:.9f},{},{:.9f},{:.4f},{:.4f},{:.4f},{:.10f},{:.10f},{:.4f},{:.5f},{:.5f},{:.5f},{:.5f},{:.6f}",
                  t_s, gps.week, gps.tow_s, st.r_e_m.x(), st.r_e_m.y(), st.r_e_m.z(), lat, lon, h, v_n.x(), v_n.y(),
                  v_n.z(), clock_bias_m, clock_drift_mps);
  if (q_nb) {
    const ins::EulerAngles e = ins::euler_from_quaternion(*q_nb);
    row += fmt::format(",{:.8f},{:.8f},{:.8f}", e.roll_rad / kDeg, e.pitch_rad / kDeg, e.yaw_rad / kDeg);
  }
  return row + "\n";
}

signals::AntennaState imu_state(const ins::TruthInterpolator& truth, double t_s) {
  const ins::EcefMotion m = truth.antenna(t_s, Eigen::Vector3d::Zero());
  return {m.r_e, m.v_e};
}

std::string inertial_summary(const Scenario& s, const InertialRun& run) {
  std::string levers;
  for (const auto& l : s.lever_arms_body_m)
    levers += fmt::format("{}[{}, {}, {}]", levers.empty() ? "" : ", ", l[0], l[1], l[2]);
  return fmt::format(
             "  \"trajectory\": \"{}\",\n  \"trajectory_duration_s\": {},\n  \"imu_rate_hz\": {},\n"
             "  \"imu_rows\": {},\n  \"imu_preset\": \"{}\",\n  \"imu_seed\": {},\n",
             io::json_escape(s.trajectory_profile.empty() ? s.trajectory_file : s.trajectory_profile), run.duration_s,
             s.imu_rate_hz, run.imu.imu_rows, io::json_escape(s.imu_preset), s.imu_seed) +
         turn_on_bias_json(run.imu.turn_on) +
         fmt::format("  \"lever_arms_body_m\": [{}],\n  \"distance_m\": {:.3f},\n  \"odometer\": {},\n", levers,
                     run.imu.distance_m, s.odometer);
}

// Inertial scenario without [signal]: IMU, truth (GPS time since the start) and the echo only.
SimulationResult run_inertial_only(const Scenario& s, const std::filesystem::path& out_dir,
                                   std::chrono::steady_clock::time_point wall_start) {
  const InertialRun run = run_inertial(s, out_dir);
  SimulationResult result;
  result.imu_rows = run.imu.imu_rows;
  std::string truth = std::string(kTruthHeader) + ",roll_deg,pitch_deg,yaw_deg\n";
  const signals::GpsTime start{s.gps_week, s.tow_s};
  const auto rows = static_cast<std::int64_t>(std::floor(run.duration_s * s.truth_rate_hz + 1e-9));
  for (std::int64_t k = 0; k <= rows; ++k) {
    const double t = static_cast<double>(k) / s.truth_rate_hz;
    const Eigen::Quaterniond q = run.truth->attitude(t);
    truth += truth_row(t, signals::add_seconds(start, t), imu_state(*run.truth, t),
                       s.clock_bias_m + s.clock_drift_mps * t, s.clock_drift_mps, &q);
    ++result.truth_rows;
  }
  io::write_file_atomically(out_dir / "truth.csv", truth);
  io::write_file_atomically(out_dir / "scenario.toml", to_toml(s));
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const std::string summary =
      fmt::format("{{\n  \"command\": \"simulate\",\n  \"scenario\": \"{}\",\n  \"signal\": false,\n",
                  io::json_escape(s.source.filename().string())) +
      inertial_summary(s, run) +
      fmt::format("  \"truth_rows\": {},\n  \"wall_s\": {:.3f}\n}}\n", result.truth_rows, result.wall_s);
  io::write_file_atomically(out_dir / "summary.json", summary);
  return result;
}

}  // namespace

SimulationResult run_simulation(const Scenario& s, const std::filesystem::path& out_dir, std::FILE* progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) throw InputError(out_dir.string(), "cannot create the output folder: " + ec.message());
  if (!s.signal) return run_inertial_only(s, out_dir, wall_start);

  const NavigationSource nav = load_navigation(s);
  const auto options = synthesiser_options(s, nav);
  std::optional<InertialRun> inertial;
  if (s.trajectory_enabled()) inertial = run_inertial(s, out_dir);
  auto motion = make_motion(s, inertial ? inertial->truth : nullptr);
  signals::IfSynthesiser synth(options, nav.ephemerides, motion);

  SimulationResult result;
  if (inertial) result.imu_rows = inertial->imu.imu_rows;
  const int n_ant = synth.antenna_count();
  std::vector<std::unique_ptr<signals::SampleWriter>> writers;
  for (int a = 0; a < n_ant; ++a) {
    const auto path = out_dir / fmt::format("antenna{}.{}.bin", a, signals::to_string(s.format));
    writers.push_back(std::make_unique<signals::SampleWriter>(path, s.format, s.two_bit));
    result.sample_files.push_back(path);
  }
  result.satellites = synth.visible_satellites(0);
  // 2-bit quantiser threshold (2 in file units, sample_writer.hpp) at 1 sigma of the noise alone, the
  // minimum-loss setting, set from the noise because the signals (up to ~10 % of the power with ten
  // satellites at 45 dB-Hz and a few MHz) are not what the threshold should scale with.
  const float to_file = signals::is_two_bit(s.format) ? static_cast<float>(2.0 / synth.noise_sigma()) : 1.0f;
  result.noise_sigma = synth.noise_sigma() * to_file;

  // Truth rows at receiver times k / truth_rate (sample-exact), CSV built in memory (small).
  std::string truth = std::string(kTruthHeader) + (inertial ? ",roll_deg,pitch_deg,yaw_deg\n" : "\n");
  std::string antenna_truth = "t_s,antenna,ecef_x_m,ecef_y_m,ecef_z_m,vel_x_mps,vel_y_mps,vel_z_mps\n";
  const auto total = static_cast<std::int64_t>(std::llround(s.duration_s * s.sample_rate_hz));
  const auto truth_sample = [&](std::int64_t k) {
    return static_cast<std::int64_t>(std::llround(static_cast<double>(k) * s.sample_rate_hz / s.truth_rate_hz));
  };
  const auto add_truth_row = [&](std::int64_t n) {
    const double t_r = synth.receive_time_s(n);
    const double t_s = static_cast<double>(n) / s.sample_rate_hz;
    const auto gps = signals::add_seconds(options.start, t_r);
    const auto clk = synth.receiver_clock(n);
    const double bias_m = clk.bias_s * signals::kSpeedOfLight_mps,
                 drift_mps = clk.drift_sps * signals::kSpeedOfLight_mps;
    if (inertial) {
      const Eigen::Quaterniond q = inertial->truth->attitude(t_r);
      truth += truth_row(t_s, gps, imu_state(*inertial->truth, t_r), bias_m, drift_mps, &q);
      for (int a = 0; a < n_ant; ++a) {
        const auto st = motion->antenna_state(a, t_r);
        antenna_truth += fmt::format("{:.9f},{},{:.4f},{:.4f},{:.4f},{:.5f},{:.5f},{:.5f}\n", t_s, a, st.r_e_m.x(),
                                     st.r_e_m.y(), st.r_e_m.z(), st.v_e_mps.x(), st.v_e_mps.y(), st.v_e_mps.z());
      }
    } else {
      truth += truth_row(t_s, gps, motion->antenna_state(0, t_r), bias_m, drift_mps, nullptr);
    }
    ++result.truth_rows;
  };

  const std::size_t chunk = static_cast<std::size_t>(std::max(1.0, std::round(s.sample_rate_hz * 0.01)));  // 10 ms
  std::vector<std::vector<std::complex<float>>> buffers(n_ant, std::vector<std::complex<float>>(chunk));
  std::vector<std::span<std::complex<float>>> spans(n_ant);
  SigintGuard sigint;
  std::int64_t next_truth = 0;
  int last_decile = 0;
  std::int64_t n = 0;
  while (n < total) {
    while (truth_sample(next_truth) <= n && truth_sample(next_truth) < total) add_truth_row(truth_sample(next_truth++));
    if (g_interrupted) {
      result.interrupted = true;
      break;
    }
    const auto count = static_cast<std::size_t>(std::min<std::int64_t>(
        {static_cast<std::int64_t>(chunk), total - n, std::max<std::int64_t>(1, truth_sample(next_truth) - n)}));
    for (int a = 0; a < n_ant; ++a) spans[a] = std::span(buffers[a].data(), count);
    synth.generate(spans);
    for (int a = 0; a < n_ant; ++a) {
      if (to_file != 1.0f)
        for (auto& x : spans[a]) x *= to_file;
      writers[a]->write(spans[a]);
    }
    n += static_cast<std::int64_t>(count);
    const int decile = static_cast<int>(10 * n / total);
    if (progress && decile > last_decile) {
      last_decile = decile;
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      const double done_s = static_cast<double>(n) / s.sample_rate_hz;
      fmt::print(progress, "simulate: {:5.1f} / {:.1f} s of signal ({:3d}%), {:.1f}x real time\n", done_s, s.duration_s,
                 decile * 10, done_s / std::max(wall, 1e-9));
      std::fflush(progress);
    }
  }
  for (auto& w : writers) w->finish();
  result.samples = n;
  result.signal_s = static_cast<double>(n) / s.sample_rate_hz;

  std::string sats = "prn,elevation_deg,azimuth_deg,cn0_dbhz,doppler_hz,code_phase_chips\n";
  for (const auto& v : result.satellites) {
    sats += fmt::format("{},{:.4f},{:.4f},{:.2f},{:.4f},{:.6f}\n", v.prn, v.elevation_rad / kDeg, v.azimuth_rad / kDeg,
                        v.cn0_dbhz, v.doppler_hz, v.code_phase_chips);
  }
  io::write_file_atomically(out_dir / "truth.csv", truth);
  if (inertial) io::write_file_atomically(out_dir / "antenna_truth.csv", antenna_truth);
  io::write_file_atomically(out_dir / "satellites.csv", sats);
  io::write_file_atomically(out_dir / "scenario.toml", to_toml(s));
  if (!s.cycle_slips.empty() || !s.blockages.empty()) {
    // The injected events as the receiver should detect them: prn 0 = every satellite; end_s = when the signal
    // is back (receiver time since the first sample).
    std::string events = "kind,antenna,prn,start_s,end_s,cycles\n";
    for (const auto& e : s.cycle_slips)
      events += fmt::format("slip,{},{},{},{},{}\n", e.antenna, e.prn, e.time_s, e.time_s + e.fade_s, e.cycles);
    for (const auto& b : s.blockages)
      events += fmt::format("blockage,{},0,{},{},0\n", b.antenna, b.start_s, b.start_s + b.duration_s);
    io::write_file_atomically(out_dir / "antenna_events.csv", events);
  }
  if (!s.cn0_steps.empty()) {
    // One row per step and transmitted satellite it applies to, in the scenario's order: the first sample with
    // the new level (sample-exact) and its receiver time.
    std::string steps = "antenna,prn,start_s,first_sample,first_sample_s,cn0_dbhz\n";
    for (const auto& c : s.cn0_steps) {
      const std::int64_t first = signals::cn0_step_first_sample(c, s.sample_rate_hz);
      for (const auto& eph : nav.ephemerides) {
        if (eph.health != 0 && !s.include_unhealthy) continue;
        if (!c.prns.empty() && std::find(c.prns.begin(), c.prns.end(), eph.prn) == c.prns.end()) continue;
        steps += fmt::format("{},{},{},{},{:.9f},{}\n", c.antenna, eph.prn, c.start_s, first,
                             static_cast<double>(first) / s.sample_rate_hz, c.cn0_dbhz);
      }
    }
    io::write_file_atomically(out_dir / "cn0_steps.csv", steps);
  }

  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  std::string prns, files;
  for (const auto& v : result.satellites) prns += fmt::format("{}{}", prns.empty() ? "" : ", ", v.prn);
  for (const auto& f : result.sample_files)
    files += fmt::format("{}\"{}\"", files.empty() ? "" : ", ", io::json_escape(f.filename().string()));
  const std::string summary =
      fmt::format("{{\n  \"command\": \"simulate\",\n  \"scenario\": \"{}\",\n  \"navigation\": \"{}\",\n",
                  io::json_escape(s.source.filename().string()),
                  io::json_escape(std::filesystem::path(nav.name).filename().string())) +
      (inertial ? inertial_summary(s, *inertial) : std::string()) +
      fmt::format(
          "  \"sample_rate_hz\": {},\n  \"if_hz\": {},\n  \"format\": \"{}\",\n  \"antennas\": {},\n"
          "  \"sample_files\": [{}],\n  \"samples_per_antenna\": {},\n  \"signal_s\": {},\n"
          "  \"satellites_in_view\": [{}],\n  \"noise_sigma_per_component\": {},\n  \"interrupted\": {},\n"
          "  \"wall_s\": {:.3f},\n  \"realtime_factor\": {:.3f}\n}}\n",
          s.sample_rate_hz, s.if_hz, signals::to_string(s.format), n_ant, files, result.samples, result.signal_s, prns,
          result.noise_sigma, result.interrupted, result.wall_s, result.signal_s / std::max(result.wall_s, 1e-9));
  io::write_file_atomically(out_dir / "summary.json", summary);
  return result;
}

}  // namespace ultratrack::tools
