// SPDX-License-Identifier: GPL-3.0-or-later
// Time synchronisation of an IMU stamped by a free-running local clock, through the GPS receiver's PPS record (seed
// 003's synchronisation of the IMU and the 1 PPS). The record gives the local time of each pulse edge with the GPS
// time it marks (a whole GPS second); a straight line local -> GPS time (offset and drift) is fitted robustly (least
// squares, then pulses whose residual exceeds max(outlier_floor_s, 5 x 1.4826 x the median absolute residual) are
// dropped and the line refitted, until nothing changes), so a missing pulse or one jittered far off changes nothing.
// The file `pps.csv`:
//   local_s,gps_week,gps_tow_s      (local clock seconds; GPS week; GPS seconds of week of the edge, whole)
// Times strictly increasing; a gap between edges longer than max_gap_s, fewer than 3 edges, or a tow that is not a
// whole second is an InputError naming the file (and line). Units: s.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "ins/nav_state.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::pipelines {

struct PpsEdge {
  int line = 0;
  double local_s = 0.0;
  signals::GpsTime gps;
};

struct PpsOptions {
  double max_gap_s = 5.0;          // between consecutive edges (local time): longer = a gap in the record
  double outlier_floor_s = 20e-6;  // residuals below this are never outliers
};

std::vector<PpsEdge> read_pps_csv(const std::filesystem::path& file);

// GPS time = reference + (1 + drift) (local - local_reference) + offset_s.
struct PpsClockFit {
  signals::GpsTime reference;  // the first edge's GPS time
  double local_reference_s = 0.0;
  double offset_s = 0.0;        // at local_reference_s
  double drift = 0.0;           // dimensionless (50 ppm = 5e-5): local clock rate error, GPS per local - 1
  double residual_rms_s = 0.0;  // of the edges used
  int used = 0, rejected = 0;
  double first_local_s = 0.0, last_local_s = 0.0;  // span of the record
  double gps_seconds_since_reference(double local_s) const {
    return offset_s + (1.0 + drift) * (local_s - local_reference_s);
  }
};

// Throws io::InputError naming `file` for the problems listed above.
PpsClockFit fit_pps_clock(std::span<const PpsEdge> edges, const std::string& file, const PpsOptions& options = {});

// IMU rows re-stamped: t_s = GPS time of the local stamp minus origin (seconds). Rows more than max_gap_s outside
// the PPS record are an InputError naming imu_file (extrapolating a free-running clock is what PPS avoids).
std::vector<ins::ImuIncrement> imu_on_gps_time(std::span<const ins::ImuIncrement> imu, const PpsClockFit& fit,
                                               const signals::GpsTime& origin, const std::string& imu_file,
                                               const PpsOptions& options = {});

// An IMU file stamped by a local clock put on GPS time through a PPS file (read, fitted, re-stamped as above):
// t_s = GPS time - origin, the origin being the given one or else the first PPS edge's GPS time. The note says how
// (edges used and rejected, drift, residual) for messages and summaries. Errors as read_pps_csv, fit_pps_clock
// and imu_on_gps_time.
struct ImuOnPps {
  std::vector<ins::ImuIncrement> imu;
  PpsClockFit fit;
  signals::GpsTime origin;  // GPS time of the new t_s = 0
  std::string note;
};
ImuOnPps imu_on_gps_time_by_pps(std::span<const ins::ImuIncrement> imu, const std::string& imu_file,
                                const std::filesystem::path& pps_file,
                                const std::optional<signals::GpsTime>& origin = std::nullopt);

}  // namespace ultratrack::pipelines
