// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_metrics.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/named_csv.hpp"
#include "io/numeric_csv.hpp"

namespace ultratrack::pipelines {
namespace {

using io::NamedCsv;
using io::read_named_csv;

bool is_locked(const std::string& state) { return state == "phase-locked" || state == "bit-synced"; }

struct Record {
  double t_s;
  bool locked;
};

// From recs[i0] (locked) on: kept while every record is locked and none is more than 0.2 s after the previous.
void follow_lock(const std::vector<Record>& recs, std::size_t i0, double duration_s, LockOutcome& o) {
  o.first_lock_s = fmt::format("{:.3f}", recs[i0].t_s);
  o.outcome = "kept";
  double end_t = recs.back().t_s, previous = recs[i0].t_s;
  for (std::size_t i = i0; i < recs.size(); ++i) {
    if (!recs[i].locked || recs[i].t_s - previous > 0.2) {  // records come every 20 ms
      o.outcome = "lost";
      end_t = previous;
      break;
    }
    previous = recs[i].t_s;
  }
  if (o.outcome == "kept" && end_t < duration_s - 0.2) o.outcome = "lost";
  o.lock_end_s = fmt::format("{:.3f}", end_t);
}

constexpr double kA = 6378137.0, kF = 1.0 / 298.257223563, kE2 = kF * (2.0 - kF);

std::array<double, 3> ecef(double lat_deg, double lon_deg, double h) {
  const double la = lat_deg * M_PI / 180.0, lo = lon_deg * M_PI / 180.0;
  const double n = kA / std::sqrt(1.0 - kE2 * std::sin(la) * std::sin(la));
  return {(n + h) * std::cos(la) * std::cos(lo), (n + h) * std::cos(la) * std::sin(lo),
          (n * (1.0 - kE2) + h) * std::sin(la)};
}

std::array<double, 3> ned(double lat_deg, double lon_deg, const std::array<double, 3>& d) {
  const double la = lat_deg * M_PI / 180.0, lo = lon_deg * M_PI / 180.0;
  const double sl = std::sin(la), cl = std::cos(la), so = std::sin(lo), co = std::cos(lo);
  return {-sl * co * d[0] - sl * so * d[1] + cl * d[2], -so * d[0] + co * d[1],
          -cl * co * d[0] - cl * so * d[1] - sl * d[2]};
}

// A simulation's truth.csv, interpolated linearly in time (t_s, seconds since the first sample).
struct TruthTrack {
  NamedCsv csv;
  std::vector<double> t;
  explicit TruthTrack(const std::filesystem::path& file) : csv(read_named_csv(file)) {
    if (csv.rows.size() < 2) throw io::InputError(csv.file, "fewer than two rows");
    const std::size_t t_col = csv.column("t_s");
    for (std::size_t r = 0; r < csv.rows.size(); ++r) t.push_back(csv.number(r, t_col));
  }
  bool covers(double time) const { return time >= t.front() && time <= t.back(); }
  // Column `c` at `time`, on the line through the two rows around it (the first or last two outside the span).
  double at(std::size_t c, double time) const {
    const std::size_t i = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), time) - t.begin()), 1, t.size() - 1);
    const double w = (time - t[i - 1]) / (t[i] - t[i - 1]);
    return csv.number(i - 1, c) + w * (csv.number(i, c) - csv.number(i - 1, c));
  }
};

}  // namespace

std::vector<LockOutcome> lock_outcomes(const std::vector<int>& prns, const std::filesystem::path& tracking_csv,
                                       double duration_s, const LockOutcomeOptions& options) {
  std::map<int, std::vector<Record>> by_prn;
  std::error_code ec;
  if (std::filesystem::exists(tracking_csv, ec)) {
    const NamedCsv csv = read_named_csv(tracking_csv);
    const std::size_t prn_col = csv.column("prn"), t_col = csv.column("time_s"), state_col = csv.column("state");
    for (std::size_t r = 0; r < csv.rows.size(); ++r)
      by_prn[static_cast<int>(csv.number(r, prn_col))].push_back(
          {csv.number(r, t_col), is_locked(csv.rows[r][state_col])});
  }
  std::vector<LockOutcome> out;
  for (const int prn : prns) {
    LockOutcome o{prn, "not_acquired", "", ""};
    const auto it = by_prn.find(prn);
    if (it != by_prn.end() && !it->second.empty()) {
      const std::vector<Record>& recs = it->second;
      if (options.strong_s > 0.0) {
        o.outcome = "not_locked_at_step";
        std::size_t last_before = recs.size();
        for (std::size_t i = 0; i < recs.size(); ++i)
          if (recs[i].t_s >= options.strong_s - 0.2 && recs[i].t_s <= options.strong_s) last_before = i;
        if (last_before < recs.size() && recs[last_before].locked) follow_lock(recs, last_before, duration_s, o);
      } else {
        o.outcome = "never_locked";
        const auto lock = std::find_if(recs.begin(), recs.end(), [](const Record& r) { return r.locked; });
        if (lock != recs.end() && lock->t_s <= options.lock_deadline_s)
          follow_lock(recs, static_cast<std::size_t>(lock - recs.begin()), duration_s, o);
      }
    }
    out.push_back(std::move(o));
  }
  return out;
}

void write_lock_outcomes_csv(const std::filesystem::path& file, const std::vector<LockOutcome>& outcomes) {
  std::string text = "prn,outcome,first_lock_s,lock_end_s\n";
  for (const LockOutcome& o : outcomes)
    text += fmt::format("{},{},{},{}\n", o.prn, o.outcome, o.first_lock_s, o.lock_end_s);
  io::write_file_atomically(file, text);
}

std::vector<LockOutcome> read_lock_outcomes_csv(const std::filesystem::path& file) {
  const NamedCsv csv = read_named_csv(file);
  const std::size_t prn = csv.column("prn"), outcome = csv.column("outcome"), first = csv.column("first_lock_s"),
                    end = csv.column("lock_end_s");
  std::vector<LockOutcome> out;
  for (std::size_t r = 0; r < csv.rows.size(); ++r)
    out.push_back({static_cast<int>(csv.number(r, prn)), csv.rows[r][outcome], csv.rows[r][first], csv.rows[r][end]});
  return out;
}

std::vector<NavZ> nav_z_scores(const std::filesystem::path& nav_csv, const std::filesystem::path& truth_csv,
                               const std::vector<double>& times_s) {
  const NamedCsv nav = read_named_csv(nav_csv);
  const TruthTrack track(truth_csv);
  const NamedCsv& truth = track.csv;
  std::vector<double> rt;
  const std::size_t nav_t = nav.column("t_s");
  for (std::size_t r = 0; r < nav.rows.size(); ++r) rt.push_back(nav.number(r, nav_t));
  const std::array<std::size_t, 6> truth_cols{truth.column("ecef_x_m"),  truth.column("ecef_y_m"),
                                              truth.column("ecef_z_m"),  truth.column("vel_n_mps"),
                                              truth.column("vel_e_mps"), truth.column("vel_d_mps")};
  const std::size_t lat = nav.column("lat_deg"), lon = nav.column("lon_deg"), height = nav.column("height_m");
  const std::array<std::size_t, 3> vel{nav.column("vel_n_mps"), nav.column("vel_e_mps"), nav.column("vel_d_mps")};
  const std::array<std::size_t, 6> sig{nav.column("sigma_n_m"),    nav.column("sigma_e_m"),
                                       nav.column("sigma_d_m"),    nav.column("sigma_vn_mps"),
                                       nav.column("sigma_ve_mps"), nav.column("sigma_vd_mps")};
  std::vector<NavZ> out;
  for (const double t : times_s) {
    const auto after = std::upper_bound(rt.begin(), rt.end(), t);
    if (after == rt.begin()) continue;
    const std::size_t j = static_cast<std::size_t>(after - rt.begin()) - 1;
    const double tr = rt[j];
    const auto lin = [&](std::size_t c) { return track.at(c, tr); };
    const double lat_deg = nav.number(j, lat), lon_deg = nav.number(j, lon);
    const std::array<double, 3> q = ecef(lat_deg, lon_deg, nav.number(j, height));
    const std::array<double, 3> ep =
        ned(lat_deg, lon_deg, {q[0] - lin(truth_cols[0]), q[1] - lin(truth_cols[1]), q[2] - lin(truth_cols[2])});
    NavZ row;
    row.t_s = t;
    for (int k = 0; k < 3; ++k) {
      row.error[k] = ep[k];
      row.error[3 + k] = nav.number(j, vel[k]) - lin(truth_cols[3 + k]);
    }
    for (int k = 0; k < 6; ++k) {
      row.sigma[k] = nav.number(j, sig[k]);
      row.z[k] = row.error[k] / row.sigma[k];
    }
    out.push_back(row);
  }
  return out;
}

WeakPartPositions weak_part_positions(const std::filesystem::path& solution_csv, const std::filesystem::path& nav_csv,
                                      const std::filesystem::path& truth_csv, double from_s) {
  const TruthTrack track(truth_csv);
  const std::array<std::size_t, 3> truth_r{track.csv.column("ecef_x_m"), track.csv.column("ecef_y_m"),
                                           track.csv.column("ecef_z_m")};
  const double tow0 = track.csv.number(0, track.csv.column("tow_s")) - track.t.front();
  // The truth position at t seconds since the first sample; false outside the truth's span.
  const auto truth_at = [&](double t, std::array<double, 3>& p) {
    if (!track.covers(t)) return false;
    for (int k = 0; k < 3; ++k) p[k] = track.at(truth_r[k], t);
    return true;
  };
  const auto accumulate = [](double e2, double& sum, double& worst, int& n) {
    sum += e2;
    worst = std::max(worst, std::sqrt(e2));
    ++n;
  };
  WeakPartPositions out;
  double sum = 0.0, worst = 0.0;
  if (std::filesystem::exists(solution_csv)) {
    const NamedCsv sol = read_named_csv(solution_csv);
    const std::size_t tow = sol.column("tow_s"), x = sol.column("ecef_x_m"), y = sol.column("ecef_y_m"),
                      z = sol.column("ecef_z_m");
    for (std::size_t r = 0; r < sol.rows.size(); ++r) {
      double t = sol.number(r, tow) - tow0;
      t -= 604800.0 * std::round(t / 604800.0);  // across a week rollover
      std::array<double, 3> p{};
      if (t < from_s - 1e-3 || !truth_at(t, p)) continue;
      const double dx = sol.number(r, x) - p[0], dy = sol.number(r, y) - p[1], dz = sol.number(r, z) - p[2];
      accumulate(dx * dx + dy * dy + dz * dz, sum, worst, out.fixes);
    }
  }
  out.rms_3d_m = out.fixes > 0 ? std::sqrt(sum / out.fixes) : NAN;
  out.max_3d_m = out.fixes > 0 ? worst : NAN;
  sum = worst = 0.0;
  if (std::filesystem::exists(nav_csv)) {
    const NamedCsv nav = read_named_csv(nav_csv);
    const std::size_t t_col = nav.column("t_s"), lat = nav.column("lat_deg"), lon = nav.column("lon_deg"),
                      height = nav.column("height_m");
    for (std::size_t r = 0; r < nav.rows.size(); ++r) {
      const double t = nav.number(r, t_col);
      std::array<double, 3> p{};
      if (t < from_s || !truth_at(t, p)) continue;
      const std::array<double, 3> q = ecef(nav.number(r, lat), nav.number(r, lon), nav.number(r, height));
      double e2 = 0.0;
      for (int k = 0; k < 3; ++k) e2 += (q[k] - p[k]) * (q[k] - p[k]);
      accumulate(e2, sum, worst, out.nav_rows);
    }
  }
  out.nav_rms_3d_m = out.nav_rows > 0 ? std::sqrt(sum / out.nav_rows) : NAN;
  out.nav_max_3d_m = out.nav_rows > 0 ? worst : NAN;
  return out;
}

namespace {
const char* const kAxes[6] = {"pn", "pe", "pd", "vn", "ve", "vd"};
}

void write_nav_z_csv(const std::filesystem::path& file, const std::vector<NavZ>& rows) {
  std::string text = "t_s";
  for (const char* prefix : {"z_", "error_", "sigma_"})
    for (const char* axis : kAxes) text += fmt::format(",{}{}", prefix, axis);
  text += '\n';
  for (const NavZ& r : rows) {
    text += fmt::format("{:.17g}", r.t_s);
    for (const auto* v : {&r.z, &r.error, &r.sigma})
      for (const double x : *v) text += fmt::format(",{:.17g}", x);
    text += '\n';
  }
  io::write_file_atomically(file, text);
}

std::vector<NavZ> read_nav_z_csv(const std::filesystem::path& file) {
  const NamedCsv csv = read_named_csv(file);
  std::vector<NavZ> out;
  const std::size_t t = csv.column("t_s");
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    NavZ row;
    row.t_s = csv.number(r, t);
    for (int k = 0; k < 6; ++k) {
      row.z[k] = csv.number(r, csv.column(std::string("z_") + kAxes[k]));
      row.error[k] = csv.number(r, csv.column(std::string("error_") + kAxes[k]));
      row.sigma[k] = csv.number(r, csv.column(std::string("sigma_") + kAxes[k]));
    }
    out.push_back(row);
  }
  return out;
}

}  // namespace ultratrack::pipelines
