// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/receive_config_toml.hpp"

#include <toml++/toml.h>

#include <functional>
#include <map>
#include <string>

#include "io/units.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::config {
namespace {

struct Setter {
  std::string file, key;
  const toml::node& node;

  double number() const {
    if (auto v = node.value<double>()) return *v;
    throw signals::InputError(file, "key '" + key + "' must be a number", static_cast<int>(node.source().begin.line));
  }
  int integer() const {
    if (auto v = node.value<std::int64_t>()) return static_cast<int>(*v);
    throw signals::InputError(file, "key '" + key + "' must be an integer", static_cast<int>(node.source().begin.line));
  }
  bool boolean() const {
    if (auto v = node.value<bool>()) return *v;
    throw signals::InputError(file, "key '" + key + "' must be true or false",
                              static_cast<int>(node.source().begin.line));
  }
};

using Table = std::map<std::string, std::function<void(const Setter&, receiver::ReceiverOptions&)>>;

const std::map<std::string, Table>& sections() {
  using O = receiver::ReceiverOptions;
  static const std::map<std::string, Table> s = {
      {"receiver",
       {{"channels", [](const Setter& v, O& o) { o.channels = v.integer(); }},
        {"prns",
         [](const Setter& v, O& o) {
           const auto* array = v.node.as_array();
           if (!array) throw signals::InputError(v.file, "key '" + v.key + "' must be an array of PRNs");
           o.prns.clear();
           for (const auto& item : *array) o.prns.push_back(Setter{v.file, v.key, item}.integer());
         }},
        {"reference_week", [](const Setter& v, O& o) { o.reference_week = v.integer(); o.reference_week_is_signal_week = true; }},
        {"observation_interval_s", [](const Setter& v, O& o) { o.observation_interval_s = v.number(); }},
        {"reacquisition_interval_s", [](const Setter& v, O& o) { o.reacquisition_interval_s = v.number(); }},
        {"reacquisition_latency_s", [](const Setter& v, O& o) { o.reacquisition_latency_s = v.number(); }},
        {"blind_prns_per_snapshot", [](const Setter& v, O& o) { o.blind_prns_per_snapshot = v.integer(); }},
        {"blind_revisit_s", [](const Setter& v, O& o) { o.blind_revisit_s = v.number(); }},
        {"hidden_prn_check_interval_s", [](const Setter& v, O& o) { o.hidden_prn_check_interval_s = v.number(); }},
        {"threads", [](const Setter& v, O& o) { o.threads = v.integer(); }},
        {"assisted_doppler_half_width_hz", [](const Setter& v, O& o) { o.assisted_doppler_half_width_hz = v.number(); }},
        {"initial_travel_time_s", [](const Setter& v, O& o) { o.initial_travel_time_s = v.number(); }},
        {"clock_jump_threshold_s", [](const Setter& v, O& o) { o.clock_jump_threshold_s = v.number(); }},
        {"smoothing_window_s", [](const Setter& v, O& o) { o.smoothing_window_s = v.number(); }},
        {"nav_bits", [](const Setter& v, O& o) { o.nav_bits = receiver::parse_nav_bit_source(v.file, v.node.value<std::string>().value_or("")); }},
        {"tracking_record_interval_s", [](const Setter& v, O& o) { o.tracking_record_interval_s = v.number(); }}}},
      {"acquisition",
       {{"coherent_ms", [](const Setter& v, O& o) { o.acquisition.coherent_ms = v.integer(); }},
        {"noncoherent", [](const Setter& v, O& o) { o.acquisition.noncoherent = v.integer(); }},
        {"doppler_max_hz", [](const Setter& v, O& o) { o.acquisition.doppler_max_hz = v.number(); }},
        {"doppler_step_hz", [](const Setter& v, O& o) { o.acquisition.doppler_step_hz = v.number(); }},
        {"pfa", [](const Setter& v, O& o) { o.acquisition.pfa = v.number(); }}}},
      {"tracking",
       {{"pll_order", [](const Setter& v, O& o) { o.tracking.pll_order = v.integer(); }},
        {"pll_bw_hz", [](const Setter& v, O& o) { o.tracking.pll_bw_hz = v.number(); }},
        {"pll_bw_coherent_hz", [](const Setter& v, O& o) { o.tracking.pll_bw_coherent_hz = v.number(); }},
        {"fll_bw_hz", [](const Setter& v, O& o) { o.tracking.fll_bw_hz = v.number(); }},
        {"fll_wide_time_s", [](const Setter& v, O& o) { o.tracking.fll_wide_time_s = v.number(); }},
        {"fll_narrow_bw_hz", [](const Setter& v, O& o) { o.tracking.fll_narrow_bw_hz = v.number(); }},
        {"fll_narrow_time_s", [](const Setter& v, O& o) { o.tracking.fll_narrow_time_s = v.number(); }},
        {"fll_fine_bw_hz", [](const Setter& v, O& o) { o.tracking.fll_fine_bw_hz = v.number(); }},
        {"fll_fine_time_s", [](const Setter& v, O& o) { o.tracking.fll_fine_time_s = v.number(); }},
        {"pullin_lock_time_s", [](const Setter& v, O& o) { o.tracking.pullin_lock_time_s = v.number(); }},
        {"pullin_timeout_s", [](const Setter& v, O& o) { o.tracking.pullin_timeout_s = v.number(); }},
        {"pullin_search_hz", [](const Setter& v, O& o) { o.tracking.pullin_search_hz = v.number(); }},
        {"pullin_search_time_s", [](const Setter& v, O& o) { o.tracking.pullin_search_time_s = v.number(); }},
        {"pll_bw_weak_hz", [](const Setter& v, O& o) { o.tracking.pll_bw_weak_hz = v.number(); }},
        {"weak_cn0_dbhz", [](const Setter& v, O& o) { o.tracking.weak_cn0_dbhz = v.number(); }},
        {"bit_sync_energy_test", [](const Setter& v, O& o) { o.tracking.bit_sync.energy_test = v.boolean(); }},
        {"bit_sync_min_energy_sigma", [](const Setter& v, O& o) { o.tracking.bit_sync.min_energy_sigma = v.number(); }},
        {"dll_bw_hz", [](const Setter& v, O& o) { o.tracking.dll_bw_hz = v.number(); }},
        {"dll_bw_coherent_hz", [](const Setter& v, O& o) { o.tracking.dll_bw_coherent_hz = v.number(); }},
        {"early_late_offset_chips", [](const Setter& v, O& o) { o.tracking.early_late_offset_chips = v.number(); }},
        {"coherent_ms", [](const Setter& v, O& o) { o.tracking.coherent_ms = v.integer(); }},
        {"cn0_window_s", [](const Setter& v, O& o) { o.tracking.cn0_window_s = v.number(); }},
        {"cn0_loss_threshold_dbhz", [](const Setter& v, O& o) { o.tracking.cn0_loss_threshold_dbhz = v.number(); }},
        {"pli_time_constant_s", [](const Setter& v, O& o) { o.tracking.pli_time_constant_s = v.number(); }},
        {"pli_lock_threshold", [](const Setter& v, O& o) { o.tracking.pli_lock_threshold = v.number(); }},
        {"pli_loss_threshold", [](const Setter& v, O& o) { o.tracking.pli_loss_threshold = v.number(); }},
        {"loss_of_lock_time_s", [](const Setter& v, O& o) { o.tracking.loss_of_lock_time_s = v.number(); }},
        {"max_coherent_ms", [](const Setter& v, O& o) { o.tracking.max_coherent_ms = v.integer(); }},
        {"adaptive_coherent", [](const Setter& v, O& o) { o.tracking.adaptive_coherent = v.boolean(); }},
        {"coherent_jitter_deg", [](const Setter& v, O& o) { o.tracking.coherent_jitter_deg = v.number(); }},
        {"coherent_hysteresis_db", [](const Setter& v, O& o) { o.tracking.coherent_hysteresis_db = v.number(); }},
        {"coherent_max_bn_t", [](const Setter& v, O& o) { o.tracking.coherent_max_bn_t = v.number(); }},
        {"oscillator", [](const Setter& v, O& o) {
           // The front end's oscillator class as a tracking loop sees it (signals/oscillator_allan.hpp).
           if (!receiver::set_tracking_oscillator(o.tracking, v.node.value<std::string>().value_or("")))
             throw signals::InputError(v.file, "key '" + v.key + "' must be \"tcxo\", \"ocxo\" or \"ideal\"",
                                       static_cast<int>(v.node.source().begin.line));
         }},
        {"oscillator_h0", [](const Setter& v, O& o) { o.tracking.oscillator_h0 = v.number(); }},
        {"oscillator_h_minus2", [](const Setter& v, O& o) { o.tracking.oscillator_h_minus2 = v.number(); }},
        {"presence_window_s", [](const Setter& v, O& o) { o.tracking.presence_window_s = v.number(); }},
        {"presence_threshold_dbhz", [](const Setter& v, O& o) { o.tracking.presence_threshold_dbhz = v.number(); }},
        {"presence_max_windows", [](const Setter& v, O& o) { o.tracking.presence_max_windows = v.integer(); }},
        {"presence_false_loss_per_min", [](const Setter& v, O& o) { o.tracking.presence_false_loss_per_min = v.number(); }},
        {"presence_relock_dbhz", [](const Setter& v, O& o) { o.tracking.presence_relock_dbhz = v.number(); }}}},
      {"pvt",
       {{"elevation_mask_deg", [](const Setter& v, O& o) { o.pvt.elevation_mask_rad = v.number() * io::kRadPerDeg; }},
        {"troposphere", [](const Setter& v, O& o) { o.pvt.troposphere = v.boolean(); }},
        {"ionosphere", [](const Setter& v, O& o) { o.pvt.ionosphere = v.boolean(); }},
        {"exclude_unhealthy", [](const Setter& v, O& o) { o.pvt.exclude_unhealthy = v.boolean(); }},
        {"fault_exclusion", [](const Setter& v, O& o) { o.pvt.fault_exclusion = v.boolean(); }},
        {"sigma_zenith_m", [](const Setter& v, O& o) { o.pvt.sigma_zenith_m = v.number(); }},
        {"sigma_doppler_mps", [](const Setter& v, O& o) { o.pvt.sigma_doppler_mps = v.number(); }},
        {"max_gdop", [](const Setter& v, O& o) { o.pvt.max_gdop = v.number(); }}}},
  };
  return s;
}

}  // namespace

void apply_receive_config(const std::filesystem::path& path, receiver::ReceiverOptions& options) {
  const std::string file = path.string();
  if (!std::filesystem::is_regular_file(path)) throw signals::InputError(file, "configuration file does not exist");
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    throw signals::InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  for (const auto& [section_key, section_node] : root) {
    const std::string section(section_key.str());
    const auto known = sections().find(section);
    const auto* table = section_node.as_table();
    if (known == sections().end() || !table)
      throw signals::InputError(file, "unknown section '" + section + "' (receiver, acquisition, tracking, pvt)",
                                static_cast<int>(section_node.source().begin.line));
    for (const auto& [key_name, node] : *table) {
      const std::string key = section + "." + std::string(key_name.str());
      const auto setter = known->second.find(std::string(key_name.str()));
      if (setter == known->second.end())
        throw signals::InputError(file, "unknown key '" + key + "'", static_cast<int>(node.source().begin.line));
      setter->second(Setter{file, key, node}, options);
    }
  }
}

}  // namespace ultratrack::config
