// SPDX-License-Identifier: GPL-3.0-or-later
// Wahba's problem: the rotation R minimising sum_k w_k |v_k - R l_k|^2 for vectors l_k in one frame (body) and v_k in
// another (ECEF), by the SVD of B = sum w_k v_k l_k^T with the determinant fix that keeps R proper
// (Markley 1988). Dimensionless; at least two non-collinear pairs make R unique.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ultratrack::receiver {

Eigen::Matrix3d wahba_rotation(const std::vector<Eigen::Vector3d>& l_body, const std::vector<Eigen::Vector3d>& v_ref,
                               const std::vector<double>& weights);

}  // namespace ultratrack::receiver
