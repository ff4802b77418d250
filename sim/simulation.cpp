// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/simulation.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "ins/earth_model.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "signals/gps_constants.hpp"
#include "sim/imu_simulation.hpp"
#include "sim/navigation_source.hpp"
#include "sim/scenario_models.hpp"

namespace ultratrack::sim {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The inertial part of a run: IMU rows (and odometer samples) to the sink, truth kept for interpolation.
std::shared_ptr<const ins::TruthInterpolator> run_inertial(const Scenario& s, SimulationSink& sink,
                                                           SimulationResult& result) {
  const ins::TrajectorySpec spec = trajectory_spec(s);
  if (s.signal && spec.duration_s() < s.duration_s - 1e-9) {
    throw io::InputError(s.source.string(), fmt::format("the trajectory lasts {} s but [signal] duration_s is {} s",
                                                        spec.duration_s(), s.duration_s));
  }
  std::vector<ins::TruthSample> samples;
  samples.reserve(static_cast<std::size_t>(std::llround(spec.duration_s() * s.imu_rate_hz)) + 1);
  ImuSimulationCallbacks callbacks;
  callbacks.on_imu = [&](const ins::ImuIncrement& inc) {
    ins::ImuIncrement stamped = inc;
    stamped.t_s += s.imu_time_offset_s;  // the IMU's clock, not true time
    sink.imu(stamped);
  };
  callbacks.on_truth = [&](const ins::TruthSample& t) { samples.push_back(t); };
  std::optional<ins::ImuIncrement> pending_imu;  // held until the next truth sample gives the sideslip
  double previous_sideslip_rad = 0.0;
  if (s.odometer_misalignment_pitch_deg != 0.0 || s.odometer_misalignment_yaw_deg != 0.0 ||
      s.sideslip_deg_per_mps2 != 0.0) {
    // The trajectory moves a track frame (x along the velocity). The vehicle yaws from it by its sideslip
    // beta = gradient * lateral acceleration (positive: the nose right of the track), and the IMU is
    // mounted rotated from the vehicle: C_bt = C_bv Rz(beta)'. The increments and the truth attitude are the
    // track's rotated into the IMU frame, the gyro's also turning with beta (no lever arm between the frames).
    const Eigen::Matrix3d C_bv = ins::C_bv_from_misalignment(s.odometer_misalignment_pitch_deg * io::kRadPerDeg,
                                                             s.odometer_misalignment_yaw_deg * io::kRadPerDeg);
    const double gradient = s.sideslip_deg_per_mps2 * io::kRadPerDeg;
    auto C_bt = [C_bv](double beta) {
      return Eigen::Matrix3d(C_bv * Eigen::AngleAxisd(beta, Eigen::Vector3d::UnitZ()).toRotationMatrix().transpose());
    };
    callbacks.on_imu = [&pending_imu](const ins::ImuIncrement& inc) { pending_imu = inc; };
    callbacks.on_truth = [&, C_bv, C_bt, gradient](const ins::TruthSample& t) {
      // The track's turn rate about the vertical (the body rate in NED less the earth rate's down part).
      const double turn_rate = (t.q_nb * t.w_ib_b).z() + ins::kEarthRate_rps * std::sin(t.lat_rad);
      const double lateral_accel = t.v_n.head<2>().norm() * turn_rate;
      const double beta = gradient * lateral_accel;
      if (pending_imu) {
        const Eigen::Matrix3d C = C_bt(0.5 * (beta + previous_sideslip_rad));
        ins::ImuIncrement r = *pending_imu;
        r.dtheta_b = C * pending_imu->dtheta_b + C_bv * Eigen::Vector3d(0.0, 0.0, beta - previous_sideslip_rad);
        r.dv_b = C * pending_imu->dv_b;
        r.t_s += s.imu_time_offset_s;  // the IMU's clock, not true time
        sink.imu(r);
        pending_imu.reset();
      }
      previous_sideslip_rad = beta;
      const Eigen::Matrix3d C = C_bt(beta);
      samples.push_back(t);
      samples.back().q_nb = (t.q_nb * Eigen::Quaterniond(C.transpose())).normalized();
      samples.back().w_ib_b = C * t.w_ib_b;
      samples.back().f_b = C * t.f_b;
    };
  }
  callbacks.on_progress = [&](int percent) { sink.progress({SimulationProgress::Stage::Imu, percent, 0.0, 0.0, 0.0}); };
  const ImuSimulationResult imu = simulate_imu(spec, s.imu_rate_hz, imu_error_spec(s), s.imu_seed, callbacks);
  if (s.odometer) {
    ins::OdometerOptions odo;
    odo.scale_factor_error = s.odometer_scale_factor_error;
    odo.delay_s = s.odometer_delay_s;
    odo.slips = s.odometer_slips;
    sink.odometer(ins::simulate_odometer(samples, odo));
  }
  result.imu_rows = imu.imu_rows;
  result.imu_turn_on = imu.turn_on;
  result.distance_m = imu.distance_m;
  result.trajectory_duration_s = spec.duration_s();
  return std::make_shared<ins::TruthInterpolator>(std::move(samples));
}

TruthRow imu_truth_row(const ins::TruthInterpolator& truth, double t_r) {
  const ins::EcefMotion m = truth.antenna(t_r, Eigen::Vector3d::Zero());
  TruthRow row;
  row.r_e_m = m.r_e;
  row.v_e_mps = m.v_e;
  row.q_nb = truth.attitude(t_r);
  return row;
}

// Inertial scenario without a signal: truth rows at GPS time since the start, the deterministic clock model.
void truth_without_signal(const Scenario& s, const ins::TruthInterpolator& truth, SimulationSink& sink,
                          SimulationResult& result) {
  const signals::GpsTime start{s.gps_week, s.tow_s};
  const auto rows = static_cast<std::int64_t>(std::floor(result.trajectory_duration_s * s.truth_rate_hz + 1e-9));
  for (std::int64_t k = 0; k <= rows; ++k) {
    const double t = static_cast<double>(k) / s.truth_rate_hz;
    TruthRow row = imu_truth_row(truth, t);
    row.t_s = t;
    row.gps = signals::add_seconds(start, t);
    row.clock_bias_m = s.clock_bias_m + s.clock_drift_mps * t;
    row.clock_drift_mps = s.clock_drift_mps;
    sink.truth(row);
    ++result.truth_rows;
  }
}

// The injected events and C/N0 steps as the receiver should detect them.
void emit_events(const Scenario& s, const NavigationSource& nav, SimulationSink& sink) {
  std::vector<AntennaEventRow> events;
  for (const auto& e : s.cycle_slips)
    events.push_back({"slip", e.antenna, e.prn, e.time_s, e.time_s + e.fade_s, e.cycles});
  for (const auto& b : s.blockages)
    events.push_back({"blockage", b.antenna, 0, b.start_s, b.start_s + b.duration_s, 0.0});
  std::vector<Cn0StepRow> steps;
  for (const auto& c : s.cn0_steps) {
    const std::int64_t first = signals::cn0_step_first_sample(c, s.sample_rate_hz);
    for (const auto& eph : nav.ephemerides) {
      if (eph.health != 0 && !s.include_unhealthy) continue;
      if (!c.prns.empty() && std::find(c.prns.begin(), c.prns.end(), eph.prn) == c.prns.end()) continue;
      steps.push_back(
          {c.antenna, eph.prn, c.start_s, first, static_cast<double>(first) / s.sample_rate_hz, c.cn0_dbhz});
    }
  }
  sink.events(events, steps);
}

// The signal part: truth rows at receiver times k / truth_rate (sample-exact) interleaved with sample blocks of
// at most 10 ms that end at the next truth row, until the end or a stop request.
class SignalRun {
 public:
  SignalRun(const Scenario& s, signals::IfSynthesiser& synth, const signals::ReceiverMotion& motion,
            const ins::TruthInterpolator* inertial, SimulationSink& sink, Clock::time_point wall_start)
      : s_(s), synth_(synth), motion_(motion), inertial_(inertial), sink_(sink), wall_start_(wall_start) {}

  void run(std::stop_token stop, float to_file, SimulationResult& result) {
    const auto total = static_cast<std::int64_t>(std::llround(s_.duration_s * s_.sample_rate_hz));
    const int n_ant = synth_.antenna_count();
    const std::size_t chunk = static_cast<std::size_t>(std::max(1.0, std::round(s_.sample_rate_hz * 0.01)));
    std::vector<std::vector<std::complex<float>>> buffers(n_ant, std::vector<std::complex<float>>(chunk));
    std::vector<std::span<std::complex<float>>> spans(n_ant);
    std::int64_t next_truth = 0;
    int last_decile = 0;
    std::int64_t n = 0;
    while (n < total) {
      while (truth_sample(next_truth) <= n && truth_sample(next_truth) < total) {
        add_truth_row(truth_sample(next_truth++));
        ++result.truth_rows;
      }
      if (stop.stop_requested()) {
        result.interrupted = true;
        break;
      }
      const auto count = static_cast<std::size_t>(std::min<std::int64_t>(
          {static_cast<std::int64_t>(chunk), total - n, std::max<std::int64_t>(1, truth_sample(next_truth) - n)}));
      for (int a = 0; a < n_ant; ++a) spans[a] = std::span(buffers[a].data(), count);
      synth_.generate(spans);
      for (int a = 0; a < n_ant; ++a) {
        if (to_file != 1.0f)
          for (auto& x : spans[a]) x *= to_file;
        sink_.samples(a, spans[a]);
      }
      n += static_cast<std::int64_t>(count);
      const int decile = static_cast<int>(10 * n / total);
      if (decile > last_decile) {
        last_decile = decile;
        const double done_s = static_cast<double>(n) / s_.sample_rate_hz;
        sink_.progress(
            {SimulationProgress::Stage::Signal, decile * 10, done_s, s_.duration_s, seconds_since(wall_start_)});
      }
    }
    result.samples = n;
    result.signal_s = static_cast<double>(n) / s_.sample_rate_hz;
  }

 private:
  std::int64_t truth_sample(std::int64_t k) const {
    return static_cast<std::int64_t>(std::llround(static_cast<double>(k) * s_.sample_rate_hz / s_.truth_rate_hz));
  }

  void add_truth_row(std::int64_t n) {
    const double t_r = synth_.receive_time_s(n);
    const double t_s = static_cast<double>(n) / s_.sample_rate_hz;
    const auto clk = synth_.receiver_clock(n);
    TruthRow row;
    if (inertial_) {
      row = imu_truth_row(*inertial_, t_r);
    } else {
      const auto st = motion_.antenna_state(0, t_r);
      row.r_e_m = st.r_e_m;
      row.v_e_mps = st.v_e_mps;
    }
    row.t_s = t_s;
    row.gps = signals::add_seconds({s_.gps_week, s_.tow_s}, t_r);
    row.clock_bias_m = clk.bias_s * signals::kSpeedOfLight_mps;
    row.clock_drift_mps = clk.drift_sps * signals::kSpeedOfLight_mps;
    sink_.truth(row);
    sink_.satellite_truth(n, t_s, synth_.visible_satellites(n));
    if (!inertial_) return;
    for (int a = 0; a < synth_.antenna_count(); ++a) {
      const auto st = motion_.antenna_state(a, t_r);
      sink_.antenna_truth({t_s, a, st.r_e_m, st.v_e_mps});
    }
  }

  const Scenario& s_;
  signals::IfSynthesiser& synth_;
  const signals::ReceiverMotion& motion_;
  const ins::TruthInterpolator* inertial_;
  SimulationSink& sink_;
  Clock::time_point wall_start_;
};

}  // namespace

SimulationResult simulate(const Scenario& s, SimulationSink& sink, std::stop_token stop) {
  const auto wall_start = Clock::now();
  if (std::string why; !s.IsValid(&why)) throw io::InputError(s.source.string(), why);
  sink.begin({s.signal ? static_cast<int>(s.antenna_count()) : 0, s.trajectory_enabled()});
  SimulationResult result;
  if (!s.signal) {
    const auto truth = run_inertial(s, sink, result);
    truth_without_signal(s, *truth, sink, result);
    result.wall_s = seconds_since(wall_start);
    sink.finish(result);
    return result;
  }
  const NavigationSource nav = load_navigation(s);
  const auto options = synthesiser_options(s, nav);
  std::shared_ptr<const ins::TruthInterpolator> inertial;
  if (s.trajectory_enabled()) inertial = run_inertial(s, sink, result);
  const auto motion = make_motion(s, inertial);
  signals::IfSynthesiser synth(options, nav.ephemerides, motion);
  result.navigation = nav.name;
  result.antennas = synth.antenna_count();
  result.satellites = synth.visible_satellites(0);
  sink.satellites(result.satellites);
  emit_events(s, nav, sink);
  // 2-bit quantiser threshold (2 in file units, signals/sample_writer.hpp) at 1 sigma of the noise alone, the
  // minimum-loss setting, set from the noise because the signals (up to ~10 % of the power with ten
  // satellites at 45 dB-Hz and a few MHz) are not what the threshold should scale with.
  const float to_file = signals::is_two_bit(s.format) ? static_cast<float>(2.0 / synth.noise_sigma()) : 1.0f;
  result.noise_sigma = synth.noise_sigma() * to_file;
  SignalRun(s, synth, *motion, inertial.get(), sink, wall_start).run(stop, to_file, result);
  result.wall_s = seconds_since(wall_start);
  sink.finish(result);
  return result;
}

}  // namespace ultratrack::sim
