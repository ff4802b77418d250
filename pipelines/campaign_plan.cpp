// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_plan.hpp"

#include <fmt/core.h>

#include <set>
#include <stdexcept>

namespace ultratrack::pipelines {

const std::string* CampaignRun::find(std::string_view name) const {
  for (const auto& [key, value] : parameters)
    if (key == name) return &value;
  return nullptr;
}

std::vector<CampaignRun> expand_campaign(const std::vector<CampaignAxis>& axes) {
  std::set<std::string> names;
  std::size_t total = 1;
  for (const CampaignAxis& axis : axes) {
    if (axis.values.empty()) throw std::invalid_argument("campaign axis '" + axis.name + "' has no values");
    if (!names.insert(axis.name).second) throw std::invalid_argument("campaign parameter '" + axis.name + "' twice");
    for (const auto& [name, values] : axis.columns) {
      if (values.size() != axis.values.size())
        throw std::invalid_argument("campaign column '" + name + "' is not as long as axis '" + axis.name + "'");
      if (!names.insert(name).second) throw std::invalid_argument("campaign parameter '" + name + "' twice");
    }
    if (axis.values.size() > kMaxCampaignRuns / total)
      throw std::invalid_argument(fmt::format("the campaign has more than {} runs", kMaxCampaignRuns));
    total *= axis.values.size();
  }
  std::vector<CampaignRun> runs(total);
  for (std::size_t i = 0; i < total; ++i) {
    CampaignRun& run = runs[i];
    run.index = static_cast<int>(i);
    // Mixed-radix digits of i, the last axis the fastest.
    std::vector<std::size_t> digit(axes.size());
    std::size_t rest = i;
    for (std::size_t a = axes.size(); a-- > 0;) {
      digit[a] = rest % axes[a].values.size();
      rest /= axes[a].values.size();
    }
    for (std::size_t a = 0; a < axes.size(); ++a) {
      run.parameters.emplace_back(axes[a].name, axes[a].values[digit[a]]);
      for (const auto& [name, values] : axes[a].columns) run.parameters.emplace_back(name, values[digit[a]]);
    }
  }
  return runs;
}

std::string substitute_parameters(std::string_view text, const CampaignRun& run) {
  const auto is_name_char = [](char c, bool first) {
    return c == '_' || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (!first && c >= '0' && c <= '9');
  };
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    std::size_t end = i + 1;
    while (end < text.size() && is_name_char(text[end], end == i + 1)) ++end;
    if (text[i] != '{' || end == i + 1 || end >= text.size() || text[end] != '}') {
      out += text[i];  // not a {name}: TOML inline tables and other braces stay as written
      continue;
    }
    const std::string_view name = text.substr(i + 1, end - i - 1);
    const std::string* value = run.find(name);
    if (!value) throw std::invalid_argument("{" + std::string(name) + "} names no campaign parameter");
    out += *value;
    i = end;
  }
  return out;
}

std::string campaign_run_folder(int index) { return fmt::format("{:04d}", index); }

}  // namespace ultratrack::pipelines
