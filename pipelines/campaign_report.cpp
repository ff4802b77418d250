// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_report.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "io/input_error.hpp"
#include "pipelines/campaign_metrics.hpp"
#include "pipelines/campaign_run.hpp"
#include "pipelines/campaign_tables.hpp"
#include "pipelines/truth_lock_rule.hpp"

namespace ultratrack::pipelines {
namespace {

namespace fs = std::filesystem;

struct CompleteRun {
  const CampaignRun* run;
  fs::path dir;
  CampaignRunStatus status;
};

std::string group_key(const CampaignRun& run, const std::vector<std::string>& group) {
  std::string key;
  for (const std::string& name : group) {
    const std::string* value = run.find(name);
    key += (key.empty() ? "" : " ") + (value ? *value : std::string("-"));
  }
  return key;
}

std::string group_title(const std::vector<std::string>& group, const std::string& key) {
  if (group.empty()) return "";
  std::string title = "== ";
  for (const std::string& name : group) title += name + " ";
  return title + key + "\n";
}

// Runs split by their group key, keys in sorted order (the scripts sort their couplings and filters).
std::map<std::string, std::vector<const CompleteRun*>> split(const std::vector<CompleteRun>& runs,
                                                             const std::vector<std::string>& group) {
  std::map<std::string, std::vector<const CompleteRun*>> out;
  for (const CompleteRun& r : runs) out[group_key(*r.run, group)].push_back(&r);
  return out;
}

double number(const std::string& text, const std::string& what) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw io::InputError("campaign report", what + " is not a number: '" + text + "'");
}

// The lowest level above which the curve stays >= 0.9, interpolated between the bracketing levels.
std::string crossing(const std::vector<std::pair<double, double>>& pts) {
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!std::all_of(pts.begin() + static_cast<long>(i), pts.end(), [](const auto& p) { return p.second >= 0.9; }))
      continue;
    if (i == 0) return fmt::format("<= {:.1f}", pts[0].first);
    const auto [L0, v0] = pts[i - 1];
    const auto [L1, v1] = pts[i];
    return fmt::format("{:.2f}", L0 + (0.9 - v0) * (L1 - L0) / (v1 - v0));
  }
  return "None";
}

// The same satellite-runs judged by the common rule (truth_lock_outcomes.csv), when the runs wrote it.
std::string common_rule_table(const std::vector<const CompleteRun*>& members, const CampaignReduction& r) {
  std::map<double, std::map<std::string, int>> count;  // level -> outcome or loss reason -> satellite-runs
  for (const CompleteRun* run : members) {
    const fs::path file = run->dir / "truth_lock_outcomes.csv";
    const std::string* level = run->run->find(r.level);
    if (!level || !fs::exists(file)) continue;
    auto& c = count[number(*level, r.level)];
    for (const TruthLockOutcome& o : read_truth_lock_outcomes_csv(file)) {
      ++c[o.outcome];
      ++c["runs"];
      if (o.outcome == "lost") ++c[o.reason];
    }
  }
  if (count.empty()) return "";
  std::string out =
      "common loss-of-lock rule (simulator truth: code <= 0.5 chip, 1 s mean frequency error <= 2.5 Hz, no gap)\n"
      "cn0_dbhz  runs  kept  lost (code/frequency/gap/end)  not_tracked  kept_of_tracked  wilson68\n";
  std::vector<std::pair<double, double>> curve, hi_curve, lo_curve;
  for (auto& [L, c] : count) {
    const int tracked = c["kept"] + c["lost"];  // not_tracked left out, as not_acquired above
    const double f = tracked ? static_cast<double>(c["kept"]) / tracked : std::nan("");
    const auto [lo, hi] = wilson_interval(c["kept"], tracked, 1.0);
    curve.emplace_back(L, f), hi_curve.emplace_back(L, hi), lo_curve.emplace_back(L, lo);
    out += fmt::format("{:8.1f}  {:4d}  {:4d}  {:4d} ({:>20})  {:11d}  {:15.3f}  [{:.3f}, {:.3f}]\n", L, c["runs"],
                       c["kept"], c["lost"], fmt::format("{}/{}/{}/{}", c["code"], c["frequency"], c["gap"], c["end"]),
                       c["not_tracked"], f, lo, hi);
  }
  out += fmt::format("90 % threshold by the common rule: {} dB-Hz; from the 68 % intervals: {} .. {}\n",
                     crossing(curve), crossing(hi_curve), crossing(lo_curve));
  return out;
}

std::string lock_threshold(const std::vector<CompleteRun>& runs, const CampaignReduction& r) {
  std::string out;
  for (const auto& [key, members] : split(runs, r.group)) {
    std::map<double, std::map<std::string, int>> count;  // level -> outcome -> satellite-runs
    bool step_mode = false;
    for (const CompleteRun* run : members) {
      const fs::path file = run->dir / "lock_outcomes.csv";
      if (!fs::exists(file)) continue;
      const std::string* level = run->run->find(r.level);
      if (!level)
        throw io::InputError("campaign report", "lock threshold: the runs have no parameter '" + r.level + "'");
      auto& c = count[number(*level, r.level)];
      for (const LockOutcome& o : read_lock_outcomes_csv(file)) {
        ++c[o.outcome];
        ++c["runs"];
        step_mode = step_mode || o.outcome == "not_locked_at_step";
      }
    }
    out += group_title(r.group, key);
    out +=
        "cn0_dbhz  runs  kept  lost  never_locked  not_acquired  fraction_kept  wilson68        kept_of_locked  "
        "wilson68";
    out += step_mode ? "        not_locked_at_step\n" : "\n";
    std::vector<std::pair<double, double>> f_curve, f_hi, f_lo, g_curve, g_hi, g_lo;
    for (auto& [L, c] : count) {
      const int n = c["kept"] + c["lost"] + c["never_locked"];
      const double f = n ? static_cast<double>(c["kept"]) / n : std::nan("");
      const auto [lo, hi] = wilson_interval(c["kept"], n, 1.0);
      const int m = c["kept"] + c["lost"];
      const double g = m ? static_cast<double>(c["kept"]) / m : 0.0;
      const auto [glo, ghi] = wilson_interval(c["kept"], m, 1.0);
      f_curve.emplace_back(L, f), f_hi.emplace_back(L, hi), f_lo.emplace_back(L, lo);
      g_curve.emplace_back(L, g), g_hi.emplace_back(L, ghi), g_lo.emplace_back(L, glo);
      out += fmt::format(
          "{:8.1f}  {:4d}  {:4d}  {:4d}  {:12d}  {:12d}  {:13.3f}  [{:.3f}, {:.3f}]  {:14.3f}  [{:.3f}, {:.3f}]", L,
          c["runs"], c["kept"], c["lost"], c["never_locked"], c["not_acquired"], f, lo, hi, g, glo, ghi);
      out += step_mode ? fmt::format("  {:18d}\n", c["not_locked_at_step"]) : "\n";
    }
    if (!step_mode)  // in the step protocol both fractions are kept / (kept + lost)
      out += fmt::format(
          "90 % threshold, of acquired satellites (pull-in included): {} dB-Hz; from the 68 % "
          "intervals: {} .. {}\n",
          crossing(f_curve), crossing(f_hi), crossing(f_lo));
    out +=
        fmt::format("90 % threshold, of locked satellites (lock kept): {} dB-Hz; from the 68 % intervals: {} .. {}\n",
                    crossing(g_curve), crossing(g_hi), crossing(g_lo));
    out += common_rule_table(members, r);
  }
  return out;
}

// Wilson-Hilferty, good to < 1 % of the band for k >= 20.
double chi2_quantile(double zp, double k) {
  return k * std::pow(1.0 - 2.0 / (9.0 * k) + zp * std::sqrt(2.0 / (9.0 * k)), 3);
}

std::string nav_consistency(const std::vector<CompleteRun>& runs, const CampaignReduction& r) {
  std::string out;
  for (const auto& [key, members] : split(runs, r.group)) {
    // Runs whose fusion started (ultra-tight: that handed over), with their z rows by evaluation time.
    std::vector<std::vector<NavZ>> used;
    std::vector<double> handover;
    for (const CompleteRun* run : members) {
      const auto& s = run->status.scalars;
      const auto get = [&](const char* name) { return s.count(name) ? s.at(name) : std::string(); };
      if (get("navigation_started") != "1") continue;
      if (get("coupling") == "ultra-tight") {
        if (get("handed_over") != "1") continue;
        handover.push_back(number(get("handover_t_s"), "handover_t_s"));
      }
      if (!fs::exists(run->dir / "nav_z.csv")) continue;
      used.push_back(read_nav_z_csv(run->dir / "nav_z.csv"));
    }
    const std::string label = key.empty() ? "runs" : key;
    const double n = static_cast<double>(used.size());
    if (used.empty()) {
      out += label + ": no run handed over\n";
      continue;
    }
    out += handover.empty() ? fmt::format("{}: {} runs (no hand-over: tight coupling)\n", label, used.size())
                            : fmt::format("{}: {} runs handed over, hand-over at {:.2f}-{:.2f} s\n", label, used.size(),
                                          *std::min_element(handover.begin(), handover.end()),
                                          *std::max_element(handover.begin(), handover.end()));
    out += fmt::format(
        "  bands (95 %): mean z +-{:.2f}; mean z^2 per axis [{:.2f}, {:.2f}]; sum of 3 axes [{:.2f}, "
        "{:.2f}] (if uncorrelated)\n",
        1.96 / std::sqrt(n), chi2_quantile(-1.959964, n) / n, chi2_quantile(1.959964, n) / n,
        chi2_quantile(-1.959964, 3 * n) / n, chi2_quantile(1.959964, 3 * n) / n);
    out +=
        "  t_s   | mean z  pN    pE    pD    vN    vE    vD   | mean z^2 pN   pE   pD   vN   vE   vD  | pos sum vel "
        "sum | "
        "RMS err pos m  vel m/s | RMS sigma pos m vel m/s\n";
    for (const double t : r.times_s) {
      std::vector<const NavZ*> at;
      for (const auto& rows : used)
        for (const NavZ& row : rows)
          if (row.t_s == t) at.push_back(&row);
      if (at.empty()) continue;
      const double m = static_cast<double>(at.size());
      std::array<double, 6> mz{}, mz2{};
      double e_pos = 0, e_vel = 0, s_pos = 0, s_vel = 0;
      for (const NavZ* z : at) {
        for (int i = 0; i < 6; ++i) {
          mz[i] += z->z[i];
          mz2[i] += z->z[i] * z->z[i];
          (i < 3 ? e_pos : e_vel) += z->error[i] * z->error[i];
          (i < 3 ? s_pos : s_vel) += z->sigma[i] * z->sigma[i];
        }
      }
      for (int i = 0; i < 6; ++i) mz[i] /= m, mz2[i] /= m;
      out += fmt::format("  {:5.1f} | ", t);
      for (int i = 0; i < 6; ++i) out += fmt::format("{}{:+5.2f}", i ? " " : "", mz[i]);
      out += "  | ";
      for (int i = 0; i < 6; ++i) out += fmt::format("{}{:4.2f}", i ? " " : "", mz2[i]);
      out += fmt::format(" | {:5.2f}  {:5.2f}  | {:6.3f} {:8.4f}    | {:6.3f} {:8.4f}\n", mz2[0] + mz2[1] + mz2[2],
                         mz2[3] + mz2[4] + mz2[5], std::sqrt(e_pos / m), std::sqrt(e_vel / m), std::sqrt(s_pos / m),
                         std::sqrt(s_vel / m));
    }
  }
  return out;
}

// Two-sided 95 % Student-t quantile for `dof` degrees of freedom (1.96 beyond the table).
double student_t95(int dof) {
  static const double table[] = {12.706, 4.303, 2.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                 2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                 2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
  return dof >= 1 && dof <= 30 ? table[dof - 1] : 1.96;
}

std::string stats(const std::vector<CompleteRun>& runs, const CampaignReduction& r) {
  std::string out = fmt::format("{}: {:>5} {:>12} {:>25} {:>12} {:>12} {:>12} {:>12}\n", r.value, "runs", "mean",
                                "95 % interval of mean", "median", "std", "min", "max");
  for (const auto& [key, members] : split(runs, r.group)) {
    std::vector<double> v;
    for (const CompleteRun* run : members) {
      const auto it = run->status.scalars.find(r.value);
      const std::string* p = run->run->find(r.value);
      if (it != run->status.scalars.end())
        v.push_back(number(it->second, r.value));
      else if (p)
        v.push_back(number(*p, r.value));
    }
    if (v.empty()) continue;
    std::sort(v.begin(), v.end());
    const double n = static_cast<double>(v.size());
    double mean = 0, var = 0;
    for (const double x : v) mean += x / n;
    for (const double x : v) var += (x - mean) * (x - mean);
    const double sd = v.size() > 1 ? std::sqrt(var / (n - 1)) : 0.0;
    const double half = v.size() > 1 ? student_t95(static_cast<int>(v.size()) - 1) * sd / std::sqrt(n) : 0.0;
    const double median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    out += fmt::format("{:>{}} {:5d} {:12.4g} {:>25} {:12.4g} {:12.4g} {:12.4g} {:12.4g}\n",
                       r.group.empty() ? "all" : key, r.value.size() + 1, v.size(), mean,
                       fmt::format("[{:.4g}, {:.4g}]", mean - half, mean + half), median, sd, v.front(), v.back());
  }
  if (!r.group.empty()) out = group_title(r.group, "") + out;
  return out;
}

// The rms, table and error_stats reductions: each group's runs as their parameters and scalars.
std::string tables(const std::vector<CompleteRun>& runs, const CampaignReduction& r) {
  std::string out;
  for (const auto& [key, members] : split(runs, r.group)) {
    std::vector<CampaignRunValues> values;
    for (const CompleteRun* run : members) {
      CampaignRunValues v = run->status.scalars;
      for (const auto& [name, value] : run->run->parameters) v.emplace(name, value);
      values.push_back(std::move(v));
    }
    const std::string label = key.empty() ? "runs" : key;
    if (r.kind == CampaignReduction::Kind::kRms) {
      out += rms_table(label, values, r.values);
    } else if (r.kind == CampaignReduction::Kind::kTable) {
      out += group_title(r.group, key) + run_table(values, r.values);
    } else {
      out += error_stats_table(label, values, r.values);
    }
  }
  return out;
}

std::string describe(const CampaignRun& run) {
  std::string text;
  for (const auto& [name, value] : run.parameters) text += (text.empty() ? "" : " ") + name + "=" + value;
  return text;
}

// "0004-0007, 0010" from sorted indices.
std::string ranges(const std::vector<int>& indices) {
  std::string text;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!text.empty()) text += ", ";
    text += campaign_run_folder(indices[i]);
    if (j > i) text.append("-").append(campaign_run_folder(indices[j]));  // appended: GCC 12's false -Wrestrict
    i = j + 1;
  }
  return text;
}

}  // namespace

std::pair<double, double> wilson_interval(int k, int n, double z) {
  if (n == 0) return {0.0, 1.0};
  const double p = static_cast<double>(k) / n, d = 1 + z * z / n;
  const double c = (p + z * z / (2.0 * n)) / d;
  const double h = z * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n)) / d;
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

std::string campaign_report(const fs::path& campaign_dir, const std::vector<CampaignRun>& runs,
                            const std::vector<CampaignReduction>& reductions) {
  std::vector<CompleteRun> complete;
  std::vector<int> missing;
  std::string failed;
  int failures = 0;
  for (const CampaignRun& run : runs) {
    const fs::path dir = campaign_run_dir(campaign_dir, run.index);
    CampaignRunStatus status = campaign_run_status(dir);
    if (status.state == CampaignRunState::kComplete) {
      complete.push_back({&run, dir, std::move(status)});
    } else if (status.state == CampaignRunState::kFailed) {
      ++failures;
      failed += fmt::format("failed: {} ({}): {} (log: {})\n", campaign_run_folder(run.index), describe(run),
                            status.message, (dir / "failed.txt").string());
    } else {
      missing.push_back(run.index);
    }
  }
  std::string out = fmt::format("campaign {}: {} runs: {} complete, {} failed, {} missing\n", campaign_dir.string(),
                                runs.size(), complete.size(), failures, missing.size());
  out += failed;
  if (!missing.empty()) out += "missing: " + ranges(missing) + "\n";
  for (const CampaignReduction& r : reductions) {
    out += "\n";
    switch (r.kind) {
      case CampaignReduction::Kind::kLockThreshold:
        out += lock_threshold(complete, r);
        break;
      case CampaignReduction::Kind::kNavConsistency:
        out += nav_consistency(complete, r);
        break;
      case CampaignReduction::Kind::kStats:
        out += stats(complete, r);
        break;
      case CampaignReduction::Kind::kRms:
      case CampaignReduction::Kind::kTable:
      case CampaignReduction::Kind::kErrorStats:
        out += tables(complete, r);
        break;
    }
  }
  return out;
}

}  // namespace ultratrack::pipelines
