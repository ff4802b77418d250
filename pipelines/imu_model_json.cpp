// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/imu_model_json.hpp"

#include <fmt/core.h>

#include "io/json_text.hpp"

namespace ultratrack::pipelines {

std::string imu_model_json(const FuseConfig& config) {
  const ins::ImuDatasheet used = ins::datasheet_of(imu_error_spec(config));
  std::string j = fmt::format("{{\"preset\": \"{}\"", io::json_escape(config.imu_preset));
  for (const auto& key : ins::imu_datasheet_keys())
    j += fmt::format(", \"{}\": {:.6g}", key.name, *(used.*(key.member)));
  std::string overridden;
  for (const auto& key : ins::imu_datasheet_keys())
    if ((config.imu_datasheet.*(key.member)).has_value())
      overridden += fmt::format("{}\"{}\"", overridden.empty() ? "" : ", ", key.name);
  return j + ", \"from_configuration\": [" + overridden + "]}";
}

}  // namespace ultratrack::pipelines
