// SPDX-License-Identifier: GPL-3.0-or-later
// summary.json of a `fuse` run (pipelines/fuse.hpp): the inputs, alignment, update counts, GPS attitude use,
// convergence, final 1-sigmas and the RMS errors against truth. Angles in degrees, the rest SI.
#pragma once

#include <string>

#include "pipelines/fuse.hpp"

namespace ultratrack::pipelines {

// `[{"t_s": ..., "reason": "..."}, ...]`: the lock-out recoveries (fusion/lockout_recovery.hpp) of a run.
std::string recovery_events_json(const std::vector<fusion::RecoveryEvent>& events);

// The "odometer" object: settings, update counts by rule, the odometer estimates with their 1-sigma and, against
// truth, [KimVMS]'s errors as % of the distance travelled since GNSS was last used (DT; null without truth).
// file names the odometer data. `fuse` and `receive` (pipelines/gnss_ins_coupler.hpp) write it.
std::string odometer_json(const OdometerUse& u, const fusion::OdometerCounters& counters,
                          const fusion::OdometerAidingOptions& options, const std::string& file);

std::string fuse_summary_json(const FuseResult& r, const FuseSettings& s, const std::string& imu_file,
                              const std::string& gnss_file, const std::string& truth_file);

}  // namespace ultratrack::pipelines
