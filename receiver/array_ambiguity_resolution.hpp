// SPDX-License-Identifier: GPL-3.0-or-later
// Single-epoch integer ambiguity resolution for a rigid antenna array from double differences alone (the code is no
// help at 1 m). Float: each baseline's DDs with the baseline vector given a zero-mean prior of sigma_b per axis,
// a_hat = DD, Q_a = Q_DD + sigma_b^2 G G^T (the ambiguity-domain form of the baseline-constrained LAMBDA search space,
// Teunissen 2006/2010; Park & Teunissen 2003). Constrained method (default): LAMBDA enumerates every integer vector
// of the ellipsoid that can hold a candidate whose float baseline has the known length and whose residuals pass;
// those are kept, combined across baselines by the known distances between the slave antennas (the angle between
// baselines), and ranked by the chi-square of the rigid-array attitude fit of all DDs (the multivariate constrained
// objective of Giorgi, Teunissen & Buist 2010, evaluated on the surviving candidates); validation by an absolute
// chi-square test, the ratio test (second best / best) and
// the difference test (second best - best, Tiberius & de Jonge 1995). Unconstrained method: the best two LAMBDA
// candidates of each baseline's float (sigma_b = length) and the ratio test alone. Units: cycles, m.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "receiver/array_fit.hpp"

namespace ultratrack::receiver {

struct AmbiguityResolutionOptions {
  bool use_constraints = true;
  double gate_sigma = 4.0;           // length, inter-antenna distance and per-baseline residual gates, sigmas
  double length_tolerance_m = 0.01;  // added to the length gates (lever-arm survey error)
  double ratio_threshold = 2.0;
  double difference_threshold = 15.0;  // J2 - J1 (constrained method only)
  double residual_test_pfa = 1e-4;     // absolute chi-square test of the best fit
  int max_candidates_per_baseline = 4000;
  // Constrained method: rigid-array candidates kept in AmbiguityResolution::candidates (for a multi-epoch test):
  // those with chi-square below the best's + keep_margin, at most max_kept (best first).
  double keep_margin = 60.0;
  int max_kept = 40;
};

// One integer candidate of every DD row and its rigid-array fit chi-square this epoch.
struct ArrayCandidate {
  Eigen::VectorXd integers;
  double chi2 = 0.0;
};

struct AmbiguityResolution {
  bool fixed = false;             // validated
  Eigen::VectorXd integers;       // DD integers of every row (best candidate, also when not validated)
  ArrayFit fit;                   // rigid fit with those integers
  double ratio = 0.0;             // second best / best (infinity when no rival survived the constraints)
  double difference = 0.0;        // second best - best (constrained method)
  int candidates_enumerated = 0;  // LAMBDA candidates over all baselines
  int candidates_kept = 0;        // after the length and residual gates
  bool truncated = false;         // a baseline's enumeration hit max_candidates_per_baseline
  // Constrained method: the best rigid-array candidates (see keep_margin), best first; kept_truncated: more were
  // within the margin than max_kept.
  std::vector<ArrayCandidate> candidates;
  bool kept_truncated = false;
};

// body_baselines[k]: antenna k's lever arm minus the master's, body frame ([0] unused). Every baseline present in the
// fitter's DDs needs at least 4 rows (5 satellites).
AmbiguityResolution resolve_array_ambiguities(const ArrayFitter& fitter,
                                              const std::vector<Eigen::Vector3d>& body_baselines,
                                              const AmbiguityResolutionOptions& options);

}  // namespace ultratrack::receiver
