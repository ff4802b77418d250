// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/antenna_phase_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "signals/gps_constants.hpp"
#include "signals/look_angles.hpp"
#include "signals/satellite_state.hpp"

namespace ultratrack::receiver {
namespace {

// x wrapped to [-0.5, 0.5).
double wrap_cycles(double x) { return x - std::floor(x + 0.5); }

}  // namespace

AntennaPhaseTracker::AntennaPhaseTracker(int num_antennas, const AntennaPhaseTrackerOptions& options)
    : num_antennas_(num_antennas), options_(options) {
  if (num_antennas < 1 || num_antennas > kMaxAntennas)
    throw std::invalid_argument("AntennaPhaseTracker: 1..kMaxAntennas antennas");
}

void AntennaPhaseTracker::restart(State& s) {
  s.started = false;
  s.slip_pending = true;
}

void AntennaPhaseTracker::update(const CorrelationEpoch& e, bool master_locked, double fs_hz) {
  master_locked_ = master_locked;
  const std::complex<double> p0(e.antenna[0].prompt);
  const double power0 = std::norm(p0);
  const double dt = e.integration_time_s;
  const double a = std::min(1.0, dt / options_.cn0_time_constant_s);
  const double mid = static_cast<double>(e.first_sample) + 0.5 * static_cast<double>(e.num_samples);
  for (int k = 1; k < num_antennas_; ++k) {
    State& s = state_[static_cast<std::size_t>(k)];
    const std::complex<double> pk(e.antenna[static_cast<std::size_t>(k)].prompt);
    const double power_k = std::norm(pk);
    // Per-antenna C/N0 from the prompt and the noise tap (both over the same epoch): (P - N) / (N T).
    const double noise_k = std::norm(std::complex<double>(e.antenna[static_cast<std::size_t>(k)].noise));
    if (!s.have_power) {
      s.signal_power = power_k;
      s.noise_power = noise_k;
      s.master_power = power0;
      s.have_power = true;
    } else {
      s.signal_power += a * (power_k - s.signal_power);
      s.noise_power += a * (noise_k - s.noise_power);
      s.master_power += a * (power0 - s.master_power);
    }
    s.cn0_dbhz = NAN;
    if (s.noise_power > 0.0) {
      const double snr = std::max(1e-3, s.signal_power / s.noise_power - 1.0);
      s.cn0_dbhz = 10.0 * std::log10(snr / dt);
    }
    if (!master_locked || power0 <= 0.0) {
      restart(s);
      continue;
    }
    const double ratio = power_k / power0;
    if (ratio < options_.fade_power_ratio) {
      s.faded = true;
      s.good_epochs = 0;
      restart(s);
      continue;
    }
    if (s.faded) {
      if (ratio > options_.recover_power_ratio && ++s.good_epochs >= options_.recover_epochs) {
        s.faded = false;
      } else {
        if (ratio <= options_.recover_power_ratio) s.good_epochs = 0;
        continue;
      }
    }
    // RINEX sense: the synthesised/received carrier phase falls with range, the RINEX phase grows with it.
    const double measured = -std::arg(pk * std::conj(p0)) / (2.0 * M_PI);
    if (!s.started) {
      // Nearest to the last value: the integer is arbitrary after a restart (the slip flag says so).
      s.phase_cycles = s.phase_cycles + wrap_cycles(measured - s.phase_cycles);
      s.rate_hz = 0.0;
      s.sample_mid = mid;
      s.started = true;
      continue;
    }
    const double step_s = (mid - s.sample_mid) / fs_hz;
    const double predicted = s.phase_cycles + s.rate_hz * step_s;
    const double innovation = wrap_cycles(measured - predicted);
    if (std::abs(innovation) > options_.slip_threshold_cycles) {
      s.slip_pending = true;
      s.rate_hz = 0.0;
    } else if (step_s > 0.0) {
      s.rate_hz += options_.rate_gain * innovation / step_s;
    }
    s.phase_cycles = predicted + innovation;
    s.sample_mid = mid;
  }
}

AntennaPhaseSample AntennaPhaseTracker::peek(int k, std::int64_t sample_index, double fs_hz) const {
  if (k < 1 || k >= num_antennas_) throw std::out_of_range("AntennaPhaseTracker: antenna index");
  const State& s = state_[static_cast<std::size_t>(k)];
  AntennaPhaseSample out;
  out.cn0_dbhz = s.cn0_dbhz;
  out.power_ratio = s.master_power > 0.0 ? s.signal_power / s.master_power : 0.0;
  // Without a noise tap the fade test (power ratio) alone decides.
  out.usable = master_locked_ && s.started && !s.faded && !(s.cn0_dbhz < options_.min_cn0_dbhz);
  out.phase_cycles = s.phase_cycles + s.rate_hz * (static_cast<double>(sample_index) - s.sample_mid) / fs_hz;
  out.slip = s.slip_pending && out.usable;  // given with the first usable phase after the break
  return out;
}

AntennaPhaseSample AntennaPhaseTracker::report(int k, std::int64_t sample_index, double fs_hz) {
  const AntennaPhaseSample out = peek(k, sample_index, fs_hz);
  if (out.usable) state_[static_cast<std::size_t>(k)].slip_pending = false;
  return out;
}

AntennaPhaseObservation make_antenna_observation(AntennaPhaseTracker& tracker, int prn, double master_phase_cycles,
                                                 double master_cn0_dbhz, bool master_slip, double pseudorange_m,
                                                 const signals::Ephemeris& eph, const signals::GpsTime& receive_time,
                                                 double clock_bias_m, const Eigen::Vector3d& master_position_e,
                                                 std::int64_t sample_index, double fs_hz) {
  AntennaPhaseObservation o;
  o.prn = prn;
  o.num_antennas = tracker.num_antennas();
  o.carrier_phase_cycles[0] = master_phase_cycles;
  o.cn0_dbhz[0] = master_cn0_dbhz;
  o.slip[0] = master_slip;
  o.usable[0] = true;
  for (int k = 1; k < o.num_antennas; ++k) {
    const AntennaPhaseSample a = tracker.report(k, sample_index, fs_hz);
    const auto i = static_cast<std::size_t>(k);
    o.carrier_phase_cycles[i] = master_phase_cycles + a.phase_cycles;
    o.cn0_dbhz[i] =
        std::isnan(a.cn0_dbhz) ? master_cn0_dbhz + 10.0 * std::log10(std::max(a.power_ratio, 1e-6)) : a.cn0_dbhz;
    o.usable[i] = a.usable;
    // A new master track restarts the between-antenna trackers too (a new channel), so its slip covers all.
    o.slip[i] = a.slip || master_slip;
  }
  // Line of sight: the satellite at its transmit time, in the ECEF frame of the receive time.
  const double c = signals::kSpeedOfLight_mps;
  const double travel_s = (pseudorange_m - clock_bias_m) / c;
  const signals::GpsTime t_rx = signals::add_seconds(receive_time, -clock_bias_m / c);
  const auto sat = signals::satellite_state(eph, signals::add_seconds(t_rx, -travel_s));
  const Eigen::Vector3d r_sat = signals::rotate_to_receive_frame(sat.r_e_m, travel_s);
  o.los_e = (r_sat - master_position_e).normalized();
  o.elevation_rad = signals::look_angles(master_position_e, r_sat).elevation_rad;
  return o;
}

}  // namespace ultratrack::receiver
