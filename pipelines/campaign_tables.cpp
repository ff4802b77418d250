// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_tables.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "io/input_error.hpp"

namespace ultratrack::pipelines {
namespace {

double value_of(const CampaignRunValues& run, const std::string& name) {
  const auto it = run.find(name);
  if (it == run.end()) throw io::InputError("campaign report", "a complete run has no value '" + name + "'");
  try {
    std::size_t used = 0;
    const double v = std::stod(it->second, &used);
    if (used == it->second.size()) return v;
  } catch (const std::exception&) {
  }
  throw io::InputError("campaign report", name + " is not a number: '" + it->second + "'");
}

}  // namespace

std::string rms_table(const std::string& label, const std::vector<CampaignRunValues>& runs,
                      const std::vector<std::string>& values) {
  if (runs.empty()) return label + ": no complete run\n";
  std::string out = fmt::format("{}: {} runs", label, runs.size());
  for (const std::string& name : values) {
    double sum2 = 0.0, largest = 0.0;
    for (const CampaignRunValues& run : runs) {
      const double v = value_of(run, name);
      sum2 += v * v;
      largest = std::max(largest, std::abs(v));
    }
    out += fmt::format("; {} RMS {:.3f} (max |{}| {:.3f})", name, std::sqrt(sum2 / static_cast<double>(runs.size())),
                       name, largest);
  }
  return out + "\n";
}

std::string run_table(const std::vector<CampaignRunValues>& runs, const std::vector<std::string>& columns) {
  std::string header = "|", rule = "|";
  std::vector<std::pair<std::string, std::string>> specs;  // name, format ("" as written)
  for (const std::string& column : columns) {
    const std::size_t colon = column.find(':');
    specs.emplace_back(column.substr(0, colon), colon == std::string::npos ? "" : column.substr(colon + 1));
    header += " " + specs.back().first + " |";
    rule += "---|";
  }
  std::string out = header + "\n" + rule + "\n";
  for (const CampaignRunValues& run : runs) {
    out += "|";
    for (const auto& [name, format] : specs) {
      const auto it = run.find(name);
      std::string cell = it == run.end() ? "-" : it->second;
      if (it != run.end() && !format.empty()) {
        try {
          cell = fmt::format(fmt::runtime("{:" + format + "}"), value_of(run, name));
        } catch (const fmt::format_error& e) {
          throw io::InputError("campaign report", "column " + name + ": bad format '" + format + "': " + e.what());
        }
      }
      out += " " + cell + " |";
    }
    out += "\n";
  }
  return out;
}

std::string error_stats_table(const std::string& label, const std::vector<CampaignRunValues>& runs,
                              const std::vector<std::string>& axes) {
  std::string out =
      fmt::format("{}: {} runs\n| axis | mean | std | RMS | mean 1-sigma | > 3 sigma |\n", label, runs.size());
  out += "|---|---|---|---|---|---|\n";
  const double n = static_cast<double>(runs.size());
  for (const std::string& axis : axes) {
    double sum = 0.0, sum2 = 0.0, sigma = 0.0;
    int outside = 0;
    for (const CampaignRunValues& run : runs) {
      const double e = value_of(run, axis + "_error_deg"), s = value_of(run, axis + "_sigma_deg");
      sum += e;
      sum2 += e * e;
      sigma += s;
      outside += std::abs(e) > 3.0 * s;
    }
    if (runs.empty()) continue;
    const double mean = sum / n;
    const double std = runs.size() > 1 ? std::sqrt(std::max(0.0, (sum2 - n * mean * mean) / (n - 1))) : 0.0;
    out += fmt::format("| {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {} |\n", axis, mean, std, std::sqrt(sum2 / n),
                       sigma / n, outside);
  }
  return out;
}

}  // namespace ultratrack::pipelines
