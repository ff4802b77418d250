// SPDX-License-Identifier: GPL-3.0-or-later
// Strapdown mechanisation in the local-level NED frame on WGS-84 ([ParkSDINS] eqs. 3-8, quaternion attitude
// eq. 15 in its incremental form): attitude from delta-theta with two-sample coning correction, velocity
// from delta-v with rotation and sculling corrections, Coriolis/transport and gravity at mid-interval,
// position (lat, lon, h) by trapezoidal integration; optional height aiding of the vertical channel.
#pragma once

#include <Eigen/Core>

#include "ins/nav_state.hpp"

namespace ultratrack::ins {

struct StrapdownOptions {
  bool coning_correction = true;    // dtheta_prev x dtheta / 12
  bool rotation_correction = true;  // dtheta x dv / 2 + dtheta x (dtheta x dv) / 6
  bool sculling_correction = true;  // (dtheta_prev x dv + dv_prev x dtheta) / 12
};

// Third-order height-aiding loop: h, v_D and a vertical acceleration correction are pulled towards an
// external height with all three closed-loop poles at -1/time_constant_s (stabilises the vertical channel).
struct HeightAidingOptions {
  double time_constant_s = 30.0;
};

class Strapdown {
 public:
  explicit Strapdown(const NavState& initial, StrapdownOptions options = {});

  // Propagates over one IMU interval ending at inc.t_s (must be later than state().t_s).
  void step(const ImuIncrement& inc);
  // Same with an explicit interval length.
  void step(const Eigen::Vector3d& dtheta_b, const Eigen::Vector3d& dv_b, double dt_s);

  const NavState& state() const { return state_; }
  // Replaces the state (e.g. after an error-state correction). The IMU history used by the coning and
  // sculling terms is kept, since the sensors did not change.
  void set_state(const NavState& s) { state_ = s; }

  // Height aiding: enable with a reference height, update it whenever a new one arrives, disable to free
  // the vertical channel again. The reference holds until changed.
  void set_height_aiding(double reference_height_m, HeightAidingOptions options = {});
  void disable_height_aiding() { aiding_on_ = false; }

  // Forget the previous increment (after a data gap): the next step uses no coning/sculling history.
  void reset_history() { have_prev_ = false; }

 private:
  NavState state_;
  StrapdownOptions opt_;
  bool have_prev_ = false;
  Eigen::Vector3d prev_dtheta_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d prev_dv_ = Eigen::Vector3d::Zero();
  double prev_dt_ = 0.0;
  Eigen::Vector3d prev_dv_n_ = Eigen::Vector3d::Zero();  // last velocity change, for mid-interval extrapolation
  bool aiding_on_ = false;
  double aiding_ref_h_ = 0.0;
  double k1_ = 0.0, k2_ = 0.0, k3_ = 0.0;
  double aiding_accel_ = 0.0;  // down-acceleration correction integrated by the loop
};

}  // namespace ultratrack::ins
