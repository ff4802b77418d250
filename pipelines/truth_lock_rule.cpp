// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/truth_lock_rule.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>

#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/named_csv.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kChipsPerCode = 1023.0;

struct TruthRow {
  std::int64_t sample = 0;
  double doppler_hz = 0.0, code_phase_chips = 0.0;
};

struct Record {
  std::int64_t sample = 0;
  double doppler_hz = 0.0, code_phase_chips = 0.0;
};

double wrap_chips(double chips) { return chips - kChipsPerCode * std::round(chips / kChipsPerCode); }

// The signal at sample n from the rows of one satellite (sorted by sample, at least one row).
struct SignalAt {
  double code_phase_chips, doppler_hz;
};
SignalAt signal_at(const std::vector<TruthRow>& rows, std::int64_t n, double fs_hz) {
  const auto after =
      std::lower_bound(rows.begin(), rows.end(), n, [](const TruthRow& r, std::int64_t s) { return r.sample < s; });
  const TruthRow* next = after == rows.end() ? nullptr : &*after;
  const TruthRow* previous = after == rows.begin() ? nullptr : &*(after - 1);
  const TruthRow& nearest = !previous ? *next
                            : !next   ? *previous
                                      : (n - previous->sample <= next->sample - n ? *previous : *next);
  double doppler = nearest.doppler_hz;
  if (previous && next && next->sample > previous->sample) {
    const double w = static_cast<double>(n - previous->sample) / static_cast<double>(next->sample - previous->sample);
    doppler = previous->doppler_hz + w * (next->doppler_hz - previous->doppler_hz);
  }
  const double dt_s = static_cast<double>(n - nearest.sample) / fs_hz;
  const double code_rate = signals::kCaChipRate_hz * (1.0 + nearest.doppler_hz / signals::kL1Frequency_hz);
  double code = std::fmod(nearest.code_phase_chips + dt_s * code_rate, kChipsPerCode);
  if (code < 0.0) code += kChipsPerCode;
  return {code, doppler};
}

}  // namespace

bool TruthLockOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  auto positive = [](double x) { return x > 0.0 && std::isfinite(x); };
  if (!(from_s >= 0.0) || !std::isfinite(from_s)) return fail("truth lock rule: from_s must be >= 0");
  if (!(end_s == 0.0 || (end_s > from_s && std::isfinite(end_s))))
    return fail("truth lock rule: end_s must be 0 (the truth's end) or after from_s");
  if (!positive(code_error_chips) || !positive(frequency_error_hz) || !positive(window_s) || !positive(max_gap_s))
    return fail("truth lock rule: the bounds, the window and the gap must be positive");
  return true;
}

std::vector<TruthLockOutcome> truth_lock_outcomes(const std::filesystem::path& satellite_truth_csv,
                                                  const std::filesystem::path& tracking_csv,
                                                  const TruthLockOptions& options) {
  if (std::string why; !options.IsValid(&why)) throw std::invalid_argument(why);

  const io::NamedCsv truth = io::read_named_csv(satellite_truth_csv);
  const auto t_sample = truth.column("sample"), t_time = truth.column("t_s"), t_prn = truth.column("prn"),
             t_doppler = truth.column("doppler_hz"), t_code = truth.column("code_phase_chips");
  std::map<int, std::vector<TruthRow>> signal;
  std::int64_t first_sample = 0, last_sample = 0;
  double first_t = 0.0, last_t = 0.0;
  for (std::size_t i = 0; i < truth.rows.size(); ++i) {
    const auto n = static_cast<std::int64_t>(truth.number(i, t_sample));
    const double t = truth.number(i, t_time);
    if (i == 0 || n < first_sample) first_sample = n, first_t = t;
    if (i == 0 || n > last_sample) last_sample = n, last_t = t;
    signal[static_cast<int>(truth.number(i, t_prn))].push_back(
        {n, truth.number(i, t_doppler), truth.number(i, t_code)});
  }
  if (last_sample <= first_sample || !(last_t > first_t))
    throw io::InputError(truth.file, "fewer than two truth rows: no sample rate");
  const double fs_hz = static_cast<double>(last_sample - first_sample) / (last_t - first_t);
  const double end_s = options.end_s > 0.0 ? options.end_s : static_cast<double>(last_sample) / fs_hz;
  for (auto& [prn, rows] : signal)
    std::sort(rows.begin(), rows.end(), [](const TruthRow& a, const TruthRow& b) { return a.sample < b.sample; });

  const io::NamedCsv tracking = io::read_named_csv(tracking_csv);
  const auto r_prn = tracking.column("prn"), r_sample = tracking.column("sample"),
             r_doppler = tracking.column("doppler_hz"), r_code = tracking.column("code_phase_chips");
  std::map<int, std::vector<Record>> records;
  for (std::size_t i = 0; i < tracking.rows.size(); ++i) {
    const auto n = static_cast<std::int64_t>(tracking.number(i, r_sample));
    const double t = static_cast<double>(n) / fs_hz;
    if (t < options.from_s - 0.5 / fs_hz || t > end_s) continue;
    records[static_cast<int>(tracking.number(i, r_prn))].push_back(
        {n, tracking.number(i, r_doppler), tracking.number(i, r_code)});
  }

  std::vector<TruthLockOutcome> outcomes;
  for (const auto& [prn, rows] : signal) {
    const auto from_sample = static_cast<std::int64_t>(std::llround(options.from_s * fs_hz));
    // Transmitted at from_s: a truth row within one row interval of it.
    const bool transmitted = std::any_of(rows.begin(), rows.end(), [&](const TruthRow& r) {
      return std::abs(static_cast<double>(r.sample - from_sample)) / fs_hz <= 0.11;
    });
    if (!transmitted) continue;
    TruthLockOutcome o;
    o.prn = prn;
    auto it = records.find(prn);
    if (it == records.end() || it->second.empty()) {
      o.outcome = "not_tracked";
      outcomes.push_back(o);
      continue;
    }
    std::vector<Record>& recs = it->second;
    std::sort(recs.begin(), recs.end(), [](const Record& a, const Record& b) { return a.sample < b.sample; });
    auto lose = [&](const char* reason, double t) {
      if (!o.outcome.empty() && o.lost_s <= t) return;
      o.outcome = "lost";
      o.reason = reason;
      o.lost_s = t;
    };
    double previous_t = options.from_s;
    long window = -1;
    double window_sum = 0.0, window_start_t = options.from_s;
    int window_count = 0;
    auto close_window = [&] {
      if (window_count == 0) return;
      const double mean = window_sum / window_count;
      if (o.outcome.empty()) o.max_frequency_error_hz = std::max(o.max_frequency_error_hz, std::abs(mean));
      if (std::abs(mean) > options.frequency_error_hz) lose("frequency", window_start_t);
    };
    for (const Record& r : recs) {
      const double t = static_cast<double>(r.sample) / fs_hz;
      if (t - previous_t > options.max_gap_s) lose("gap", previous_t);
      previous_t = t;
      const SignalAt s = signal_at(rows, r.sample, fs_hz);
      const double code_error = wrap_chips(r.code_phase_chips - s.code_phase_chips);
      if (o.outcome.empty()) {
        o.max_code_error_chips = std::max(o.max_code_error_chips, std::abs(code_error));
        ++o.records;
      }
      if (std::abs(code_error) > options.code_error_chips) lose("code", t);
      const long w = static_cast<long>(std::floor((t - options.from_s) / options.window_s));
      if (w != window) {
        close_window();
        window = w;
        window_sum = 0.0;
        window_count = 0;
        window_start_t = options.from_s + static_cast<double>(w) * options.window_s;
      }
      window_sum += r.doppler_hz - s.doppler_hz;
      ++window_count;
    }
    close_window();
    if (end_s - previous_t > options.max_gap_s) lose("end", previous_t);
    if (o.outcome.empty()) o.outcome = "kept";
    outcomes.push_back(o);
  }
  return outcomes;
}

std::string truth_lock_outcomes_text(const std::vector<TruthLockOutcome>& outcomes) {
  std::string text = "prn,outcome,reason,lost_s,max_code_error_chips,max_frequency_error_hz,records\n";
  for (const TruthLockOutcome& o : outcomes)
    text += fmt::format("{},{},{},{},{:.4f},{:.3f},{}\n", o.prn, o.outcome, o.reason,
                        std::isnan(o.lost_s) ? std::string{} : fmt::format("{:.3f}", o.lost_s), o.max_code_error_chips,
                        o.max_frequency_error_hz, o.records);
  return text;
}

void write_truth_lock_outcomes_csv(const std::filesystem::path& file, const std::vector<TruthLockOutcome>& outcomes) {
  io::write_file_atomically(file, truth_lock_outcomes_text(outcomes));
}

std::vector<TruthLockOutcome> read_truth_lock_outcomes_csv(const std::filesystem::path& file) {
  const io::NamedCsv csv = io::read_named_csv(file);
  const auto prn = csv.column("prn"), outcome = csv.column("outcome"), reason = csv.column("reason"),
             lost = csv.column("lost_s"), code = csv.column("max_code_error_chips"),
             frequency = csv.column("max_frequency_error_hz"), records = csv.column("records");
  std::vector<TruthLockOutcome> out;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    TruthLockOutcome o;
    o.prn = static_cast<int>(csv.number(i, prn));
    o.outcome = csv.rows[i][outcome];
    if (o.outcome != "kept" && o.outcome != "lost" && o.outcome != "not_tracked")
      throw io::InputError(csv.file, "outcome '" + o.outcome + "' is not kept, lost or not_tracked", csv.lines[i]);
    o.reason = csv.rows[i][reason];
    if (!csv.rows[i][lost].empty()) o.lost_s = csv.number(i, lost);
    o.max_code_error_chips = csv.number(i, code);
    o.max_frequency_error_hz = csv.number(i, frequency);
    o.records = static_cast<int>(csv.number(i, records));
    out.push_back(o);
  }
  return out;
}

}  // namespace ultratrack::pipelines
