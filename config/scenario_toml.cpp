// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/scenario_toml.hpp"

#include <fmt/core.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ins/imu_datasheet.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "io/input_error.hpp"
#include "io/open_failure.hpp"
#include "io/units.hpp"
#include "signals/gps_constants.hpp"
#include "signals/oscillator_allan.hpp"

namespace ultratrack::config {
namespace {

using io::InputError;
using sim::Scenario;

// Strict readers of one key: the node must have the right type; errors name the file, line and key.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& problem) const {
    throw InputError(file_, "key " + key + ": " + problem, static_cast<int>(node.source().begin.line));
  }
  void check(const toml::node& n, const std::string& key, bool ok, const std::string& what) const {
    if (!ok) fail(n, key, what);
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

// Which keys a file gave: conflicts and the inertial rules depend on presence, not on values.
struct GivenKeys {
  bool llh = false, rinex = false, constellation = false, offsets = false;
  bool signal = false, trajectory = false, antennas = false, attitude = false;
  bool duration = false, start_state = false;
  bool oscillator = false, clock_noise = false;
};

bool in_list(const std::vector<std::string>& names, const std::string& v) {
  return std::find(names.begin(), names.end(), v) != names.end();
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// The [[name]] tables of an array-of-tables section.
const toml::array& tables_of(const Reader& r, const toml::node& section_node, const std::string& section,
                             const std::string& expected) {
  const auto* arr = section_node.as_array();
  if (!arr || arr->empty() || !arr->is_array_of_tables()) r.fail(section_node, section, expected);
  return *arr;
}

// [[antenna]]: lever arm (required) and impairments of each antenna.
void read_antennas(const Reader& r, const toml::node& section_node, Scenario& s) {
  const auto& arr =
      tables_of(r, section_node, "antenna", "expected [[antenna]] tables with lever_arm_body_m = [x, y, z]");
  s.lever_arms_body_m.clear();
  s.antenna_impairments.clear();
  for (const auto& e : arr) {
    const toml::node* lever = nullptr;
    signals::AntennaImpairment imp;
    for (auto&& [k, n] : *e.as_table()) {
      const std::string key(k.str());
      if (key == "line_bias_cycles") {
        imp.line_bias_cycles = r.number(n, "antenna.line_bias_cycles");
        r.check(n, "antenna.line_bias_cycles", std::abs(imp.line_bias_cycles) <= 1e6, "must be within +-1e6");
      } else if (key == "phase_noise_m") {
        imp.phase_noise_m = r.number(n, "antenna.phase_noise_m");
        r.check(n, "antenna.phase_noise_m", imp.phase_noise_m >= 0 && imp.phase_noise_m < 1, "must be within [0, 1) m");
      } else if (key == "lever_arm_body_m") {
        lever = &n;
      } else {
        r.fail(n, "antenna." + key, "unknown key in [[antenna]]");
      }
    }
    s.antenna_impairments.push_back(imp);
    if (!lever) r.fail(e, "antenna.lever_arm_body_m", "missing in an [[antenna]] table");
    const auto l = r.triple(*lever, "antenna.lever_arm_body_m");
    r.check(*lever, "antenna.lever_arm_body_m",
            std::abs(l[0]) <= 1000 && std::abs(l[1]) <= 1000 && std::abs(l[2]) <= 1000,
            "each component must be within +-1000 m");
    s.lever_arms_body_m.push_back(l);
  }
}

std::vector<int> read_prn_list(const Reader& r, const toml::node& n) {
  const auto* list = n.as_array();
  if (!list || list->empty()) r.fail(n, "cn0_step.prns", "expected a list of PRNs, e.g. [3, 7] (leave out for all)");
  std::vector<int> prns;
  for (const auto& p : *list) {
    const auto prn = r.integer(p, "cn0_step.prns");
    r.check(p, "cn0_step.prns", prn >= 1 && prn <= 32, "PRN must be 1..32");
    prns.push_back(static_cast<int>(prn));
  }
  return prns;
}

// [[cn0_step]]: start_s and cn0_dbhz required, antenna and prns optional.
void read_cn0_steps(const Reader& r, const toml::node& section_node, Scenario& s) {
  for (const auto& e : tables_of(r, section_node, "cn0_step", "expected [[cn0_step]] tables")) {
    signals::Cn0StepEvent ev;
    bool start_given = false, cn0_given = false;
    for (auto&& [k, n] : *e.as_table()) {
      const std::string key(k.str());
      if (key == "antenna") {
        const auto antenna = r.integer(n, "cn0_step.antenna");
        r.check(n, "cn0_step.antenna", antenna >= 0 && antenna < 4, "must be 0..3");
        ev.antenna = static_cast<int>(antenna);
      } else if (key == "start_s") {
        ev.start_s = r.number(n, "cn0_step.start_s");
        r.check(n, "cn0_step.start_s", ev.start_s >= 0 && ev.start_s <= 86400, "must be within 0..86400 s");
        start_given = true;
      } else if (key == "cn0_dbhz") {
        ev.cn0_dbhz = r.number(n, "cn0_step.cn0_dbhz");
        r.check(n, "cn0_step.cn0_dbhz", ev.cn0_dbhz >= 0 && ev.cn0_dbhz <= 80, "must be within 0..80 dB-Hz");
        cn0_given = true;
      } else if (key == "prns") {
        ev.prns = read_prn_list(r, n);
      } else {
        r.fail(n, "cn0_step." + key, "unknown key in [[cn0_step]] (antenna, start_s, cn0_dbhz, prns)");
      }
    }
    if (!start_given) r.fail(e, "cn0_step.start_s", "missing in a [[cn0_step]] table");
    if (!cn0_given) r.fail(e, "cn0_step.cn0_dbhz", "missing in a [[cn0_step]] table");
    s.cn0_steps.push_back(ev);
  }
}

// One [[cycle_slip]] or [[blockage]] table: its keys by name, unknown ones rejected, required ones present.
class EventTable {
 public:
  EventTable(const Reader& r, const toml::node& table, std::string section, const std::vector<std::string>& allowed)
      : r_(r), table_(table), section_(std::move(section)) {
    for (auto&& [k, n] : *table.as_table()) keys_[std::string(k.str())] = &n;
    for (const auto& [k, n] : keys_)
      if (!in_list(allowed, k)) r.fail(*n, section_ + "." + k, "unknown key in [[" + section_ + "]]");
  }
  const toml::node* get(const std::string& k, bool required) const {
    auto it = keys_.find(k);
    if (it != keys_.end()) return it->second;
    if (required) r_.fail(table_, section_ + "." + k, "missing in a [[" + section_ + "]] table");
    return nullptr;
  }
  int antenna() const {
    const toml::node* ant = get("antenna", true);
    const auto antenna = r_.integer(*ant, section_ + ".antenna");
    r_.check(*ant, section_ + ".antenna", antenna >= 0 && antenna < 4, "must be 0..3");
    return static_cast<int>(antenna);
  }

 private:
  const Reader& r_;
  const toml::node& table_;
  std::string section_;
  std::map<std::string, const toml::node*> keys_;
};

void read_cycle_slips(const Reader& r, const toml::node& section_node, Scenario& s) {
  for (const auto& e : tables_of(r, section_node, "cycle_slip", "expected [[cycle_slip]] tables")) {
    const EventTable t(r, e, "cycle_slip", {"antenna", "prn", "time_s", "cycles", "fade_s"});
    signals::CycleSlipEvent ev;
    ev.antenna = t.antenna();
    const toml::node* p = t.get("prn", true);
    const auto prn = r.integer(*p, "cycle_slip.prn");
    r.check(*p, "cycle_slip.prn", prn >= 1 && prn <= 32, "PRN must be 1..32");
    ev.prn = static_cast<int>(prn);
    const toml::node* time = t.get("time_s", true);
    ev.time_s = r.number(*time, "cycle_slip.time_s");
    r.check(*time, "cycle_slip.time_s", ev.time_s >= 0, "must be >= 0");
    const toml::node* c = t.get("cycles", true);
    ev.cycles = r.number(*c, "cycle_slip.cycles");
    r.check(*c, "cycle_slip.cycles", std::abs(ev.cycles) <= 1e6, "must be within +-1e6");
    if (const toml::node* f = t.get("fade_s", false)) {
      ev.fade_s = r.number(*f, "cycle_slip.fade_s");
      r.check(*f, "cycle_slip.fade_s", ev.fade_s >= 0 && ev.fade_s <= 60, "must be within 0..60 s");
    }
    s.cycle_slips.push_back(ev);
  }
}

void read_blockages(const Reader& r, const toml::node& section_node, Scenario& s) {
  for (const auto& e : tables_of(r, section_node, "blockage", "expected [[blockage]] tables")) {
    const EventTable t(r, e, "blockage", {"antenna", "start_s", "duration_s"});
    signals::BlockageEvent ev;
    ev.antenna = t.antenna();
    const toml::node* start = t.get("start_s", true);
    ev.start_s = r.number(*start, "blockage.start_s");
    r.check(*start, "blockage.start_s", ev.start_s >= 0, "must be >= 0");
    const toml::node* d = t.get("duration_s", true);
    ev.duration_s = r.number(*d, "blockage.duration_s");
    r.check(*d, "blockage.duration_s", ev.duration_s > 0 && ev.duration_s <= 86400, "must be within (0, 86400] s");
    s.blockages.push_back(ev);
  }
}

// [[vibration]]: frequency_hz (required), accel_amplitude_mps2 = [north, east, down] (peak, m/s^2) and
// angle_amplitude_deg = [roll, pitch, yaw] (peak), phase_deg; at least one amplitude not zero.
void read_vibrations(const Reader& r, const toml::node& section_node, Scenario& s) {
  for (const auto& e : tables_of(r, section_node, "vibration", "expected [[vibration]] tables")) {
    const EventTable t(r, e, "vibration", {"frequency_hz", "accel_amplitude_mps2", "angle_amplitude_deg", "phase_deg"});
    ins::Vibration v;
    const toml::node* f = t.get("frequency_hz", true);
    v.frequency_hz = r.number(*f, "vibration.frequency_hz");
    r.check(*f, "vibration.frequency_hz", v.frequency_hz > 0 && v.frequency_hz <= 500, "must be within (0, 500] Hz");
    bool moves = false;
    if (const toml::node* a = t.get("accel_amplitude_mps2", false)) {
      v.accel_amplitude_n_mps2 = r.triple(*a, "vibration.accel_amplitude_mps2");
      for (const double x : v.accel_amplitude_n_mps2) {
        r.check(*a, "vibration.accel_amplitude_mps2", std::abs(x) <= 100, "each must be within +-100 m/s^2");
        moves = moves || x != 0.0;
      }
    }
    if (const toml::node* a = t.get("angle_amplitude_deg", false)) {
      const auto deg = r.triple(*a, "vibration.angle_amplitude_deg");
      for (int i = 0; i < 3; ++i) {
        r.check(*a, "vibration.angle_amplitude_deg", std::abs(deg[i]) <= 10, "each must be within +-10 deg");
        v.angle_amplitude_rad[static_cast<std::size_t>(i)] = deg[i] * io::kRadPerDeg;
        moves = moves || deg[i] != 0.0;
      }
    }
    if (!moves) r.fail(e, "vibration", "needs accel_amplitude_mps2 or angle_amplitude_deg not zero");
    if (const toml::node* p = t.get("phase_deg", false)) {
      v.phase_rad = r.number(*p, "vibration.phase_deg") * io::kRadPerDeg;
      r.check(*p, "vibration.phase_deg", std::abs(v.phase_rad) <= 2.0 * std::numbers::pi, "must be within +-360 deg");
    }
    s.vibrations.push_back(v);
  }
}

void read_odometer_slips(const Reader& r, const toml::node& section_node, Scenario& s) {
  for (const auto& e : tables_of(r, section_node, "odometer_slip", "expected [[odometer_slip]] tables")) {
    const auto* t = e.as_table();
    if (!t) r.fail(e, "odometer_slip", "expected a table");
    ins::OdometerSlip ev;
    bool start = false, duration = false, ratio = false;
    for (auto&& [k, n] : *t) {
      const std::string key(k.str()), name = "odometer_slip." + key;
      if (key == "start_s") {
        ev.start_s = r.number(n, name);
        r.check(n, name, ev.start_s >= 0, "must be >= 0");
        start = true;
      } else if (key == "duration_s") {
        ev.duration_s = r.number(n, name);
        r.check(n, name, ev.duration_s > 0 && ev.duration_s <= 3600, "must be within (0, 3600] s");
        duration = true;
      } else if (key == "ratio") {
        ev.ratio = r.number(n, name);
        r.check(n, name, ev.ratio >= -1 && ev.ratio <= 10, "must be within -1..10 (-1: a locked wheel)");
        ratio = true;
      } else {
        r.fail(n, name, "unknown key in [[odometer_slip]] (start_s, duration_s, ratio)");
      }
    }
    if (!start || !duration || !ratio) r.fail(e, "odometer_slip", "needs start_s, duration_s and ratio");
    s.odometer_slips.push_back(ev);
  }
}

// [signal] cn0_dbhz_by_prn = { 5 = 40.0 }
void read_cn0_by_prn(const Reader& r, const toml::node& n, const std::string& name, Scenario& s) {
  const auto* t = n.as_table();
  if (!t) r.fail(n, name, "expected a table of PRN = C/N0 (dB-Hz), e.g. { 5 = 40.0 }");
  for (auto&& [pk, pn] : *t) {
    const std::string prn_text(pk.str());
    int prn = 0;
    std::istringstream ss(prn_text);
    if (!(ss >> prn) || !ss.eof() || prn < 1 || prn > 32) r.fail(pn, name + "." + prn_text, "PRN must be 1..32");
    const double cn0 = r.number(pn, name + "." + prn_text);
    r.check(pn, name + "." + prn_text, cn0 >= 0 && cn0 <= 80, "must be within 0..80 dB-Hz");
    s.cn0_dbhz_by_prn[prn] = cn0;
  }
}

void read_signal_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                     Scenario& s) {
  if (key == "sample_rate_hz") {
    s.sample_rate_hz = r.number(n, name);
    r.check(n, name, s.sample_rate_hz >= 1e5 && s.sample_rate_hz <= 1e9, "must be within 100 kHz..1 GHz");
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
    r.check(n, name, s.duration_s > 0 && s.duration_s <= 86400, "must be within (0, 86400] s");
  } else if (key == "cn0_dbhz") {
    s.cn0_dbhz = r.number(n, name);
    r.check(n, name, s.cn0_dbhz >= 0 && s.cn0_dbhz <= 80, "must be within 0..80 dB-Hz");
  } else if (key == "seed") {
    const auto v = r.integer(n, name);
    r.check(n, name, v >= 0, "must be >= 0");
    s.seed = static_cast<std::uint64_t>(v);
  } else if (key == "cn0_dbhz_by_prn") {
    read_cn0_by_prn(r, n, name, s);
  } else if (key == "nav_data") {
    s.nav_data = r.boolean(n, name);
  } else if (key == "noise") {
    s.noise = r.boolean(n, name);
  } else if (key == "parameter_update_s") {
    s.parameter_update_s = r.number(n, name);
    const double ms = s.parameter_update_s * 1e3;
    r.check(n, name, ms >= 1.0 - 1e-9 && ms <= 1000.0 + 1e-9 && std::abs(ms - std::round(ms)) < 1e-6,
            "must be a whole number of milliseconds within 0.001..1 s");
  } else {
    r.fail(n, name, "unknown key in [signal]");
  }
}

void read_time_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n, Scenario& s) {
  if (key == "gps_week") {
    const auto v = r.integer(n, name);
    r.check(n, name, v >= 0 && v < 100000, "must be a full GPS week >= 0");
    s.gps_week = static_cast<int>(v);
  } else if (key == "tow_s") {
    s.tow_s = r.number(n, name);
    r.check(n, name, s.tow_s >= 0 && s.tow_s < 604800, "must be within [0, 604800) s");
  } else {
    r.fail(n, name, "unknown key in [time]");
  }
}

void read_navigation_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                         Scenario& s, GivenKeys& given) {
  if (key == "rinex") {
    s.rinex = r.string(n, name);
    given.rinex = true;
  } else if (key == "constellation") {
    s.constellation = r.string(n, name);
    if (s.constellation != "nominal") r.fail(n, name, "unknown constellation (only \"nominal\")");
    given.constellation = true;
  } else if (key == "elevation_mask_deg") {
    s.elevation_mask_deg = r.number(n, name);
    r.check(n, name, s.elevation_mask_deg >= -90 && s.elevation_mask_deg <= 90, "must be within -90..90");
  } else if (key == "include_unhealthy") {
    s.include_unhealthy = r.boolean(n, name);
  } else if (key == "field_rounding") {
    const std::string v = r.string(n, name);
    if (v != "nearest" && v != "toward_zero") r.fail(n, name, "must be \"nearest\" or \"toward_zero\"");
    s.nav_field_rounding = v == "nearest" ? signals::FieldRounding::kNearest : signals::FieldRounding::kTowardZero;
  } else if (key == "pages") {
    const std::string v = r.string(n, name);
    if (v != "almanac" && v != "random") r.fail(n, name, "must be \"almanac\" or \"random\"");
    s.nav_random_pages = v == "random";
  } else {
    r.fail(n, name, "unknown key in [navigation]");
  }
  if (given.rinex && given.constellation) r.fail(n, name, "give either rinex or constellation, not both");
}

// [receiver]: the position keys and their conflicts.
bool read_receiver_position_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                                Scenario& s, GivenKeys& given) {
  if (key == "llh_deg_m") {
    s.llh_deg_m = r.triple(n, name);
    r.check(n, name,
            std::abs(s.llh_deg_m[0]) <= 90 && std::abs(s.llh_deg_m[1]) <= 360 && s.llh_deg_m[2] > -1e4 &&
                s.llh_deg_m[2] < 1e7,
            "latitude must be within +-90 deg, longitude +-360 deg, height -10 km..10000 km");
    given.llh = true;
  } else if (key == "trajectory") {
    s.trajectory = r.string(n, name);
  } else if (key == "antenna_offsets_enu_m") {
    const auto* a = n.as_array();
    if (!a || a->empty()) r.fail(n, name, "expected an array of [east, north, up] offsets in metres");
    s.antenna_offsets_enu_m.clear();
    for (const auto& e : *a) s.antenna_offsets_enu_m.push_back(r.triple(e, name));
    given.offsets = true;
  } else if (key == "attitude_deg") {
    s.attitude_deg = r.triple(n, name);
    r.check(
        n, name,
        std::abs(s.attitude_deg[0]) <= 180 && std::abs(s.attitude_deg[1]) <= 80 && std::abs(s.attitude_deg[2]) <= 360,
        "roll must be within +-180 deg, pitch +-80 deg, yaw +-360 deg");
    given.attitude = true;
  } else {
    return false;
  }
  return true;
}

// [receiver]: the clock model's keys.
void read_receiver_clock_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                             Scenario& s, GivenKeys& given) {
  if (key == "clock_bias_m") {
    s.clock_bias_m = r.number(n, name);
    r.check(n, name, std::abs(s.clock_bias_m) < 3e8, "must be below 1 light-second");
  } else if (key == "clock_drift_mps") {
    s.clock_drift_mps = r.number(n, name);
    r.check(n, name, std::abs(s.clock_drift_mps) < 3e5, "must be below 3e5 m/s (1e-3 s/s)");
  } else if (key == "clock_bias_noise_m_per_sqrt_s") {
    s.clock_bias_noise_m_per_sqrt_s = r.number(n, name);
    r.check(n, name, s.clock_bias_noise_m_per_sqrt_s >= 0, "must be >= 0");
    given.clock_noise = true;
  } else if (key == "clock_drift_noise_mps_per_sqrt_s") {
    s.clock_drift_noise_mps_per_sqrt_s = r.number(n, name);
    r.check(n, name, s.clock_drift_noise_mps_per_sqrt_s >= 0, "must be >= 0");
    given.clock_noise = true;
  } else if (key == "oscillator") {
    // A named oscillator sets both random walks from its Allan coefficients as a signal sees them
    // (signals/oscillator_allan.hpp: datasheet phase noise for the white frequency noise).
    // "ideal": a perfect clock (no phase noise, no wander), the default, named so that a campaign axis can hold it.
    const std::string oscillator = r.string(n, name);
    const auto allan =
        oscillator == "ideal" ? signals::OscillatorAllan{0.0, 0.0} : signals::oscillator_signal_preset(oscillator);
    if (!allan) r.fail(n, name, "unknown oscillator (ideal, " + joined(signals::oscillator_preset_names()) + ")");
    const signals::ReceiverClockModel noise = signals::receiver_clock_from_allan(*allan);
    s.clock_bias_noise_m_per_sqrt_s = noise.bias_noise_s_per_sqrt_s * signals::kSpeedOfLight_mps;
    s.clock_drift_noise_mps_per_sqrt_s = noise.drift_noise_sps_per_sqrt_s * signals::kSpeedOfLight_mps;
    given.oscillator = true;
  } else {
    r.fail(n, name, "unknown key in [receiver]");
  }
}

void read_receiver_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                       Scenario& s, GivenKeys& given) {
  if (!read_receiver_position_key(r, key, name, n, s, given)) read_receiver_clock_key(r, key, name, n, s, given);
  if (given.oscillator && given.clock_noise)
    r.fail(n, name, "give either oscillator or the clock noise keys (clock_*_noise_*), not both");
  if (given.llh && !s.trajectory.empty()) r.fail(n, name, "give either llh_deg_m or trajectory, not both");
  if (given.offsets && !s.trajectory.empty())
    r.fail(n, name, "antenna_offsets_enu_m needs a static receiver (llh_deg_m), not a trajectory");
}

void read_atmosphere_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                         Scenario& s) {
  if (key == "ionosphere") {
    s.ionosphere = r.boolean(n, name);
  } else if (key == "troposphere") {
    s.troposphere = r.boolean(n, name);
  } else {
    r.fail(n, name, "unknown key in [atmosphere]");
  }
}

// [trajectory]: the segment file's start-state keys.
bool read_segment_start_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                            Scenario& s) {
  if (key == "speed_mps") {
    s.start_speed_mps = r.number(n, name);
    r.check(n, name, s.start_speed_mps >= 0 && s.start_speed_mps < 3000, "must be within 0..3000 m/s");
  } else if (key == "heading_deg") {
    s.start_heading_deg = r.number(n, name);
    r.check(n, name, std::abs(s.start_heading_deg) <= 360, "must be within +-360 deg");
  } else if (key == "coordinated_turns") {
    s.coordinated_turns = r.boolean(n, name);
  } else if (key == "ramp_s") {
    s.ramp_s = r.number(n, name);
    r.check(n, name, s.ramp_s >= 0 && s.ramp_s <= 600, "must be within 0..600 s");
  } else {
    return false;
  }
  return true;
}

void read_trajectory_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                         Scenario& s, GivenKeys& given) {
  given.trajectory = true;
  if (key == "profile") {
    s.trajectory_profile = r.string(n, name);
    if (!in_list(ins::profile_names(), s.trajectory_profile))
      r.fail(n, name, "unknown profile (" + joined(ins::profile_names()) + ")");
  } else if (key == "file") {
    s.trajectory_file = r.string(n, name);
    if (s.trajectory_file.empty()) r.fail(n, name, "must name a segment CSV file");
  } else if (key == "duration_s") {
    s.trajectory_duration_s = r.number(n, name);
    r.check(n, name, s.trajectory_duration_s > 0 && s.trajectory_duration_s <= 86400, "must be within (0, 86400] s");
    given.duration = true;
  } else if (key == "imu_rate_hz") {
    s.imu_rate_hz = r.number(n, name);
    r.check(n, name, s.imu_rate_hz >= 50 && s.imu_rate_hz <= 1000, "must be within 50..1000 Hz");
  } else if (read_segment_start_key(r, key, name, n, s)) {
    given.start_state = true;
  } else if (key == "odometer") {
    s.odometer = r.boolean(n, name);
  } else if (key == "odometer_scale_factor_error") {
    s.odometer_scale_factor_error = r.number(n, name);
    r.check(n, name, std::abs(s.odometer_scale_factor_error) < 0.5, "must be within +-0.5");
  } else if (key == "sideslip_deg_per_mps2") {
    s.sideslip_deg_per_mps2 = r.number(n, name);
    r.check(n, name, std::abs(s.sideslip_deg_per_mps2) <= 2, "must be within +-2 deg per m/s^2");
  } else if (key == "odometer_delay_s") {
    s.odometer_delay_s = r.number(n, name);
    r.check(n, name, s.odometer_delay_s >= 0 && s.odometer_delay_s <= 1, "must be within 0..1 s");
  } else if (key == "odometer_misalignment_pitch_deg" || key == "odometer_misalignment_yaw_deg") {
    double& m =
        key == "odometer_misalignment_pitch_deg" ? s.odometer_misalignment_pitch_deg : s.odometer_misalignment_yaw_deg;
    m = r.number(n, name);
    r.check(n, name, std::abs(m) <= 10, "must be within +-10 deg");
  } else {
    r.fail(n, name, "unknown key in [trajectory]");
  }
  if (!s.trajectory_profile.empty() && !s.trajectory_file.empty())
    r.fail(n, name, "give either profile or file, not both");
}

void read_imu_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n, Scenario& s) {
  if (key == "preset") {
    s.imu_preset = r.string(n, name);
    if (!in_list(ins::imu_preset_names(), s.imu_preset))
      r.fail(n, name, "unknown preset (" + joined(ins::imu_preset_names()) + ")");
  } else if (key == "seed") {
    const auto v = r.integer(n, name);
    r.check(n, name, v >= 0, "must be >= 0");
    s.imu_seed = static_cast<std::uint64_t>(v);
  } else if (key == "time_offset_s") {
    s.imu_time_offset_s = r.number(n, name);
    r.check(n, name, std::abs(s.imu_time_offset_s) <= 0.1, "must be within +-0.1 s");
  } else {
    const auto keys = ins::imu_datasheet_keys();
    const auto k = std::find_if(keys.begin(), keys.end(), [&](const auto& d) { return d.name == key; });
    if (k == keys.end()) r.fail(n, name, "unknown key in [imu]");
    const double v = r.number(n, name);
    const std::string problem = ins::datasheet_value_problem(*k, v);
    r.check(n, name, problem.empty(), problem);
    s.imu_datasheet.*(k->member) = v;
  }
}

void read_output_key(const Reader& r, const std::string& key, const std::string& name, const toml::node& n,
                     Scenario& s) {
  if (key == "truth_rate_hz") {
    s.truth_rate_hz = r.number(n, name);
    r.check(n, name, s.truth_rate_hz > 0 && s.truth_rate_hz <= 1000, "must be within (0, 1000] Hz");
  } else {
    r.fail(n, name, "unknown key in [output]");
  }
}

// One key of a plain [section] table.
void read_table_key(const Reader& r, const std::string& section, const toml::node& section_node, const std::string& key,
                    const toml::node& n, Scenario& s, GivenKeys& given) {
  const std::string name = section + "." + key;
  if (section == "signal") {
    given.signal = true;
    read_signal_key(r, key, name, n, s);
  } else if (section == "time") {
    read_time_key(r, key, name, n, s);
  } else if (section == "navigation") {
    read_navigation_key(r, key, name, n, s, given);
  } else if (section == "receiver") {
    read_receiver_key(r, key, name, n, s, given);
  } else if (section == "atmosphere") {
    read_atmosphere_key(r, key, name, n, s);
  } else if (section == "trajectory") {
    read_trajectory_key(r, key, name, n, s, given);
  } else if (section == "imu") {
    read_imu_key(r, key, name, n, s);
  } else if (section == "output") {
    read_output_key(r, key, name, n, s);
  } else {
    r.fail(section_node, section,
           "unknown section (signal, time, navigation, receiver, atmosphere, output, trajectory, imu, "
           "[[antenna]], [[cycle_slip]], [[blockage]], [[cn0_step]], [[odometer_slip]], [[vibration]])");
  }
}

void read_section(const Reader& r, const std::string& section, const toml::node& section_node, Scenario& s,
                  GivenKeys& given) {
  if (section == "antenna") {
    read_antennas(r, section_node, s);
    given.antennas = true;
  } else if (section == "cn0_step") {
    read_cn0_steps(r, section_node, s);
  } else if (section == "cycle_slip") {
    read_cycle_slips(r, section_node, s);
  } else if (section == "blockage") {
    read_blockages(r, section_node, s);
  } else if (section == "odometer_slip") {
    read_odometer_slips(r, section_node, s);
  } else if (section == "vibration") {
    read_vibrations(r, section_node, s);
  } else {
    const auto* tbl = section_node.as_table();
    if (!tbl) r.fail(section_node, section, "expected a table [" + section + "]");
    for (auto&& [k, n] : *tbl) read_table_key(r, section, section_node, std::string(k.str()), n, s, given);
  }
}

// The rules of inertial and static scenarios that depend on which keys were given.
void check_given_keys(const std::string& file, const GivenKeys& given, const Scenario& s) {
  const auto fail = [&](const std::string& problem) { throw InputError(file, problem); };
  if (!given.trajectory) {
    if (given.antennas) fail("[[antenna]] needs a [trajectory] section (static receivers: antenna_offsets_enu_m)");
    if (!s.vibrations.empty()) fail("[[vibration]] needs a [trajectory] section (the platform that vibrates)");
    if (given.attitude) fail("key receiver.attitude_deg: needs [trajectory] profile = \"static\"");
    return;
  }
  if (!s.trajectory_enabled()) fail("[trajectory] needs profile = \"NAME\" or file = \"segments.csv\"");
  if (!s.trajectory_profile.empty() && !given.duration) fail("key trajectory.duration_s: missing (profiles)");
  if (!s.trajectory_file.empty() && given.duration)
    fail("key trajectory.duration_s: a segment file sets its own duration");
  if (s.trajectory_file.empty() && given.start_state)
    fail("keys trajectory.speed_mps / heading_deg / coordinated_turns / ramp_s: only with a segment file");
  if (!s.trajectory.empty()) fail("key receiver.trajectory: not with a [trajectory] section");
  if (given.offsets) fail("key receiver.antenna_offsets_enu_m: with [trajectory] use [[antenna]] lever_arm_body_m");
  if (std::abs(s.llh_deg_m[0]) >= 89.0)
    fail("key receiver.llh_deg_m: latitude must be within +-89 deg with [trajectory]");
  if (given.attitude && s.trajectory_profile != "static")
    fail("key receiver.attitude_deg: needs [trajectory] profile = \"static\"");
}

}  // namespace

Scenario parse_scenario(std::string_view text, const std::filesystem::path& source,
                        const std::vector<TomlOverride>& overrides) {
  const std::string file = source.string();
  toml::table root;
  try {
    root = toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  try {
    apply_toml_overrides(root, overrides);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, e.what());
  }
  const Reader r(file);
  Scenario s;
  s.source = source;
  GivenKeys given;
  for (auto&& [section_key, section_node] : root)
    read_section(r, std::string(section_key.str()), section_node, s, given);
  if (given.rinex) s.constellation.clear();
  check_given_keys(file, given, s);
  s.signal = given.signal || !given.trajectory;
  // The rules on values (events on existing antennas and with a signal, IF against the format and rate).
  if (std::string why; !s.IsValid(&why)) throw InputError(file, why);
  return s;
}

Scenario read_scenario(const std::filesystem::path& path, const std::vector<TomlOverride>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open the scenario file: " + io::open_failure_reason());
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scenario(ss.str(), path, overrides);
}

}  // namespace ultratrack::config
