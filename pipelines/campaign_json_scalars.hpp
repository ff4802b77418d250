// SPDX-License-Identifier: GPL-3.0-or-later
// Run scalars read from the JSON files a campaign run wrote ([compute] json = { name = "FILE:dotted.path" }), e.g.
// the outage drift out of `fuse`'s summary.json. FILE is relative to the run's folder; the value is kept as written.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace ultratrack::pipelines {

struct CampaignJsonScalar {
  std::string name;  // the run scalar's name (complete.csv)
  std::string file;  // relative to the run folder
  std::string path;  // dotted keys in the document
};

// Parses "FILE:dotted.path"; std::invalid_argument when there is no ':' or either side is empty.
CampaignJsonScalar parse_campaign_json_scalar(const std::string& name, const std::string& spec);

// name -> value of every scalar. Throws io::InputError naming the file when it is missing, not JSON, or has no
// scalar at the path.
std::map<std::string, std::string> read_campaign_json_scalars(const std::filesystem::path& run_dir,
                                                              const std::vector<CampaignJsonScalar>& scalars);

}  // namespace ultratrack::pipelines
