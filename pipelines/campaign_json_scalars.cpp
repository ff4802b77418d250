// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/campaign_json_scalars.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "io/input_error.hpp"
#include "io/json_lookup.hpp"

namespace ultratrack::pipelines {

CampaignJsonScalar parse_campaign_json_scalar(const std::string& name, const std::string& spec) {
  const std::size_t colon = spec.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size())
    throw std::invalid_argument("must be FILE:dotted.path, got '" + spec + "'");
  return {name, spec.substr(0, colon), spec.substr(colon + 1)};
}

std::map<std::string, std::string> read_campaign_json_scalars(const std::filesystem::path& run_dir,
                                                              const std::vector<CampaignJsonScalar>& scalars) {
  std::map<std::string, std::string> out;
  for (const CampaignJsonScalar& s : scalars) {
    const std::filesystem::path file = run_dir / s.file;
    std::ifstream in(file);
    if (!in) throw io::InputError(file.string(), "cannot read the file (scalar " + s.name + ")");
    std::stringstream text;
    text << in.rdbuf();
    std::optional<std::string> value;
    try {
      value = io::json_scalar_at(text.str(), s.path);
    } catch (const std::invalid_argument& e) {
      throw io::InputError(file.string(), e.what());
    }
    if (!value) throw io::InputError(file.string(), "no scalar at '" + s.path + "' (scalar " + s.name + ")");
    out[s.name] = *value;
  }
  return out;
}

}  // namespace ultratrack::pipelines
