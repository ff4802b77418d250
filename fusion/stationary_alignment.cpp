// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/stationary_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "fusion/ekf.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/nav_correction.hpp"
#include "ins/strapdown.hpp"

namespace ultratrack::fusion {
namespace {

using align_ix::kAccelBias;
using align_ix::kAtt;
using align_ix::kGyroBias;
using align_ix::kVel;

Eigen::Vector3d euler_sigma(const AlignmentMatrix& P, const ins::EulerAngles& e) {
  const Eigen::Matrix3d HG = euler_error_from_psi(e);
  return (HG * P.block<3, 3>(kAtt, kAtt) * HG.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
}

template <class Filter>
StationaryAlignmentResult run(Filter& filter, std::span<const ins::ImuIncrement> imu, std::size_t first_row,
                              std::span<const GnssAttitude> attitudes, std::size_t first_attitude, ins::NavState nav,
                              const StationaryAlignmentOptions& o, const StationaryAlignmentModelOptions& model_options,
                              double zupt_sigma) {
  StationaryAlignmentResult r;
  r.start_s = nav.t_s;
  const double t_end = o.duration_s > 0.0 ? nav.t_s + o.duration_s : imu.back().t_s;
  ins::Strapdown ins(nav);
  Eigen::Vector3d ba = Eigen::Vector3d::Zero(), bg = Eigen::Vector3d::Zero();
  AttitudeAidingOptions usable;
  usable.max_abs_pitch_rad = o.max_abs_pitch_rad;
  double next_epoch = nav.t_s + o.filter_interval_s, last_epoch = nav.t_s;
  std::size_t a = first_attitude + 1;  // the first attitude started the INS
  for (std::size_t i = first_row; i < imu.size(); ++i) {
    const double dt = imu[i].t_s - ins.state().t_s;
    if (!(dt > 0.0)) continue;
    if (imu[i].t_s > t_end + 0.5 * dt) break;
    ins.step(imu[i].dtheta_b - bg * dt, imu[i].dv_b - ba * dt, dt);
    if (imu[i].t_s < next_epoch - 0.5 * dt && imu[i].t_s < t_end - 0.5 * dt) continue;
    // --- filter epoch ---
    ins::NavState s = ins.state();
    const Eigen::Matrix3d C_nb = s.q_nb.toRotationMatrix();
    filter.predict(StationaryAlignmentModel(C_nb, model_options), s.t_s - last_epoch);
    last_epoch = s.t_s;
    next_epoch += o.filter_interval_s;
    filter.update(ZeroVelocityMeasurement(s.v_n, zupt_sigma)).accepted ? ++r.zero_velocity_updates
                                                                       : ++r.zero_velocity_rejected;
    const GnssAttitude* latest = nullptr;
    while (a < attitudes.size() && attitudes[a].t_s <= s.t_s) {
      if (attitude_usable(attitudes[a], usable))
        latest = &attitudes[a];
      else
        ++r.attitude_unusable;
      ++a;
    }
    AlignmentEpoch epoch;
    if (latest) {
      const auto u =
          filter.update(EulerAttitudeMeasurement(s.q_nb, measured_q_nb(*latest, o.q_ba), latest->sigma_euler_rad));
      epoch.attitude_used = u.accepted;
      u.accepted ? ++r.attitude_updates : ++r.attitude_rejected;
    }
    // Feedback: truth = nominal with the error removed; then the error state restarts from zero.
    const AlignmentVector x = filter.x();
    ins::correct_velocity(s, x.segment<3>(kVel));
    ins::correct_attitude(s, x.segment<3>(kAtt));
    ba += x.segment<3>(kAccelBias);
    bg += x.segment<3>(kGyroBias);
    ins.set_state(s);
    filter.set_x(AlignmentVector::Zero());
    epoch.t_s = s.t_s;
    epoch.euler = ins::euler_from_quaternion(s.q_nb);
    epoch.sigma_euler_rad = euler_sigma(filter.P(), epoch.euler);
    epoch.accel_bias_b = ba;
    epoch.gyro_bias_b = bg;
    epoch.v_n = s.v_n;
    r.history.push_back(epoch);
    if (s.t_s >= t_end - 1e-9) break;
  }
  r.nav = ins.state();
  r.end_s = r.nav.t_s;
  r.accel_bias_b = ba;
  r.gyro_bias_b = bg;
  r.P = filter.P();
  r.sigma_euler_rad = euler_sigma(r.P, ins::euler_from_quaternion(r.nav.q_nb));
  return r;
}

}  // namespace

bool StationaryAlignmentOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* w) {
    if (why) *why = w;
    return false;
  };
  if (!(filter_interval_s > 0.0) || !std::isfinite(filter_interval_s))
    return fail("alignment: the filter interval must be positive");
  if (!(duration_s >= 0.0) || !std::isfinite(duration_s)) return fail("alignment: the duration must be >= 0");
  if (!std::isfinite(lat_rad) || !std::isfinite(lon_rad) || !std::isfinite(height_m))
    return fail("alignment: the position must be finite");
  if (!(zero_velocity_sigma_mps >= 0.0) || !(initial_velocity_sigma_mps > 0.0) ||
      !std::isfinite(zero_velocity_sigma_mps) || !std::isfinite(initial_velocity_sigma_mps))
    return fail("alignment: the velocity sigmas must be finite, the initial one positive");
  if (!q_ba.coeffs().allFinite() || std::abs(q_ba.norm() - 1.0) > 1e-6)
    return fail("alignment: the mounting q_ba must be a unit quaternion");
  if (!(max_abs_pitch_rad > 0.0 && max_abs_pitch_rad <= 0.5 * std::numbers::pi))
    return fail("alignment: the pitch limit must lie in (0, 90] deg");
  if (!(gate.probability > 0.0 && gate.probability < 1.0))
    return fail("alignment: the gate probability must lie in (0, 1)");
  return true;
}

StationaryAlignmentResult align_stationary(std::span<const ins::ImuIncrement> imu,
                                           std::span<const GnssAttitude> attitudes,
                                           const StationaryAlignmentOptions& o) {
  if (imu.size() < 2) throw std::invalid_argument("fewer than 2 IMU rows");
  if (std::string why; !o.IsValid(&why)) throw std::invalid_argument(why);
  AttitudeAidingOptions usable;
  usable.max_abs_pitch_rad = o.max_abs_pitch_rad;
  const double imu_start = imu[0].t_s - (imu[1].t_s - imu[0].t_s);
  std::size_t first = 0;
  while (first < attitudes.size() && !(attitudes[first].t_s >= imu_start && attitudes[first].t_s < imu.back().t_s &&
                                       attitude_usable(attitudes[first], usable)))
    ++first;
  if (first == attitudes.size()) throw std::invalid_argument("no usable GPS attitude inside the IMU data");
  const GnssAttitude& a0 = attitudes[first];
  // The INS starts at the last IMU row at or before the first attitude (at rest the attitude holds meanwhile).
  std::size_t row = 0;
  while (row + 1 < imu.size() && imu[row + 1].t_s <= a0.t_s) ++row;
  if (row + 1 >= imu.size()) throw std::invalid_argument("fewer than 2 IMU rows after the first GPS attitude");

  ins::NavState nav;
  nav.t_s = imu[row].t_s;  // (an attitude inside the first row's interval starts the INS at its end)
  const std::size_t first_row = row + 1;
  nav.lat_rad = o.lat_rad;
  nav.lon_rad = o.lon_rad;
  nav.height_m = o.height_m;
  nav.q_nb = measured_q_nb(a0, o.q_ba);

  const double g = ins::gravity_n(o.lat_rad, o.height_m).z();  // NED: down, positive
  const StationaryAlignmentModelOptions model = alignment_model_options(o.imu, o.lat_rad, g);
  const double zupt_sigma =
      o.zero_velocity_sigma_mps > 0.0 ? o.zero_velocity_sigma_mps : std::max(1e-3, o.imu.accel.output_white_noise);

  AlignmentMatrix P0 = AlignmentMatrix::Zero();
  P0.block<3, 3>(kVel, kVel) =
      Eigen::Matrix3d::Identity() * o.initial_velocity_sigma_mps * o.initial_velocity_sigma_mps;
  const Eigen::Matrix3d M = euler_rate_to_rotation_n(a0.euler_a);
  P0.block<3, 3>(kAtt, kAtt) = M * a0.sigma_euler_rad.cwiseAbs2().asDiagonal() * M.transpose();
  const double sa = std::max(1e-5, std::hypot(o.imu.accel.bias_sigma, o.imu.accel.bias_instability_sigma));
  const double sg = std::max(1e-8, std::hypot(o.imu.gyro.bias_sigma, o.imu.gyro.bias_instability_sigma));
  P0.block<3, 3>(kAccelBias, kAccelBias) = Eigen::Matrix3d::Identity() * sa * sa;
  P0.block<3, 3>(kGyroBias, kGyroBias) = Eigen::Matrix3d::Identity() * sg * sg;

  if (o.filter == FilterKind::Ukf) {
    Ukf<12> f(AlignmentVector::Zero(), P0, UkfOptions{o.ukf, Discretisation::VanLoan, o.gate});
    return run(f, imu, first_row, attitudes, first, nav, o, model, zupt_sigma);
  }
  Ekf<12> f(AlignmentVector::Zero(), P0, EkfOptions{Discretisation::VanLoan, o.gate});
  return run(f, imu, first_row, attitudes, first, nav, o, model, zupt_sigma);
}

}  // namespace ultratrack::fusion
