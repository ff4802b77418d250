// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/fuse_config_toml.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "ins/imu_datasheet.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"

namespace ultratrack::config {
namespace {

struct Value {
  std::string file, key;
  const toml::node& node;

  int line() const { return static_cast<int>(node.source().begin.line); }
  double number() const {
    if (auto v = node.value<double>()) return *v;
    throw io::InputError(file, "key '" + key + "' must be a number", line());
  }
  double positive() const {
    const double v = number();
    if (!(v > 0.0)) throw io::InputError(file, "key '" + key + "' must be positive", line());
    return v;
  }
  double non_negative() const {
    const double v = number();
    if (!(v >= 0.0)) throw io::InputError(file, "key '" + key + "' must not be negative", line());
    return v;
  }
  bool boolean() const {
    if (auto v = node.value_exact<bool>()) return *v;
    throw io::InputError(file, "key '" + key + "' must be true or false", line());
  }
  std::int64_t integer() const {
    if (auto v = node.value_exact<std::int64_t>(); v && *v <= 1000000) return *v;
    throw io::InputError(file, "key '" + key + "' must be an integer (at most 1000000)", line());
  }
  int count() const {
    const std::int64_t n = integer();
    if (n < 1) throw io::InputError(file, "key '" + key + "' must be at least 1", line());
    return static_cast<int>(n);
  }
  std::string text() const {
    if (auto v = node.value<std::string>()) return *v;
    throw io::InputError(file, "key '" + key + "' must be a string", line());
  }
  Eigen::Vector3d vector3(bool positive_only = false) const {
    const auto* a = node.as_array();
    if (!a || a->size() != 3) throw io::InputError(file, "key '" + key + "' must be an array of 3 numbers", line());
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      const auto x = (*a)[static_cast<std::size_t>(i)].value<double>();
      if (!x) throw io::InputError(file, "key '" + key + "' must be an array of 3 numbers", line());
      if (positive_only && !(*x > 0.0)) throw io::InputError(file, "key '" + key + "' must be positive", line());
      v[i] = *x;
    }
    return v;
  }
};

using Table = std::map<std::string, std::function<void(const Value&, FuseConfig&)>>;

// [imu]: the preset and the datasheet keys of ins/imu_datasheet.hpp (the scenario's names).
Table imu_table() {
  Table t{{"preset",
           [](const Value& v, FuseConfig& c) {
             c.imu_preset = v.text();
             const auto& names = ins::imu_preset_names();
             if (std::find(names.begin(), names.end(), c.imu_preset) == names.end())
               throw io::InputError(v.file, "key '" + v.key + "': unknown preset '" + c.imu_preset + "'", v.line());
           }},
          {"max_gap_s", [](const Value& v, FuseConfig& c) { c.imu_max_gap_s = v.positive(); }}};
  for (const auto& key : ins::imu_datasheet_keys())
    t.emplace(std::string(key.name), [&key](const Value& v, FuseConfig& c) {
      const double x = v.number();
      if (const std::string problem = ins::datasheet_value_problem(key, x); !problem.empty())
        throw io::InputError(v.file, "key '" + v.key + "' " + problem, v.line());
      c.imu_datasheet.*(key.member) = x;
    });
  return t;
}

const std::map<std::string, Table>& sections() {
  using C = FuseConfig;
  static const std::map<std::string, Table> s = {
      {"imu", imu_table()},
      {"initial",
       {{"attitude_deg", [](const Value& v, C& c) { c.attitude_deg = v.vector3(); }},
        {"position_deg_m",
         [](const Value& v, C& c) {
           c.position_deg_m = v.vector3();
           if (std::fabs(c.position_deg_m->x()) > 90.0)
             throw io::InputError(v.file, "key '" + v.key + "': latitude outside [-90, 90]", v.line());
         }},
        {"sigma_position_m", [](const Value& v, C& c) { c.sigma_position_m = v.vector3(true); }},
        {"sigma_velocity_mps", [](const Value& v, C& c) { c.sigma_velocity_mps = v.vector3(true); }},
        {"velocity_ned_mps", [](const Value& v, C& c) { c.velocity_ned_mps = v.vector3(); }},
        {"sigma_attitude_deg", [](const Value& v, C& c) { c.sigma_attitude_deg = v.vector3(true); }}}},
      {"alignment",
       {{"static_duration_s", [](const Value& v, C& c) { c.static_duration_s = v.positive(); }},
        {"motion_min_speed_mps", [](const Value& v, C& c) { c.motion_min_speed_mps = v.positive(); }},
        {"motion_window_s", [](const Value& v, C& c) { c.motion_window_s = v.positive(); }},
        {"motion_heading_sigma_deg", [](const Value& v, C& c) { c.motion_heading_sigma_deg = v.positive(); }},
        {"standstill_gyro_bias", [](const Value& v, C& c) { c.standstill_gyro_bias = v.boolean(); }}}},
      {"gnss",
       {{"velocity_sigma_mps", [](const Value& v, C& c) { c.velocity_sigma_mps = v.positive(); }},
        {"use_velocity", [](const Value& v, C& c) { c.use_velocity = v.boolean(); }},
        {"update_interval_s", [](const Value& v, C& c) { c.fix_min_interval_s = v.non_negative(); }},
        {"error_correlation_time_s",
         [](const Value& v, C& c) {
           c.fix_error_auto = v.node.is_string();
           if (c.fix_error_auto && v.text() != "auto")
             throw io::InputError(v.file, "key '" + v.key + "' must be a number of seconds or \"auto\"", v.line());
           if (!c.fix_error_auto) c.fix_error_correlation_s = v.non_negative();
         }},
        {"error_sigma_ned_m", [](const Value& v, C& c) { c.fix_error_sigma_ned_m = v.vector3(true); }},
        {"lever_arm_body_m", [](const Value& v, C& c) { c.lever_arm_b = v.vector3(); }}}},
      {"filter",
       {{"ukf_alpha", [](const Value& v, C& c) { c.ukf.alpha = v.positive(); }},
        {"ukf_beta", [](const Value& v, C& c) { c.ukf.beta = v.number(); }},
        {"ukf_kappa", [](const Value& v, C& c) { c.ukf.kappa = v.number(); }},
        {"gate", [](const Value& v, C& c) { c.gate.enabled = v.boolean(); }},
        {"gate_probability",
         [](const Value& v, C& c) {
           c.gate.probability = v.number();
           if (!(c.gate.probability > 0.0 && c.gate.probability < 1.0))
             throw io::InputError(v.file, "key '" + v.key + "' must be in (0, 1)", v.line());
         }},
        {"propagation_interval_s", [](const Value& v, C& c) { c.propagation_interval_s = v.positive(); }},
        {"recovery", [](const Value& v, C& c) { c.recovery.enabled = v.boolean(); }},
        {"recovery_rejections", [](const Value& v, C& c) { c.recovery.consecutive_rejections = v.count(); }},
        {"recovery_span_s", [](const Value& v, C& c) { c.recovery.min_span_s = v.non_negative(); }},
        {"recovery_nis_window",
         [](const Value& v, C& c) {
           const std::int64_t n = v.integer();
           if (n < 0) throw io::InputError(v.file, "key '" + v.key + "' must not be negative", v.line());
           c.recovery.nis_window = static_cast<int>(n);
         }}}},
      {"vehicle",
       {{"nhc", [](const Value& v, C& c) { c.land.nhc = v.boolean(); }},
        {"nhc_sigma_mps", [](const Value& v, C& c) { c.land.nhc_sigma_mps = v.positive(); }},
        {"nhc_interval_s", [](const Value& v, C& c) { c.land.nhc_interval_s = v.non_negative(); }},
        {"nhc_lever_arm_body_m", [](const Value& v, C& c) { c.land.lever_arm_b = v.vector3(); }}}},
      {"odometer",
       {{"mode",
         [](const Value& v, C& c) {
           const std::string m = v.text();
           if (m != "gated" && m != "always")
             throw io::InputError(v.file, "key '" + v.key + "' must be \"gated\" or \"always\"", v.line());
           c.odometer.mode = m == "gated" ? fusion::OdometerMode::kGated : fusion::OdometerMode::kAlways;
         }},
        {"yaw_rate_threshold_dps",
         [](const Value& v, C& c) { c.odometer.yaw_rate_threshold_rad_s = v.positive() * io::kRadPerDeg; }},
        {"min_speed_mps", [](const Value& v, C& c) { c.odometer.min_speed_mps = v.non_negative(); }},
        {"update_rate_hz", [](const Value& v, C& c) { c.odometer.update_rate_hz = v.positive(); }},
        {"rate_hz", [](const Value& v, C& c) { c.odometer_rate_hz = v.positive(); }},
        {"lever_arm_body_m", [](const Value& v, C& c) { c.odometer.lever_arm_b = v.vector3(); }},
        {"sigma_scale_factor", [](const Value& v, C& c) { c.odometer.sigma_scale_factor = v.positive(); }},
        {"sigma_misalignment_deg",
         [](const Value& v, C& c) { c.odometer.sigma_misalignment_rad = v.positive() * io::kRadPerDeg; }},
        {"sigma_delay_s", [](const Value& v, C& c) { c.odometer.sigma_delay_s = v.positive(); }},
        {"scale_factor_psd", [](const Value& v, C& c) { c.odometer.scale_factor_psd = v.non_negative(); }},
        {"sigma_forward_mps", [](const Value& v, C& c) { c.odometer.sigma_forward_mps = v.positive(); }},
        {"sigma_lateral_mps", [](const Value& v, C& c) { c.odometer.sigma_lateral_mps = v.positive(); }},
        {"sigma_vertical_mps", [](const Value& v, C& c) { c.odometer.sigma_vertical_mps = v.positive(); }}}},
      {"clock",
       {{"oscillator",
         [](const Value& v, C& c) {
           const auto p = fusion::oscillator_preset(v.text());
           if (!p) throw io::InputError(v.file, "key '" + v.key + "' must be \"tcxo\" or \"ocxo\"", v.line());
           c.clock_oscillator = v.text();
           c.clock_allan = *p;
         }},
        {"h0", [](const Value& v, C& c) { c.clock_allan_h0 = v.positive(); }},
        {"h_minus2", [](const Value& v, C& c) { c.clock_allan_hm2 = v.positive(); }}}},
      {"height_aiding",
       {{"mode",
         [](const Value& v, C& c) {
           const std::string m = v.text();
           if (m != "auto" && m != "off")
             throw io::InputError(v.file, "key '" + v.key + "' must be \"auto\" or \"off\"", v.line());
           c.height_aiding.enabled = m == "auto";
         }},
        {"sigma_m", [](const Value& v, C& c) { c.height_aiding.sigma0_m = v.positive(); }},
        {"terrain_sigma_m", [](const Value& v, C& c) { c.height_aiding.terrain_sigma_m = v.positive(); }},
        {"terrain_correlation_s", [](const Value& v, C& c) { c.height_aiding.terrain_correlation_s = v.positive(); }},
        {"height_m", [](const Value& v, C& c) { c.height_aiding.fixed_height_m = v.number(); }},
        {"interval_s", [](const Value& v, C& c) { c.height_aiding.min_interval_s = v.non_negative(); }}}},
      {"output",
       {{"convergence_heading_sigma_deg", [](const Value& v, C& c) { c.convergence_heading_sigma_deg = v.positive(); }}}},
      {"attitude",
       {{"gps_time_at_imu_zero",
         [](const Value& v, C& c) {
           const auto* a = v.node.as_array();
           const auto week = a && a->size() == 2 ? (*a)[0].value<std::int64_t>() : std::nullopt;
           const auto tow = a && a->size() == 2 ? (*a)[1].value<double>() : std::nullopt;
           if (!week || !tow || *week < 0 || !(*tow >= 0.0 && *tow < 604800.0))
             throw io::InputError(v.file, "key '" + v.key + "' must be [week, tow_s] with tow_s in [0, 604800)",
                                  v.line());
           c.attitude_gps_time_at_imu_zero = signals::GpsTime{static_cast<int>(*week), *tow};
         }},
        {"misalignment_deg", [](const Value& v, C& c) { c.attitude_misalignment_deg = v.vector3(); }},
        {"max_pitch_deg",
         [](const Value& v, C& c) {
           c.attitude_max_pitch_deg = v.positive();
           if (c.attitude_max_pitch_deg > 90.0)
             throw io::InputError(v.file, "key '" + v.key + "' must be at most 90", v.line());
         }}}},
  };
  return s;
}

}  // namespace

FuseConfig read_fuse_config(const std::filesystem::path& path) {
  const std::string file = path.string();
  if (!std::filesystem::is_regular_file(path)) throw io::InputError(file, "configuration file does not exist");
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    throw io::InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  FuseConfig c;
  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    const auto known = sections().find(section);
    const auto* table = section_node.as_table();
    if (known == sections().end() || !table)
      throw io::InputError(
          file,
          "unknown section '" + section +
              "' (imu, initial, alignment, gnss, vehicle, odometer, clock, height_aiding, filter, output, attitude)",
          static_cast<int>(section_node.source().begin.line));
    for (const auto& [key_name, node] : *table) {
      const std::string key = section + "." + std::string(key_name.str());
      const auto setter = known->second.find(std::string(key_name.str()));
      if (setter == known->second.end())
        throw io::InputError(file, "unknown key '" + key + "'", static_cast<int>(node.source().begin.line));
      setter->second(Value{file, key, node}, c);
    }
  }
  // h0 / h_minus2 override the oscillator preset whatever their order in the file.
  if (c.clock_allan_h0) c.clock_allan.h0 = *c.clock_allan_h0;
  if (c.clock_allan_hm2) c.clock_allan.h_minus2 = *c.clock_allan_hm2;
  return c;
}

}  // namespace ultratrack::config
