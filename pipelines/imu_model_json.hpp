// SPDX-License-Identifier: GPL-3.0-or-later
// The IMU error model a filter actually used, as a JSON object for summary.json: the preset's name and every
// datasheet value after the configuration's overrides (ins/imu_datasheet.hpp units: deg/h, mg, deg/sqrt(h),
// m/s/sqrt(h), ppm, s), so a reader sees the model, not only the preset it started from.
#pragma once

#include <string>

#include "pipelines/fuse_config.hpp"

namespace ultratrack::pipelines {

// `{"preset": "...", "gyro_bias_dph": ..., ...}` (one line, no trailing comma).
std::string imu_model_json(const FuseConfig& config);

}  // namespace ultratrack::pipelines
