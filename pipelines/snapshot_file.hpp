// SPDX-License-Identifier: GPL-3.0-or-later
// A position from a snapshot of a recording (tens to hundreds of ms) with broadcast ephemerides and an approximate
// time: `ultratrack snapshot` below its command line. Reads the snapshot from the file, detects every satellite with
// its fine code phase and Doppler (receiver/snapshot_measurement.hpp), pairs each with its ephemeris at the
// approximate time and solves the coarse-time navigation (receiver/snapshot_navigation.hpp); the ionosphere is the
// nav file's Klobuchar set, or the default set when the file has none. write_snapshot_outputs() writes
// snapshot.json and solution.csv (one row, `receive`'s columns, only with a fix).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "receiver/sample_source.hpp"
#include "receiver/snapshot_measurement.hpp"
#include "receiver/snapshot_navigation.hpp"
#include "signals/gps_time.hpp"
#include "signals/rinex_nav.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::pipelines {

struct SnapshotFileJob {
  std::filesystem::path input;
  signals::SampleFormat format = signals::SampleFormat::i8;
  receiver::SampleSourceOptions source;  // start_sample: where the snapshot begins
  double snapshot_ms = 100.0;            // the file's remaining length when shorter (>= 10 ms needed)
  std::vector<int> prns;                 // searched
  receiver::SnapshotSearchOptions search;
  receiver::SnapshotOptions navigation;                     // time_sigma_s; klobuchar is set from `nav`
  signals::GpsTime approximate_time;                        // of the snapshot's first sample
  std::optional<Eigen::Vector3d> approximate_position_e_m;  // ECEF; without it a Doppler fix and a grid search
  signals::RinexNavData nav;
};

struct SnapshotFileResult {
  double used_ms = 0.0;    // signal read (shorter than asked when the file ends)
  bool shortened = false;  // the file held less than snapshot_ms
  std::string ionosphere;  // which Klobuchar set was used
  std::vector<receiver::SnapshotDetection> detections;
  std::vector<int> without_ephemeris;   // detected, but no healthy ephemeris at the time
  receiver::SnapshotSolution solution;  // valid, or failure says why
};

// Throws signals::InputError naming the file: unreadable samples, fewer than 10 ms of signal, no ephemeris in the
// nav data, no satellite detected, options that do not validate. Fewer than 5 usable satellites is not an error:
// the solution says so.
SnapshotFileResult snapshot_file(const SnapshotFileJob& job);

// DIR/snapshot.json (the job, the detections, the solution and its tests) and DIR/solution.csv, both atomically;
// DIR is created. wall_s: the run's wall-clock time, reported.
void write_snapshot_outputs(const std::filesystem::path& dir, const SnapshotFileJob& job,
                            const SnapshotFileResult& result, const std::string& format_label, double wall_s);

}  // namespace ultratrack::pipelines
