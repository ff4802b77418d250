// SPDX-License-Identifier: GPL-3.0-or-later
// A campaign's runs: the product of its parameter axes, and its templates filled in per run. The order is fixed
// (the first axis outermost, the last varying fastest), each run numbered 0..N-1 and carrying one value of every
// parameter as text. An axis may carry zipped columns (parameters that vary with it, one value per axis value: e.g. a
// file number with its seed and start time), so that seeds and levels combine without writing every pair. Templates
// (scenario and configuration text) name parameters as {name}; substitute_parameters fills them in.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ultratrack::pipelines {

// One axis: its values, and zipped columns of the same length (column name, values).
struct CampaignAxis {
  std::string name;
  std::vector<std::string> values;
  std::vector<std::pair<std::string, std::vector<std::string>>> columns;
};

struct CampaignRun {
  int index = 0;                                                // 0..N-1 in expansion order
  std::vector<std::pair<std::string, std::string>> parameters;  // axis values and their columns, in axis order

  // The parameter's value; nullptr when the run has no such parameter.
  const std::string* find(std::string_view name) const;
};

// At most this many runs (a campaign of more is split into several).
inline constexpr std::size_t kMaxCampaignRuns = 1000000;

// The runs of the product of `axes` (no axis: one run without parameters). Axes must be non-empty with columns of
// their own length and unique names, at most kMaxCampaignRuns runs (config/campaign_toml.hpp checks that at the
// edge; std::invalid_argument here).
std::vector<CampaignRun> expand_campaign(const std::vector<CampaignAxis>& axes);

// `text` with every {name} (letters, digits and _) replaced by the run's value; other braces stay as written (TOML
// inline tables). A {name} the run does not have: std::invalid_argument naming it (the caller's InputError names
// its file).
std::string substitute_parameters(std::string_view text, const CampaignRun& run);

// The run's folder name under the campaign's runs/ folder: its index, zero-padded to 4 digits ("0007").
std::string campaign_run_folder(int index);

}  // namespace ultratrack::pipelines
