// SPDX-License-Identifier: GPL-3.0-or-later
// Error-state corrections of a NavState, for the fusion layer's feedback. Errors are estimate minus truth:
// position error in NED metres, velocity error in NED m/s, attitude error as the psi-angle of
// attitude_error_n (C_nb_est = (I - [psi x]) C_nb_true). Each correction removes its error exactly for the
// position (through the radii of curvature at the state) and the attitude (rotation vector, any size).
#pragma once

#include <Eigen/Core>

#include "ins/nav_state.hpp"

namespace ultratrack::ins {

// NED position error (metres) of `est` relative to `truth`, to first order in the separation.
Eigen::Vector3d position_error_ned(const NavState& est, const NavState& truth);

void correct_position(NavState& s, const Eigen::Vector3d& position_error_ned_m);
void correct_velocity(NavState& s, const Eigen::Vector3d& velocity_error_n_mps);
void correct_attitude(NavState& s, const Eigen::Vector3d& psi_n_rad);

}  // namespace ultratrack::ins
