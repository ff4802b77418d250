#include "scenario.hpp"

#include <fmt/core.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::tools {
namespace {

using signals::InputError;

// Strict readers of one key: the node must have the right type; errors name the file, line and key.
class Reader {
 public:
  Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& problem) const {
    throw InputError(file_, "key " + key + ": " + problem, static_cast<int>(node.source().begin.line));
  }

  double number(const toml::node& n, const std::string& key) const {
    if (auto v = n.as_floating_point()) return v->get();
    if (auto v = n.as_integer()) return static_cast<double>(v->get());
    fail(n, key, "expected a number");
  }
  std::int64_t integer(const toml::node& n, const std::string& key) const {
    if (auto v = n.as_integer()) return v->get();
    fail(n, key, "expected an integer");
  }
  bool boolean(const toml::node& n, const std::string& key) const {
    if (auto v = n.as_boolean()) return v->get();
    fail(n, key, "expected true or false");
  }
  std::string string(const toml::node& n, const std::string& key) const {
    if (auto v = n.as_string()) return v->get();
    fail(n, key, "expected a string");
  }
  std::array<double, 3> triple(const toml::node& n, const std::string& key) const {
    const auto* a = n.as_array();
    if (!a || a->size() != 3) fail(n, key, "expected an array of 3 numbers");
    std::array<double, 3> out{};
    for (std::size_t i = 0; i < 3; ++i) out[i] = number(*a->get(i), key);
    return out;
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

void check_range(const Reader& r, const toml::node& n, const std::string& key, bool ok, const std::string& what) {
  if (!ok) r.fail(n, key, what);
}

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

}  // namespace

Scenario parse_scenario(std::string_view text, const std::filesystem::path& source) {
  const std::string file = source.string();
  toml::table root;
  try {
    root = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  Reader r(file);
  Scenario s;
  s.source = source;
  bool llh_given = false, rinex_given = false, constellation_given = false, offsets_given = false;
  bool signal_given = false, trajectory_given = false, antennas_given = false, attitude_given = false;
  bool duration_given = false, start_state_given = false;
  auto in_list = [](const std::vector<std::string>& names, const std::string& v) {
    return std::find(names.begin(), names.end(), v) != names.end();
  };
  auto joined = [](const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  };

  for (auto&& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    if (section == "antenna") {
      const auto* arr = section_node.as_array();
      if (!arr || arr->empty() || !arr->is_array_of_tables())
        r.fail(section_node, section, "expected [[antenna]] tables with lever_arm_body_m = [x, y, z]");
      s.lever_arms_body_m.clear();
      s.antenna_impairments.clear();
      for (const auto& e : *arr) {
        const auto& t = *e.as_table();
        const toml::node* lever = nullptr;
        signals::AntennaImpairment imp;
        for (auto&& [k, n] : t) {
          const std::string key(k.str());
          if (key == "line_bias_cycles") {
            imp.line_bias_cycles = r.number(n, "antenna.line_bias_cycles");
            check_range(r, n, "antenna.line_bias_cycles", std::abs(imp.line_bias_cycles) <= 1e6, "must be within +-1e6");
          } else if (key == "phase_noise_m") {
            imp.phase_noise_m = r.number(n, "antenna.phase_noise_m");
            check_range(r, n, "antenna.phase_noise_m", imp.phase_noise_m >= 0 && imp.phase_noise_m < 1,
                        "must be within [0, 1) m");
          } else if (key == "lever_arm_body_m") {
            lever = &n;
          } else {
            r.fail(n, "antenna." + key, "unknown key in [[antenna]]");
          }
        }
        s.antenna_impairments.push_back(imp);
        if (!lever) r.fail(e, "antenna.lever_arm_body_m", "missing in an [[antenna]] table");
        const auto l = r.triple(*lever, "antenna.lever_arm_body_m");
        check_range(r, *lever, "antenna.lever_arm_body_m",
                    std::abs(l[0]) <= 1000 && std::abs(l[1]) <= 1000 && std::abs(l[2]) <= 1000,
                    "each component must be within +-1000 m");
        s.lever_arms_body_m.push_back(l);
      }
      antennas_given = true;
      continue;
    }
    if (section == "cn0_step") {
      const auto* arr = section_node.as_array();
      if (!arr || arr->empty() || !arr->is_array_of_tables()) r.fail(section_node, section, "expected [[cn0_step]] tables");
      for (const auto& e : *arr) {
        signals::Cn0StepEvent ev;
        bool start_given = false, cn0_given = false;
        for (auto&& [k, n] : *e.as_table()) {
          const std::string key(k.str());
          if (key == "antenna") {
            const auto antenna = r.integer(n, "cn0_step.antenna");
            check_range(r, n, "cn0_step.antenna", antenna >= 0 && antenna < 4, "must be 0..3");
            ev.antenna = static_cast<int>(antenna);
          } else if (key == "start_s") {
            ev.start_s = r.number(n, "cn0_step.start_s");
            check_range(r, n, "cn0_step.start_s", ev.start_s >= 0 && ev.start_s <= 86400, "must be within 0..86400 s");
            start_given = true;
          } else if (key == "cn0_dbhz") {
            ev.cn0_dbhz = r.number(n, "cn0_step.cn0_dbhz");
            check_range(r, n, "cn0_step.cn0_dbhz", ev.cn0_dbhz >= 0 && ev.cn0_dbhz <= 80, "must be within 0..80 dB-Hz");
            cn0_given = true;
          } else if (key == "prns") {
            const auto* list = n.as_array();
            if (!list || list->empty()) r.fail(n, "cn0_step.prns", "expected a list of PRNs, e.g. [3, 7] (leave out for all)");
            for (const auto& p : *list) {
              const auto prn = r.integer(p, "cn0_step.prns");
              check_range(r, p, "cn0_step.prns", prn >= 1 && prn <= 32, "PRN must be 1..32");
              ev.prns.push_back(static_cast<int>(prn));
            }
          } else {
            r.fail(n, "cn0_step." + key, "unknown key in [[cn0_step]] (antenna, start_s, cn0_dbhz, prns)");
          }
        }
        if (!start_given) r.fail(e, "cn0_step.start_s", "missing in a [[cn0_step]] table");
        if (!cn0_given) r.fail(e, "cn0_step.cn0_dbhz", "missing in a [[cn0_step]] table");
        s.cn0_steps.push_back(ev);
      }
      continue;
    }
    if (section == "cycle_slip" || section == "blockage") {
      const auto* arr = section_node.as_array();
      if (!arr || arr->empty() || !arr->is_array_of_tables()) r.fail(section_node, section, "expected [[" + section + "]] tables");
      for (const auto& e : *arr) {
        std::map<std::string, const toml::node*> keys;
        for (auto&& [k, n] : *e.as_table()) keys[std::string(k.str())] = &n;
        const std::vector<std::string> allowed = section == "cycle_slip"
                                                     ? std::vector<std::string>{"antenna", "prn", "time_s", "cycles", "fade_s"}
                                                     : std::vector<std::string>{"antenna", "start_s", "duration_s"};
        for (const auto& [k, n] : keys)
          if (!in_list(allowed, k)) r.fail(*n, section + "." + k, "unknown key in [[" + section + "]]");
        auto get = [&](const std::string& k, bool required) -> const toml::node* {
          auto it = keys.find(k);
          if (it == keys.end()) {
            if (required) r.fail(e, section + "." + k, "missing in a [[" + section + "]] table");
            return nullptr;
          }
          return it->second;
        };
        const toml::node* ant = get("antenna", true);
        const auto antenna = r.integer(*ant, section + ".antenna");
        check_range(r, *ant, section + ".antenna", antenna >= 0 && antenna < 4, "must be 0..3");
        if (section == "cycle_slip") {
          signals::CycleSlipEvent ev;
          ev.antenna = static_cast<int>(antenna);
          const toml::node* p = get("prn", true);
          const auto prn = r.integer(*p, "cycle_slip.prn");
          check_range(r, *p, "cycle_slip.prn", prn >= 1 && prn <= 32, "PRN must be 1..32");
          ev.prn = static_cast<int>(prn);
          const toml::node* t = get("time_s", true);
          ev.time_s = r.number(*t, "cycle_slip.time_s");
          check_range(r, *t, "cycle_slip.time_s", ev.time_s >= 0, "must be >= 0");
          const toml::node* c = get("cycles", true);
          ev.cycles = r.number(*c, "cycle_slip.cycles");
          check_range(r, *c, "cycle_slip.cycles", std::abs(ev.cycles) <= 1e6, "must be within +-1e6");
          if (const toml::node* f = get("fade_s", false)) {
            ev.fade_s = r.number(*f, "cycle_slip.fade_s");
            check_range(r, *f, "cycle_slip.fade_s", ev.fade_s >= 0 && ev.fade_s <= 60, "must be within 0..60 s");
          }
          s.cycle_slips.push_back(ev);
        } else {
          signals::BlockageEvent ev;
          ev.antenna = static_cast<int>(antenna);
          const toml::node* t = get("start_s", true);
          ev.start_s = r.number(*t, "blockage.start_s");
          check_range(r, *t, "blockage.start_s", ev.start_s >= 0, "must be >= 0");
          const toml::node* d = get("duration_s", true);
          ev.duration_s = r.number(*d, "blockage.duration_s");
          check_range(r, *d, "blockage.duration_s", ev.duration_s > 0 && ev.duration_s <= 86400, "must be within (0, 86400] s");
          s.blockages.push_back(ev);
        }
      }
      continue;
    }
    const auto* tbl = section_node.as_table();
    if (!tbl) r.fail(section_node, section, "expected a table [" + section + "]");
    for (auto&& [k, n] : *tbl) {
      const std::string key(k.str());
      const std::string name = section + "." + key;
      if (section == "signal") signal_given = true;
      if (section == "signal") {
        if (key == "sample_rate_hz") {
          s.sample_rate_hz = r.number(n, name);
          check_range(r, n, name, s.sample_rate_hz >= 1e5 && s.sample_rate_hz <= 1e9, "must be within 100 kHz..1 GHz");
        } else if (key == "if_hz") {
          s.if_hz = r.number(n, name);
        } else if (key == "format") {
          const auto f = signals::parse_sample_format(r.string(n, name));
          if (!f) r.fail(n, name, "unknown sample format (" + std::string(signals::sample_format_names()) + ")");
          s.format = *f;
        } else if (key == "two_bit_coding") {
          const auto c = signals::parse_two_bit_coding(r.string(n, name));
          if (!c) r.fail(n, name, "unknown 2-bit coding (" + std::string(signals::two_bit_coding_names()) + ")");
          s.two_bit.coding = *c;
        } else if (key == "two_bit_order") {
          const auto o = signals::parse_bit_order(r.string(n, name));
          if (!o) r.fail(n, name, "unknown bit order (" + std::string(signals::bit_order_names()) + ")");
          s.two_bit.order = *o;
        } else if (key == "duration_s") {
          s.duration_s = r.number(n, name);
          check_range(r, n, name, s.duration_s > 0 && s.duration_s <= 86400, "must be within (0, 86400] s");
        } else if (key == "cn0_dbhz") {
          s.cn0_dbhz = r.number(n, name);
          check_range(r, n, name, s.cn0_dbhz >= 0 && s.cn0_dbhz <= 80, "must be within 0..80 dB-Hz");
        } else if (key == "seed") {
          const auto v = r.integer(n, name);
          check_range(r, n, name, v >= 0, "must be >= 0");
          s.seed = static_cast<std::uint64_t>(v);
        } else if (key == "cn0_dbhz_by_prn") {
          const auto* t = n.as_table();
          if (!t) r.fail(n, name, "expected a table of PRN = C/N0 (dB-Hz), e.g. { 5 = 40.0 }");
          for (auto&& [pk, pn] : *t) {
            const std::string prn_text(pk.str());
            int prn = 0;
            std::istringstream ss(prn_text);
            if (!(ss >> prn) || !ss.eof() || prn < 1 || prn > 32)
              r.fail(pn, name + "." + prn_text, "PRN must be 1..32");
            const double cn0 = r.number(pn, name + "." + prn_text);
            check_range(r, pn, name + "." + prn_text, cn0 >= 0 && cn0 <= 80, "must be within 0..80 dB-Hz");
            s.cn0_dbhz_by_prn[prn] = cn0;
          }
        } else if (key == "nav_data") {
          s.nav_data = r.boolean(n, name);
        } else if (key == "noise") {
          s.noise = r.boolean(n, name);
        } else {
          r.fail(n, name, "unknown key in [signal]");
        }
      } else if (section == "time") {
        if (key == "gps_week") {
          const auto v = r.integer(n, name);
          check_range(r, n, name, v >= 0 && v < 100000, "must be a full GPS week >= 0");
          s.gps_week = static_cast<int>(v);
        } else if (key == "tow_s") {
          s.tow_s = r.number(n, name);
          check_range(r, n, name, s.tow_s >= 0 && s.tow_s < 604800, "must be within [0, 604800) s");
        } else {
          r.fail(n, name, "unknown key in [time]");
        }
      } else if (section == "navigation") {
        if (key == "rinex") {
          s.rinex = r.string(n, name);
          rinex_given = true;
        } else if (key == "constellation") {
          s.constellation = r.string(n, name);
          if (s.constellation != "nominal") r.fail(n, name, "unknown constellation (only \"nominal\")");
          constellation_given = true;
        } else if (key == "elevation_mask_deg") {
          s.elevation_mask_deg = r.number(n, name);
          check_range(r, n, name, s.elevation_mask_deg >= -90 && s.elevation_mask_deg <= 90, "must be within -90..90");
        } else if (key == "include_unhealthy") {
          s.include_unhealthy = r.boolean(n, name);
        } else {
          r.fail(n, name, "unknown key in [navigation]");
        }
        if (rinex_given && constellation_given) r.fail(n, name, "give either rinex or constellation, not both");
      } else if (section == "receiver") {
        if (key == "llh_deg_m") {
          s.llh_deg_m = r.triple(n, name);
          check_range(r, n, name,
                      std::abs(s.llh_deg_m[0]) <= 90 && std::abs(s.llh_deg_m[1]) <= 360 && s.llh_deg_m[2] > -1e4 &&
                          s.llh_deg_m[2] < 1e7,
                      "latitude must be within +-90 deg, longitude +-360 deg, height -10 km..10000 km");
          llh_given = true;
        } else if (key == "trajectory") {
          s.trajectory = r.string(n, name);
        } else if (key == "antenna_offsets_enu_m") {
          const auto* a = n.as_array();
          if (!a || a->empty()) r.fail(n, name, "expected an array of [east, north, up] offsets in metres");
          s.antenna_offsets_enu_m.clear();
          for (const auto& e : *a) s.antenna_offsets_enu_m.push_back(r.triple(e, name));
          offsets_given = true;
        } else if (key == "attitude_deg") {
          s.attitude_deg = r.triple(n, name);
          check_range(r, n, name,
                      std::abs(s.attitude_deg[0]) <= 180 && std::abs(s.attitude_deg[1]) <= 80 &&
                          std::abs(s.attitude_deg[2]) <= 360,
                      "roll must be within +-180 deg, pitch +-80 deg, yaw +-360 deg");
          attitude_given = true;
        } else if (key == "clock_bias_m") {
          s.clock_bias_m = r.number(n, name);
          check_range(r, n, name, std::abs(s.clock_bias_m) < 3e8, "must be below 1 light-second");
        } else if (key == "clock_drift_mps") {
          s.clock_drift_mps = r.number(n, name);
          check_range(r, n, name, std::abs(s.clock_drift_mps) < 3e5, "must be below 3e5 m/s (1e-3 s/s)");
        } else if (key == "clock_bias_noise_m_per_sqrt_s") {
          s.clock_bias_noise_m_per_sqrt_s = r.number(n, name);
          check_range(r, n, name, s.clock_bias_noise_m_per_sqrt_s >= 0, "must be >= 0");
        } else if (key == "clock_drift_noise_mps_per_sqrt_s") {
          s.clock_drift_noise_mps_per_sqrt_s = r.number(n, name);
          check_range(r, n, name, s.clock_drift_noise_mps_per_sqrt_s >= 0, "must be >= 0");
        } else {
          r.fail(n, name, "unknown key in [receiver]");
        }
        if (llh_given && !s.trajectory.empty()) r.fail(n, name, "give either llh_deg_m or trajectory, not both");
        if (offsets_given && !s.trajectory.empty())
          r.fail(n, name, "antenna_offsets_enu_m needs a static receiver (llh_deg_m), not a trajectory");
      } else if (section == "atmosphere") {
        if (key == "ionosphere") {
          s.ionosphere = r.boolean(n, name);
        } else if (key == "troposphere") {
          s.troposphere = r.boolean(n, name);
        } else {
          r.fail(n, name, "unknown key in [atmosphere]");
        }
      } else if (section == "trajectory") {
        trajectory_given = true;
        if (key == "profile") {
          s.trajectory_profile = r.string(n, name);
          if (!in_list(ins::profile_names(), s.trajectory_profile))
            r.fail(n, name, "unknown profile (" + joined(ins::profile_names()) + ")");
        } else if (key == "file") {
          s.trajectory_file = r.string(n, name);
          if (s.trajectory_file.empty()) r.fail(n, name, "must name a segment CSV file");
        } else if (key == "duration_s") {
          s.trajectory_duration_s = r.number(n, name);
          check_range(r, n, name, s.trajectory_duration_s > 0 && s.trajectory_duration_s <= 86400,
                      "must be within (0, 86400] s");
          duration_given = true;
        } else if (key == "imu_rate_hz") {
          s.imu_rate_hz = r.number(n, name);
          check_range(r, n, name, s.imu_rate_hz >= 50 && s.imu_rate_hz <= 1000, "must be within 50..1000 Hz");
        } else if (key == "speed_mps") {
          s.start_speed_mps = r.number(n, name);
          check_range(r, n, name, s.start_speed_mps >= 0 && s.start_speed_mps < 3000, "must be within 0..3000 m/s");
          start_state_given = true;
        } else if (key == "heading_deg") {
          s.start_heading_deg = r.number(n, name);
          check_range(r, n, name, std::abs(s.start_heading_deg) <= 360, "must be within +-360 deg");
          start_state_given = true;
        } else if (key == "coordinated_turns") {
          s.coordinated_turns = r.boolean(n, name);
          start_state_given = true;
        } else if (key == "ramp_s") {
          s.ramp_s = r.number(n, name);
          check_range(r, n, name, s.ramp_s >= 0 && s.ramp_s <= 600, "must be within 0..600 s");
          start_state_given = true;
        } else if (key == "odometer") {
          s.odometer = r.boolean(n, name);
        } else if (key == "odometer_scale_factor_error") {
          s.odometer_scale_factor_error = r.number(n, name);
          check_range(r, n, name, std::abs(s.odometer_scale_factor_error) < 0.5, "must be within +-0.5");
        } else {
          r.fail(n, name, "unknown key in [trajectory]");
        }
        if (!s.trajectory_profile.empty() && !s.trajectory_file.empty())
          r.fail(n, name, "give either profile or file, not both");
      } else if (section == "imu") {
        auto override_value = [&](std::optional<double>& v, double max) {
          v = r.number(n, name);
          check_range(r, n, name, *v >= 0 && *v <= max, fmt::format("must be within 0..{}", max));
        };
        if (key == "preset") {
          s.imu_preset = r.string(n, name);
          if (!in_list(ins::imu_preset_names(), s.imu_preset))
            r.fail(n, name, "unknown preset (" + joined(ins::imu_preset_names()) + ")");
        } else if (key == "seed") {
          const auto v = r.integer(n, name);
          check_range(r, n, name, v >= 0, "must be >= 0");
          s.imu_seed = static_cast<std::uint64_t>(v);
        } else if (key == "gyro_bias_dph") {
          override_value(s.gyro_bias_dph, 1e5);
        } else if (key == "accel_bias_mg") {
          override_value(s.accel_bias_mg, 1e3);
        } else if (key == "gyro_arw_dpsh") {
          override_value(s.gyro_arw_dpsh, 1e3);
        } else if (key == "accel_vrw_mpspsh") {
          override_value(s.accel_vrw_mpspsh, 1e3);
        } else {
          r.fail(n, name, "unknown key in [imu]");
        }
      } else if (section == "output") {
        if (key == "truth_rate_hz") {
          s.truth_rate_hz = r.number(n, name);
          check_range(r, n, name, s.truth_rate_hz > 0 && s.truth_rate_hz <= 1000, "must be within (0, 1000] Hz");
        } else {
          r.fail(n, name, "unknown key in [output]");
        }
      } else {
        r.fail(section_node, section,
               "unknown section (signal, time, navigation, receiver, atmosphere, output, trajectory, imu, "
               "[[antenna]], [[cycle_slip]], [[blockage]], [[cn0_step]])");
      }
    }
  }
  if (rinex_given) s.constellation.clear();
  // Inertial scenarios.
  const auto fail_file = [&](const std::string& problem) { throw InputError(file, problem); };
  if (trajectory_given) {
    if (!s.trajectory_enabled()) fail_file("[trajectory] needs profile = \"NAME\" or file = \"segments.csv\"");
    if (!s.trajectory_profile.empty() && !duration_given) fail_file("key trajectory.duration_s: missing (profiles)");
    if (!s.trajectory_file.empty() && duration_given)
      fail_file("key trajectory.duration_s: a segment file sets its own duration");
    if (s.trajectory_file.empty() && start_state_given)
      fail_file("keys trajectory.speed_mps / heading_deg / coordinated_turns / ramp_s: only with a segment file");
    if (!s.trajectory.empty()) fail_file("key receiver.trajectory: not with a [trajectory] section");
    if (offsets_given)
      fail_file("key receiver.antenna_offsets_enu_m: with [trajectory] use [[antenna]] lever_arm_body_m");
    if (std::abs(s.llh_deg_m[0]) >= 89.0)
      fail_file("key receiver.llh_deg_m: latitude must be within +-89 deg with [trajectory]");
    if (attitude_given && s.trajectory_profile != "static")
      fail_file("key receiver.attitude_deg: needs [trajectory] profile = \"static\"");
  } else {
    if (antennas_given) fail_file("[[antenna]] needs a [trajectory] section (static receivers: antenna_offsets_enu_m)");
    if (attitude_given) fail_file("key receiver.attitude_deg: needs [trajectory] profile = \"static\"");
  }
  s.signal = signal_given || !trajectory_given;
  const std::size_t n_antennas = s.trajectory_enabled() ? s.lever_arms_body_m.size() : s.antenna_offsets_enu_m.size();
  if ((!s.cycle_slips.empty() || !s.blockages.empty()) && !s.signal)
    fail_file("[[cycle_slip]] and [[blockage]] need a [signal] section");
  for (const auto& e : s.cycle_slips)
    if (static_cast<std::size_t>(e.antenna) >= n_antennas)
      fail_file(fmt::format("key cycle_slip.antenna: antenna {} does not exist ({} antennas)", e.antenna, n_antennas));
  for (const auto& b : s.blockages)
    if (static_cast<std::size_t>(b.antenna) >= n_antennas)
      fail_file(fmt::format("key blockage.antenna: antenna {} does not exist ({} antennas)", b.antenna, n_antennas));
  if (!s.cn0_steps.empty() && !s.signal) fail_file("[[cn0_step]] needs a [signal] section");
  for (const auto& c : s.cn0_steps)
    if (static_cast<std::size_t>(c.antenna) >= n_antennas)
      fail_file(fmt::format("key cn0_step.antenna: antenna {} does not exist ({} antennas)", c.antenna, n_antennas));
  // Cross-key checks that need the whole scenario.
  const bool real = !signals::is_complex(s.format);
  if (real && !(s.if_hz > 0))
    throw InputError(
        file, "key signal.if_hz: real format " + std::string(signals::to_string(s.format)) + " needs an IF above 0 Hz");
  if (!(std::abs(s.if_hz) < 0.5 * s.sample_rate_hz))
    throw InputError(file, "key signal.if_hz: must be below half the sample rate");
  return s;
}

Scenario read_scenario(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open the scenario file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scenario(ss.str(), path);
}

std::filesystem::path resolve_path(const Scenario& scenario, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_absolute() || scenario.source.empty()) return p;
  return scenario.source.parent_path() / p;
}

std::string to_toml(const Scenario& s) {
  auto abs = [&](const std::string& p) {
    std::error_code ec;
    const auto a = std::filesystem::absolute(resolve_path(s, p), ec);
    return toml_string(ec ? p : a.lexically_normal().string());
  };
  std::string out = "# Scenario as run by `ultratrack simulate` (every key, defaults filled in).\n";
  if (s.signal) out += "\n[signal]\n";
  if (s.signal)
    out += fmt::format("sample_rate_hz = {}\nif_hz = {}\nformat = \"{}\"\nduration_s = {}\ncn0_dbhz = {}\nseed = {}\n",
                       toml_float(s.sample_rate_hz), toml_float(s.if_hz), signals::to_string(s.format),
                       toml_float(s.duration_s), toml_float(s.cn0_dbhz), s.seed);
  if (s.signal) {
    out += "cn0_dbhz_by_prn = {";
    bool first = true;
    for (const auto& [prn, cn0] : s.cn0_dbhz_by_prn) {
      out += fmt::format("{} {} = {}", first ? "" : ",", prn, toml_float(cn0));
      first = false;
    }
    out += first ? "}\n" : " }\n";
    out += fmt::format("nav_data = {}\nnoise = {}\n", s.nav_data, s.noise);
    if (signals::is_two_bit(s.format))
      out += fmt::format("two_bit_coding = \"{}\"\ntwo_bit_order = \"{}\"\n", signals::to_string(s.two_bit.coding),
                         signals::to_string(s.two_bit.order));
  }
  out += fmt::format("\n[time]\ngps_week = {}\ntow_s = {}\n", s.gps_week, toml_float(s.tow_s));
  out += "\n[navigation]\n";
  if (!s.rinex.empty()) {
    out += "rinex = " + abs(s.rinex) + "\n";
  } else {
    out += "constellation = " + toml_string(s.constellation) + "\n";
  }
  out += fmt::format("elevation_mask_deg = {}\ninclude_unhealthy = {}\n", toml_float(s.elevation_mask_deg),
                     s.include_unhealthy);
  out += "\n[receiver]\n";
  if (!s.trajectory.empty()) {
    out += "trajectory = " + abs(s.trajectory) + "\n";
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
  if (s.trajectory_enabled()) {
    out += "\n[trajectory]\n";
    if (!s.trajectory_profile.empty()) {
      out += fmt::format("profile = {}\nduration_s = {}\n", toml_string(s.trajectory_profile),
                         toml_float(s.trajectory_duration_s));
    } else {
      out += fmt::format("file = {}\nspeed_mps = {}\nheading_deg = {}\ncoordinated_turns = {}\nramp_s = {}\n",
                         abs(s.trajectory_file), toml_float(s.start_speed_mps), toml_float(s.start_heading_deg),
                         s.coordinated_turns, toml_float(s.ramp_s));
    }
    out += fmt::format("imu_rate_hz = {}\nodometer = {}\nodometer_scale_factor_error = {}\n", toml_float(s.imu_rate_hz),
                       s.odometer, toml_float(s.odometer_scale_factor_error));
    out += fmt::format("\n[imu]\npreset = {}\nseed = {}\n", toml_string(s.imu_preset), s.imu_seed);
    const std::pair<const char*, const std::optional<double>*> overrides[] = {
        {"gyro_bias_dph", &s.gyro_bias_dph},
        {"accel_bias_mg", &s.accel_bias_mg},
        {"gyro_arw_dpsh", &s.gyro_arw_dpsh},
        {"accel_vrw_mpspsh", &s.accel_vrw_mpspsh}};
    for (const auto& [key, value] : overrides)
      if (value->has_value()) out += fmt::format("{} = {}\n", key, toml_float(**value));
    for (std::size_t i = 0; i < s.lever_arms_body_m.size(); ++i) {
      const auto& l = s.lever_arms_body_m[i];
      out += fmt::format("\n[[antenna]]\nlever_arm_body_m = [{}, {}, {}]\n", toml_float(l[0]), toml_float(l[1]),
                         toml_float(l[2]));
      // Written only when set, so that the echo of a scenario without them stays as it was.
      if (i < s.antenna_impairments.size() &&
          (s.antenna_impairments[i].line_bias_cycles != 0.0 || s.antenna_impairments[i].phase_noise_m != 0.0))
        out += fmt::format("line_bias_cycles = {}\nphase_noise_m = {}\n", toml_float(s.antenna_impairments[i].line_bias_cycles),
                           toml_float(s.antenna_impairments[i].phase_noise_m));
    }
  }
  for (const auto& e : s.cycle_slips)
    out += fmt::format("\n[[cycle_slip]]\nantenna = {}\nprn = {}\ntime_s = {}\ncycles = {}\nfade_s = {}\n", e.antenna,
                       e.prn, toml_float(e.time_s), toml_float(e.cycles), toml_float(e.fade_s));
  for (const auto& b : s.blockages)
    out += fmt::format("\n[[blockage]]\nantenna = {}\nstart_s = {}\nduration_s = {}\n", b.antenna, toml_float(b.start_s),
                       toml_float(b.duration_s));
  for (const auto& c : s.cn0_steps) {
    out += fmt::format("\n[[cn0_step]]\nantenna = {}\nstart_s = {}\ncn0_dbhz = {}\n", c.antenna, toml_float(c.start_s),
                       toml_float(c.cn0_dbhz));
    if (!c.prns.empty()) out += fmt::format("prns = [{}]\n", fmt::join(c.prns, ", "));
  }
  return out;
}

}  // namespace ultratrack::tools
