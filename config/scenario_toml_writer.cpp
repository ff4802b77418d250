// SPDX-License-Identifier: GPL-3.0-or-later
// The writing half of config/scenario_toml.hpp: a sim::Scenario as TOML with every key written (defaults filled in,
// paths absolute, floats in their shortest round-trip form), so that reading it back gives the same scenario.
#include <fmt/core.h>
#include <fmt/format.h>

#include <filesystem>
#include <numbers>
#include <string>

#include "config/scenario_toml.hpp"
#include "ins/imu_datasheet.hpp"

namespace ultratrack::config {

using sim::Scenario;

namespace {

std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// Shortest round-trip text of a double, always with a decimal point or exponent (a TOML float).
std::string toml_float(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// A path of the scenario as an absolute TOML string (as given when it cannot be made absolute).
std::string absolute_toml_path(const Scenario& s, const std::string& p) {
  std::error_code ec;
  const auto a = std::filesystem::absolute(sim::resolve_path(s, p), ec);
  return toml_string(ec ? p : a.lexically_normal().string());
}

std::string signal_toml(const Scenario& s) {
  std::string out = "\n[signal]\n";
  out += fmt::format("sample_rate_hz = {}\nif_hz = {}\nformat = \"{}\"\nduration_s = {}\ncn0_dbhz = {}\nseed = {}\n",
                     toml_float(s.sample_rate_hz), toml_float(s.if_hz), signals::to_string(s.format),
                     toml_float(s.duration_s), toml_float(s.cn0_dbhz), s.seed);
  out += "cn0_dbhz_by_prn = {";
  bool first = true;
  for (const auto& [prn, cn0] : s.cn0_dbhz_by_prn) {
    out += fmt::format("{} {} = {}", first ? "" : ",", prn, toml_float(cn0));
    first = false;
  }
  out += first ? "}\n" : " }\n";
  out += fmt::format("nav_data = {}\nnoise = {}\n", s.nav_data, s.noise);
  // The other-generator conventions are written only when set, so that other echoes stay as they were.
  if (s.parameter_update_s != 1e-3) out += fmt::format("parameter_update_s = {}\n", toml_float(s.parameter_update_s));
  if (signals::is_two_bit(s.format))
    out += fmt::format("two_bit_coding = \"{}\"\ntwo_bit_order = \"{}\"\n", signals::to_string(s.two_bit.coding),
                       signals::to_string(s.two_bit.order));
  return out;
}

// [time], [navigation], [receiver], [atmosphere], [output].
std::string static_toml(const Scenario& s) {
  std::string out = fmt::format("\n[time]\ngps_week = {}\ntow_s = {}\n", s.gps_week, toml_float(s.tow_s));
  out += "\n[navigation]\n";
  if (!s.rinex.empty()) {
    out += "rinex = " + absolute_toml_path(s, s.rinex) + "\n";
  } else {
    out += "constellation = " + toml_string(s.constellation) + "\n";
  }
  out += fmt::format("elevation_mask_deg = {}\ninclude_unhealthy = {}\n", toml_float(s.elevation_mask_deg),
                     s.include_unhealthy);
  if (s.nav_field_rounding == signals::FieldRounding::kTowardZero) out += "field_rounding = \"toward_zero\"\n";
  if (s.nav_random_pages) out += "pages = \"random\"\n";
  out += "\n[receiver]\n";
  if (!s.trajectory.empty()) {
    out += "trajectory = " + absolute_toml_path(s, s.trajectory) + "\n";
  } else {
    out += fmt::format("llh_deg_m = [{}, {}, {}]\n", toml_float(s.llh_deg_m[0]), toml_float(s.llh_deg_m[1]),
                       toml_float(s.llh_deg_m[2]));
  }
  if (s.trajectory_profile == "static") {
    out += fmt::format("attitude_deg = [{}, {}, {}]\n", toml_float(s.attitude_deg[0]), toml_float(s.attitude_deg[1]),
                       toml_float(s.attitude_deg[2]));
  }
  if (s.trajectory.empty() && !s.trajectory_enabled()) {
    out += "antenna_offsets_enu_m = [";
    for (std::size_t i = 0; i < s.antenna_offsets_enu_m.size(); ++i) {
      const auto& o = s.antenna_offsets_enu_m[i];
      out += fmt::format("{}[{}, {}, {}]", i ? ", " : "", toml_float(o[0]), toml_float(o[1]), toml_float(o[2]));
    }
    out += "]\n";
  }
  out += fmt::format(
      "clock_bias_m = {}\nclock_drift_mps = {}\nclock_bias_noise_m_per_sqrt_s = {}\n"
      "clock_drift_noise_mps_per_sqrt_s = {}\n",
      toml_float(s.clock_bias_m), toml_float(s.clock_drift_mps), toml_float(s.clock_bias_noise_m_per_sqrt_s),
      toml_float(s.clock_drift_noise_mps_per_sqrt_s));
  out += fmt::format("\n[atmosphere]\nionosphere = {}\ntroposphere = {}\n", s.ionosphere, s.troposphere);
  out += fmt::format("\n[output]\ntruth_rate_hz = {}\n", toml_float(s.truth_rate_hz));
  return out;
}

// [trajectory], [imu], [[antenna]].
std::string inertial_toml(const Scenario& s) {
  std::string out = "\n[trajectory]\n";
  if (!s.trajectory_profile.empty()) {
    out += fmt::format("profile = {}\nduration_s = {}\n", toml_string(s.trajectory_profile),
                       toml_float(s.trajectory_duration_s));
  } else {
    out += fmt::format("file = {}\nspeed_mps = {}\nheading_deg = {}\ncoordinated_turns = {}\nramp_s = {}\n",
                       absolute_toml_path(s, s.trajectory_file), toml_float(s.start_speed_mps),
                       toml_float(s.start_heading_deg), s.coordinated_turns, toml_float(s.ramp_s));
  }
  out += fmt::format("imu_rate_hz = {}\nodometer = {}\nodometer_scale_factor_error = {}\n", toml_float(s.imu_rate_hz),
                     s.odometer, toml_float(s.odometer_scale_factor_error));
  // Written only when set, so that the echo of a scenario without them stays as it was.
  if (s.sideslip_deg_per_mps2 != 0.0)
    out += fmt::format("sideslip_deg_per_mps2 = {}\n", toml_float(s.sideslip_deg_per_mps2));
  if (s.odometer_delay_s != 0.0) out += fmt::format("odometer_delay_s = {}\n", toml_float(s.odometer_delay_s));
  if (s.odometer_misalignment_pitch_deg != 0.0 || s.odometer_misalignment_yaw_deg != 0.0)
    out += fmt::format("odometer_misalignment_pitch_deg = {}\nodometer_misalignment_yaw_deg = {}\n",
                       toml_float(s.odometer_misalignment_pitch_deg), toml_float(s.odometer_misalignment_yaw_deg));
  out += fmt::format("\n[imu]\npreset = {}\nseed = {}\n", toml_string(s.imu_preset), s.imu_seed);
  if (s.imu_time_offset_s != 0.0) out += fmt::format("time_offset_s = {}\n", toml_float(s.imu_time_offset_s));
  for (const auto& key : ins::imu_datasheet_keys())
    if (const auto& value = s.imu_datasheet.*(key.member))
      out += fmt::format("{} = {}\n", key.name, toml_float(*value));
  for (std::size_t i = 0; i < s.lever_arms_body_m.size(); ++i) {
    const auto& l = s.lever_arms_body_m[i];
    out += fmt::format("\n[[antenna]]\nlever_arm_body_m = [{}, {}, {}]\n", toml_float(l[0]), toml_float(l[1]),
                       toml_float(l[2]));
    // Written only when set, so that the echo of a scenario without them stays as it was.
    if (i < s.antenna_impairments.size() &&
        (s.antenna_impairments[i].line_bias_cycles != 0.0 || s.antenna_impairments[i].phase_noise_m != 0.0))
      out += fmt::format("line_bias_cycles = {}\nphase_noise_m = {}\n",
                         toml_float(s.antenna_impairments[i].line_bias_cycles),
                         toml_float(s.antenna_impairments[i].phase_noise_m));
  }
  return out;
}

std::string events_toml(const Scenario& s) {
  std::string out;
  for (const auto& e : s.cycle_slips)
    out += fmt::format("\n[[cycle_slip]]\nantenna = {}\nprn = {}\ntime_s = {}\ncycles = {}\nfade_s = {}\n", e.antenna,
                       e.prn, toml_float(e.time_s), toml_float(e.cycles), toml_float(e.fade_s));
  for (const auto& o : s.odometer_slips)
    out += fmt::format("\n[[odometer_slip]]\nstart_s = {}\nduration_s = {}\nratio = {}\n", toml_float(o.start_s),
                       toml_float(o.duration_s), toml_float(o.ratio));
  constexpr double kDegPerRad = 180.0 / std::numbers::pi;
  for (const auto& v : s.vibrations)
    out += fmt::format(
        "\n[[vibration]]\nfrequency_hz = {}\naccel_amplitude_mps2 = [{}, {}, {}]\nangle_amplitude_deg = [{}, {}, {}]\n"
        "phase_deg = {}\n",
        toml_float(v.frequency_hz), toml_float(v.accel_amplitude_n_mps2[0]), toml_float(v.accel_amplitude_n_mps2[1]),
        toml_float(v.accel_amplitude_n_mps2[2]), toml_float(v.angle_amplitude_rad[0] * kDegPerRad),
        toml_float(v.angle_amplitude_rad[1] * kDegPerRad), toml_float(v.angle_amplitude_rad[2] * kDegPerRad),
        toml_float(v.phase_rad * kDegPerRad));
  for (const auto& b : s.blockages)
    out += fmt::format("\n[[blockage]]\nantenna = {}\nstart_s = {}\nduration_s = {}\n", b.antenna,
                       toml_float(b.start_s), toml_float(b.duration_s));
  for (const auto& c : s.cn0_steps) {
    out += fmt::format("\n[[cn0_step]]\nantenna = {}\nstart_s = {}\ncn0_dbhz = {}\n", c.antenna, toml_float(c.start_s),
                       toml_float(c.cn0_dbhz));
    if (!c.prns.empty()) out += fmt::format("prns = [{}]\n", fmt::join(c.prns, ", "));
  }
  return out;
}

}  // namespace

std::string to_toml(const Scenario& s) {
  std::string out = "# Scenario as run by `ultratrack simulate` (every key, defaults filled in).\n";
  if (s.signal) out += signal_toml(s);
  out += static_toml(s);
  if (s.trajectory_enabled()) out += inertial_toml(s);
  return out + events_toml(s);
}

}  // namespace ultratrack::config
