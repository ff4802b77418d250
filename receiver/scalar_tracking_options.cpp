// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/scalar_tracking_options.hpp"

#include <sstream>

namespace ultratrack::receiver {
namespace {

// Appends "name = value outside range" when !ok, for the first failure only.
struct Checker {
  std::string error;
  void check(bool ok, const char* name, double value, const char* range) {
    if (ok || !error.empty()) return;
    std::ostringstream s;
    s << "tracking option " << name << " = " << value << " is outside " << range;
    error = s.str();
  }
};

}  // namespace

bool ScalarTrackingOptions::IsValid(std::string* why) const {
  const ScalarTrackingOptions& o = *this;
  const std::string problem = [&]() -> std::string {
    Checker c;
    c.check(o.pll_order == 2 || o.pll_order == 3, "pll_order", o.pll_order, "{2, 3}");
    c.check(o.pll_bw_hz > 0 && o.pll_bw_hz <= 50, "pll_bw_hz", o.pll_bw_hz, "(0, 50] Hz");
    c.check(o.pll_bw_coherent_hz > 0 && o.pll_bw_coherent_hz <= 15, "pll_bw_coherent_hz", o.pll_bw_coherent_hz,
            "(0, 15] Hz");
    c.check(o.fll_bw_hz > 0 && o.fll_bw_hz <= 50, "fll_bw_hz", o.fll_bw_hz, "(0, 50] Hz");
    c.check(o.fll_wide_time_s >= 0.01 && o.fll_wide_time_s <= 5, "fll_wide_time_s", o.fll_wide_time_s, "[0.01, 5] s");
    c.check(o.fll_narrow_time_s >= 0 && o.fll_narrow_time_s <= 5, "fll_narrow_time_s", o.fll_narrow_time_s, "[0, 5] s");
    c.check(o.fll_narrow_bw_hz > 0 && o.fll_narrow_bw_hz <= 20, "fll_narrow_bw_hz", o.fll_narrow_bw_hz, "(0, 20] Hz");
    c.check(o.pullin_lock_time_s >= 0.01 && o.pullin_lock_time_s <= 2, "pullin_lock_time_s", o.pullin_lock_time_s,
            "[0.01, 2] s");
    c.check(o.pullin_timeout_s >= 0.1 && o.pullin_timeout_s <= 30, "pullin_timeout_s", o.pullin_timeout_s,
            "[0.1, 30] s");
    c.check(o.fll_fine_time_s >= 0 && o.fll_fine_time_s <= 5, "fll_fine_time_s", o.fll_fine_time_s, "[0, 5] s");
    c.check(o.fll_fine_bw_hz > 0 && o.fll_fine_bw_hz <= 10, "fll_fine_bw_hz", o.fll_fine_bw_hz, "(0, 10] Hz");
    c.check(o.pullin_search_hz >= 0 && o.pullin_search_hz <= 500, "pullin_search_hz", o.pullin_search_hz,
            "[0, 500] Hz");
    c.check(o.pullin_search_time_s >= 0.05 && o.pullin_search_time_s <= 0.5, "pullin_search_time_s",
            o.pullin_search_time_s, "[0.05, 0.5] s");
    c.check(o.pll_bw_weak_hz > 0 && o.pll_bw_weak_hz <= 50, "pll_bw_weak_hz", o.pll_bw_weak_hz, "(0, 50] Hz");
    c.check(o.weak_cn0_dbhz >= 0 && o.weak_cn0_dbhz <= 60, "weak_cn0_dbhz", o.weak_cn0_dbhz, "[0, 60] dB-Hz");
    const double acquire_s = o.pullin_search_hz > 0 ? o.pullin_search_time_s : o.fll_wide_time_s + o.fll_narrow_time_s;
    const double pullin_min_s = acquire_s + o.fll_fine_time_s + o.pli_time_constant_s + o.pullin_lock_time_s;
    c.check(o.pullin_timeout_s > pullin_min_s, "pullin_timeout_s", o.pullin_timeout_s,
            "(search or wide + narrow FLL time, + fine FLL time + pli_time_constant_s + pullin_lock_time_s, 30] s");
    c.check(o.dll_bw_hz > 0 && o.dll_bw_hz <= 10, "dll_bw_hz", o.dll_bw_hz, "(0, 10] Hz");
    c.check(o.dll_bw_coherent_hz > 0 && o.dll_bw_coherent_hz <= 5, "dll_bw_coherent_hz", o.dll_bw_coherent_hz,
            "(0, 5] Hz");
    c.check(o.early_late_offset_chips > 0 && o.early_late_offset_chips <= 0.5, "early_late_offset_chips",
            o.early_late_offset_chips, "(0, 0.5] chips");
    c.check(!o.very_early_late ||
                (o.very_early_late_offset_chips > o.early_late_offset_chips && o.very_early_late_offset_chips <= 2),
            "very_early_late_offset_chips", o.very_early_late_offset_chips, "(early_late_offset_chips, 2] chips");
    c.check(o.coherent_ms == 1 || o.coherent_ms == 2 || o.coherent_ms == 4 || o.coherent_ms == 5 ||
                o.coherent_ms == 10 || o.coherent_ms == 20,
            "coherent_ms", o.coherent_ms, "{1, 2, 4, 5, 10, 20} ms");
    c.check(o.bit_sync.min_edges >= 3 && o.bit_sync.min_edges <= 1000, "bit_sync.min_edges", o.bit_sync.min_edges,
            "[3, 1000]");
    c.check(o.bit_sync.min_ratio >= 1.5 && o.bit_sync.min_ratio <= 100, "bit_sync.min_ratio", o.bit_sync.min_ratio,
            "[1.5, 100]");
    c.check(o.bit_sync.min_lead_sigma >= 3 && o.bit_sync.min_lead_sigma <= 100, "bit_sync.min_lead_sigma",
            o.bit_sync.min_lead_sigma, "[3, 100]");
    c.check(o.bit_sync.min_energy_bits >= 10 && o.bit_sync.min_energy_bits <= 1000, "bit_sync.min_energy_bits",
            o.bit_sync.min_energy_bits, "[10, 1000]");
    c.check(o.bit_sync.min_energy_sigma >= 3 && o.bit_sync.min_energy_sigma <= 100, "bit_sync.min_energy_sigma",
            o.bit_sync.min_energy_sigma, "[3, 100]");
    c.check(o.bit_sync.max_periods >= 200, "bit_sync.max_periods", o.bit_sync.max_periods, "[200, inf)");
    c.check(o.cn0_window_s >= 0.02 && o.cn0_window_s <= 5, "cn0_window_s", o.cn0_window_s, "[0.02, 5] s");
    c.check(o.cn0_loss_threshold_dbhz >= 0 && o.cn0_loss_threshold_dbhz <= 45, "cn0_loss_threshold_dbhz",
            o.cn0_loss_threshold_dbhz, "[0, 45] dB-Hz");
    c.check(o.pli_time_constant_s >= 0.005 && o.pli_time_constant_s <= 5, "pli_time_constant_s", o.pli_time_constant_s,
            "[0.005, 5] s");
    c.check(o.pli_lock_threshold > 0 && o.pli_lock_threshold < 1, "pli_lock_threshold", o.pli_lock_threshold, "(0, 1)");
    c.check(o.pli_loss_threshold >= -1 && o.pli_loss_threshold < o.pli_lock_threshold, "pli_loss_threshold",
            o.pli_loss_threshold, "[-1, pli_lock_threshold)");
    c.check(o.loss_of_lock_time_s >= 0.02 && o.loss_of_lock_time_s <= 10, "loss_of_lock_time_s", o.loss_of_lock_time_s,
            "[0.02, 10] s");
    c.check(o.max_coherent_ms == 20 || o.max_coherent_ms == 40 || o.max_coherent_ms == 100 ||
                o.max_coherent_ms == 200 || o.max_coherent_ms == 400,
            "max_coherent_ms", o.max_coherent_ms, "{20, 40, 100, 200, 400} ms");
    c.check(o.coherent_jitter_deg > 0 && o.coherent_jitter_deg <= 30, "coherent_jitter_deg", o.coherent_jitter_deg,
            "(0, 30] deg");
    c.check(o.coherent_hysteresis_db >= 0 && o.coherent_hysteresis_db <= 10, "coherent_hysteresis_db",
            o.coherent_hysteresis_db, "[0, 10] dB");
    c.check(o.coherent_max_bn_t > 0 && o.coherent_max_bn_t <= 0.25, "coherent_max_bn_t", o.coherent_max_bn_t,
            "(0, 0.25]");
    c.check(o.oscillator_h0 >= 0 && o.oscillator_h0 <= 1e-17, "oscillator_h0", o.oscillator_h0, "[0, 1e-17] s");
    c.check(o.oscillator_h_minus2 >= 0 && o.oscillator_h_minus2 <= 1e-17, "oscillator_h_minus2", o.oscillator_h_minus2,
            "[0, 1e-17] 1/s");
    c.check(o.presence_window_s >= 0.1 && o.presence_window_s <= 5, "presence_window_s", o.presence_window_s,
            "[0.1, 5] s");
    c.check(o.presence_threshold_dbhz >= 0 && o.presence_threshold_dbhz <= 30, "presence_threshold_dbhz",
            o.presence_threshold_dbhz, "[0, 30] dB-Hz");
    c.check(o.presence_max_windows >= 1 && o.presence_max_windows <= 10, "presence_max_windows", o.presence_max_windows,
            "[1, 10]");
    c.check(o.presence_false_loss_per_min > 0 && o.presence_false_loss_per_min < 1, "presence_false_loss_per_min",
            o.presence_false_loss_per_min, "(0, 1)");
    c.check(o.presence_relock_dbhz >= o.presence_threshold_dbhz && o.presence_relock_dbhz <= 40, "presence_relock_dbhz",
            o.presence_relock_dbhz, "[presence_threshold_dbhz, 40] dB-Hz");
    return c.error;
  }();
  if (why) *why = problem;
  return problem.empty();
}

bool set_tracking_oscillator(ScalarTrackingOptions& o, const std::string& name) {
  if (name == "ideal" || name == "none") {
    o.oscillator_h0 = o.oscillator_h_minus2 = 0.0;
    return true;
  }
  const auto allan = signals::oscillator_signal_preset(name);
  if (!allan) return false;
  o.oscillator_h0 = allan->h0;
  o.oscillator_h_minus2 = allan->h_minus2;
  return true;
}

std::string tracking_oscillator_name(const ScalarTrackingOptions& o) {
  if (o.oscillator_h0 == 0.0 && o.oscillator_h_minus2 == 0.0) return "ideal";
  for (const std::string& name : signals::oscillator_preset_names()) {
    const auto allan = signals::oscillator_signal_preset(name);
    if (o.oscillator_h0 == allan->h0 && o.oscillator_h_minus2 == allan->h_minus2) return name;
  }
  return "custom";
}

ChannelConfig channel_config(const ScalarTrackingOptions& o, int prn, double sample_rate_hz, int num_antennas) {
  ChannelConfig c;
  c.prn = prn;
  c.sample_rate_hz = sample_rate_hz;
  c.num_antennas = num_antennas;
  c.layout.early_late_offset_chips = o.early_late_offset_chips;
  c.layout.very_early_late = o.very_early_late;
  c.layout.very_early_late_offset_chips = o.very_early_late_offset_chips;
  c.layout.noise = o.cn0_method == Cn0Method::kNoiseTap;
  return c;
}

}  // namespace ultratrack::receiver
