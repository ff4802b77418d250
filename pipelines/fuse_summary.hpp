// summary.json of a `fuse` run (pipelines/fuse.hpp): the inputs, alignment, update counts, GPS attitude use,
// convergence, final 1-sigmas and the RMS errors against truth. Angles in degrees, the rest SI.
#pragma once

#include <string>

#include "pipelines/fuse.hpp"

namespace ultratrack::pipelines {

// `[{"t_s": ..., "reason": "..."}, ...]`: the lock-out recoveries (fusion/lockout_recovery.hpp) of a run.
std::string recovery_events_json(const std::vector<fusion::RecoveryEvent>& events);

std::string fuse_summary_json(const FuseResult& r, const FuseSettings& s, const std::string& imu_file,
                              const std::string& gnss_file, const std::string& truth_file);

}  // namespace ultratrack::pipelines
