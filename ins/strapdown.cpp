// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/strapdown.hpp"

#include <cmath>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::ins {

Strapdown::Strapdown(const NavState& initial, StrapdownOptions options) : state_(initial), opt_(options) {
  state_.q_nb.normalize();
}

void Strapdown::set_height_aiding(double reference_height_m, HeightAidingOptions options) {
  const double tau = options.time_constant_s;
  const Radii r = radii_of_curvature(state_.lat_rad);
  const double g = gravity_n(state_.lat_rad, state_.height_m).z();
  const double ws2 = g / std::sqrt(r.meridian_m * r.transverse_m);  // Schuler frequency squared
  // Characteristic polynomial s^3 + k1 s^2 + (k2 - 2 ws^2) s + k3 = (s + 1/tau)^3.
  k1_ = 3.0 / tau;
  k2_ = 3.0 / (tau * tau) + 2.0 * ws2;
  k3_ = 1.0 / (tau * tau * tau);
  if (!aiding_on_) aiding_accel_ = 0.0;
  aiding_on_ = true;
  aiding_ref_h_ = reference_height_m;
}

void Strapdown::step(const ImuIncrement& inc) { step(inc.dtheta_b, inc.dv_b, inc.t_s - state_.t_s); }

void Strapdown::step(const Eigen::Vector3d& dtheta, const Eigen::Vector3d& dv, double dt) {
  // Previous increments scaled to this interval's length (constant-rate assumption across intervals).
  Eigen::Vector3d dth_p = Eigen::Vector3d::Zero(), dv_p = Eigen::Vector3d::Zero();
  if (have_prev_ && prev_dt_ > 0.0) {
    const double s = dt / prev_dt_;
    dth_p = prev_dtheta_ * s;
    dv_p = prev_dv_ * s;
  } else {
    dth_p = dtheta;  // constant-rate assumption for the first step: both corrections vanish
    dv_p = dv;
  }

  const double lat0 = state_.lat_rad, h0 = state_.height_m;
  const Eigen::Vector3d v0 = state_.v_n;

  // --- velocity: rates at the extrapolated mid-interval point
  const Eigen::Vector3d v_mid_x = v0 + 0.5 * prev_dv_n_ * (have_prev_ && prev_dt_ > 0.0 ? dt / prev_dt_ : 0.0);
  const Eigen::Vector3d rates0 = geodetic_rates(lat0, h0, v0);
  const double lat_mid_x = lat0 + 0.5 * dt * rates0.x();
  const double h_mid_x = h0 + 0.5 * dt * rates0.z();
  const Eigen::Vector3d w_ie = earth_rate_n(lat_mid_x);
  const Eigen::Vector3d w_en = transport_rate_n(lat_mid_x, h_mid_x, v_mid_x);
  const Eigen::Vector3d zeta_x = (w_ie + w_en) * dt;

  Eigen::Vector3d dv_b = dv;
  if (opt_.rotation_correction) {  // constant-rate rotation of dv within the interval, to second order
    const Eigen::Vector3d r1 = dtheta.cross(dv);
    dv_b += 0.5 * r1 + dtheta.cross(r1) / 6.0;
  }
  if (opt_.sculling_correction) dv_b += (dth_p.cross(dv) + dv_p.cross(dtheta)) / 12.0;
  const Eigen::Vector3d dv_n_sf = state_.q_nb * dv_b - 0.5 * zeta_x.cross(state_.q_nb * dv_b);
  Eigen::Vector3d g = gravity_n(lat_mid_x, h_mid_x);
  if (aiding_on_) g.z() += aiding_accel_;
  const Eigen::Vector3d dv_n_cor = (g - (2.0 * w_ie + w_en).cross(v_mid_x)) * dt;
  Eigen::Vector3d v1 = v0 + dv_n_sf + dv_n_cor;

  // --- position: height first, then latitude with the mid height, longitude with the mid latitude
  const Eigen::Vector3d v_mid = 0.5 * (v0 + v1);
  double h1 = h0 - v_mid.z() * dt;
  double h_mid = 0.5 * (h0 + h1);
  const Radii r0 = radii_of_curvature(lat0);
  double lat1 = lat0 + v_mid.x() / (r0.meridian_m + h_mid) * dt;
  const Radii r_mid = radii_of_curvature(0.5 * (lat0 + lat1));
  lat1 = lat0 + v_mid.x() / (r_mid.meridian_m + h_mid) * dt;
  const double lat_mid = 0.5 * (lat0 + lat1);
  const double lon1 = state_.lon_rad + v_mid.y() / ((r_mid.transverse_m + h_mid) * std::cos(lat_mid)) * dt;

  if (aiding_on_) {  // third-order vertical loop driven by the height misfit
    const double e = h1 - aiding_ref_h_;
    h1 -= k1_ * e * dt;
    v1.z() += k2_ * e * dt;
    aiding_accel_ += k3_ * e * dt;
    h_mid = 0.5 * (h0 + h1);
  }

  // --- attitude: body rotation with coning, navigation-frame rotation at the true mid point
  Eigen::Vector3d phi = dtheta;
  if (opt_.coning_correction) phi += dth_p.cross(dtheta) / 12.0;
  const Eigen::Vector3d zeta = (earth_rate_n(lat_mid) + transport_rate_n(lat_mid, h_mid, v_mid)) * dt;
  state_.q_nb = quaternion_from_rotation_vector(-zeta) * state_.q_nb * quaternion_from_rotation_vector(phi);
  state_.q_nb.normalize();

  state_.lat_rad = lat1;
  state_.lon_rad = lon1;
  state_.height_m = h1;
  state_.v_n = v1;
  state_.t_s += dt;

  prev_dv_n_ = v1 - v0;
  prev_dtheta_ = dtheta;
  prev_dv_ = dv;
  prev_dt_ = dt;
  have_prev_ = true;
}

}  // namespace ultratrack::ins
