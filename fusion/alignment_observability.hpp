// SPDX-License-Identifier: GPL-3.0-or-later
// Observability of the stationary alignment ([KimAlign] eqs. 18-20): the rank of O = [H; H A; ...; H A^11] of the
// 12-state model at rest (fusion/stationary_alignment_model.hpp) for a given attitude, and its weakest direction.
// H_G's rows are scaled by cos(pitch) (roll and yaw rows), which changes no rank away from pitch +-90 deg and has
// a limit there: at +-90 deg the roll and yaw rows coincide, the GPS attitude gives only two angles, and the rank
// drops. Each block row H A^k is scaled to unit largest entry before the SVD (earth rate makes the higher powers
// tiny; row scaling keeps the rank), and the rank counts singular values above rank_tolerance times the largest.
#pragma once

#include <Eigen/Core>

#include "fusion/stationary_alignment_model.hpp"

namespace ultratrack::fusion {

struct ObservabilityOptions {
  bool zero_velocity = true;  // the velocity rows of H
  bool gps_attitude = true;   // the H_G rows
  double rank_tolerance = 1e-9;
};

struct ObservabilityReport {
  int rank = 0;
  Eigen::Matrix<double, 12, 1> singular_values;  // descending
  AlignmentVector weakest_direction;             // unit right singular vector of the smallest singular value
};

// The observability matrix O (rows: 12 blocks of the measurement rows) of (A, H) at attitude e.
Eigen::MatrixXd alignment_observability_matrix(const ins::EulerAngles& e, const StationaryAlignmentModelOptions& model,
                                               const ObservabilityOptions& options = {});
ObservabilityReport alignment_observability(const ins::EulerAngles& e, const StationaryAlignmentModelOptions& model,
                                            const ObservabilityOptions& options = {});

}  // namespace ultratrack::fusion
