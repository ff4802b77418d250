// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/ins_error_model.hpp"

#include <cmath>

#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kWgs84A = 6378137.0;
constexpr double kWgs84F = 1.0 / 298.257223563;

SensorNoiseModel sensor_from_spec(const ins::SensorErrorSpec& s, double typical_input) {
  SensorNoiseModel m;
  // Scale factor and misalignment act like a bias of about sf * input while the motion lasts.
  const double sf = std::hypot(s.scale_factor_sigma, std::sqrt(2.0) * s.misalignment_sigma) * typical_input;
  m.bias_sigma = std::hypot(s.bias_sigma, sf);
  m.white_noise_psd = s.random_walk * s.random_walk;
  if (s.bias_instability_sigma > 0.0) {
    const double tau = s.bias_correlation_time_s;
    const double drive = 2.0 * s.bias_instability_sigma * s.bias_instability_sigma / tau;
    if (m.bias_sigma > 0.0) {
      // Turn-on bias plus instability in one state: random constant with the instability's short-term
      // random walk (2 sigma^2 / tau), which matches the Gauss-Markov growth for t << tau.
      m.bias_model = BiasModel::RandomConstant;
      m.bias_random_walk_psd = drive;
    } else {
      m.bias_model = BiasModel::GaussMarkov;
      m.gm_sigma = s.bias_instability_sigma;
      m.correlation_time_s = tau;
    }
  }
  return m;
}

double bias_drive_psd(const SensorNoiseModel& m) {
  double q = m.bias_random_walk_psd;
  if (m.bias_model == BiasModel::GaussMarkov && m.correlation_time_s > 0.0)
    q += 2.0 * m.gm_sigma * m.gm_sigma / m.correlation_time_s;
  return q;
}

}  // namespace

InsErrorModelOptions error_model_from_preset(const ins::ImuErrorSpec& spec, double typical_rate_rps) {
  InsErrorModelOptions o;
  o.accel = sensor_from_spec(spec.accel, 9.80665);
  o.gyro = sensor_from_spec(spec.gyro, typical_rate_rps);
  return o;
}

template <int N>
StateMatrix<N> ins_error_dynamics(const InsLinearisation& lin, const InsErrorModelOptions& opt) {
  using Eigen::Matrix3d;
  using Eigen::Vector3d;
  StateMatrix<N> F = StateMatrix<N>::Zero();
  const double L = lin.nav.lat_rad, h = lin.nav.height_m;
  const Vector3d v = lin.nav.v_n;
  const double sL = std::sin(L), cL = std::cos(L), tL = std::tan(L);
  const double e2 = kWgs84F * (2.0 - kWgs84F);
  const ins::Radii r = ins::radii_of_curvature(L);
  const double RM = r.meridian_m, RN = r.transverse_m;
  const double w2 = 1.0 - e2 * sL * sL;
  const double dRM = 3.0 * RM * e2 * sL * cL / w2;  // dR_M / dlat
  const double dRN = RN * e2 * sL * cL / w2;        // dR_N / dlat
  const double Rm = RM + h, Rn = RN + h;
  (void)kWgs84A;

  // Position error dr = T dp with dp = (dlat, dlon, dh).
  const Vector3d T(Rm, Rn * cL, -1.0);
  const Matrix3d Tinv = T.cwiseInverse().asDiagonal();
  const double lat_dot = v.x() / Rm, h_dot = -v.z();
  const Vector3d T_dot(dRM * lat_dot + h_dot, (dRN * cL - Rn * sL) * lat_dot + h_dot * cL, 0.0);
  Matrix3d Gp = Matrix3d::Zero();  // d(lat_dot, lon_dot, h_dot) / d(lat, lon, h)
  Gp(0, 0) = -v.x() * dRM / (Rm * Rm);
  Gp(0, 2) = -v.x() / (Rm * Rm);
  Gp(1, 0) = -v.y() * (dRN * cL - Rn * sL) / (Rn * Rn * cL * cL);
  Gp(1, 2) = -v.y() / (Rn * Rn * cL);
  const Matrix3d Fpp = (Matrix3d(T_dot.asDiagonal()) + T.asDiagonal() * Gp) * Tinv;

  // Earth rate and transport rate derivatives.
  const double W = ins::kEarthRate_rps;
  const Vector3d w_ie = ins::earth_rate_n(L);
  const Vector3d w_en = ins::transport_rate_n(L, h, v);
  Matrix3d Wie_p = Matrix3d::Zero();
  Wie_p.col(0) = Vector3d(-W * sL, 0.0, -W * cL);
  Matrix3d Wen_p = Matrix3d::Zero();
  Wen_p.col(0) =
      Vector3d(-v.y() * dRN / (Rn * Rn), v.x() * dRM / (Rm * Rm), -v.y() * (Rn / (cL * cL) - tL * dRN) / (Rn * Rn));
  Wen_p.col(2) = Vector3d(-v.y() / (Rn * Rn), v.x() / (Rm * Rm), v.y() * tL / (Rn * Rn));
  Matrix3d Wen_v = Matrix3d::Zero();
  Wen_v(0, 1) = 1.0 / Rn;
  Wen_v(1, 0) = -1.0 / Rm;
  Wen_v(2, 1) = -tL / Rn;

  // Gravity derivatives by central differences of the normal-gravity model (smooth, tiny terms).
  Matrix3d Gg_p = Matrix3d::Zero();
  const double dlat = 1e-5, dh = 10.0;
  Gg_p.col(0) = (ins::gravity_n(L + dlat, h) - ins::gravity_n(L - dlat, h)) / (2.0 * dlat);
  Gg_p.col(2) = (ins::gravity_n(L, h + dh) - ins::gravity_n(L, h - dh)) / (2.0 * dh);

  const Matrix3d C = lin.nav.q_nb.toRotationMatrix();
  const Vector3d f_n = C * lin.f_b;
  const Matrix3d vx = ins::skew(v);

  F.template block<3, 3>(ix::kPos, ix::kPos) = Fpp;
  F.template block<3, 3>(ix::kPos, ix::kVel) = Matrix3d::Identity();
  F.template block<3, 3>(ix::kVel, ix::kPos) = (vx * (2.0 * Wie_p + Wen_p) + Gg_p) * Tinv;
  F.template block<3, 3>(ix::kVel, ix::kVel) = -ins::skew(2.0 * w_ie + w_en) + vx * Wen_v;
  F.template block<3, 3>(ix::kVel, ix::kAtt) = ins::skew(f_n);
  F.template block<3, 3>(ix::kVel, ix::kAccelBias) = C;
  F.template block<3, 3>(ix::kAtt, ix::kPos) = (Wie_p + Wen_p) * Tinv;
  F.template block<3, 3>(ix::kAtt, ix::kVel) = Wen_v;
  F.template block<3, 3>(ix::kAtt, ix::kAtt) = -ins::skew(w_ie + w_en);
  F.template block<3, 3>(ix::kAtt, ix::kGyroBias) = -C;
  if (opt.accel.bias_model == BiasModel::GaussMarkov && opt.accel.correlation_time_s > 0.0)
    F.template block<3, 3>(ix::kAccelBias, ix::kAccelBias) = -Matrix3d::Identity() / opt.accel.correlation_time_s;
  if (opt.gyro.bias_model == BiasModel::GaussMarkov && opt.gyro.correlation_time_s > 0.0)
    F.template block<3, 3>(ix::kGyroBias, ix::kGyroBias) = -Matrix3d::Identity() / opt.gyro.correlation_time_s;
  if constexpr (N == 17) F(ix::kClockBias, ix::kClockDrift) = 1.0;
  return F;
}

template <int N>
InsErrorModel<N>::InsErrorModel(const InsErrorModelOptions& options) : opt_(options) {
  F_ = ins_error_dynamics<N>(lin_, opt_);
}

template <int N>
void InsErrorModel<N>::set_linearisation(const InsLinearisation& lin) {
  lin_ = lin;
  F_ = ins_error_dynamics<N>(lin_, opt_);
  cached_dt_ = -1.0;
}

template <int N>
const StateMatrix<N>& InsErrorModel<N>::transition(double dt) const {
  if (dt != cached_dt_) {
    cached_phi_ = discretise<N>(F_, StateMatrix<N>::Zero(), dt, opt_.discretisation).Phi;
    cached_dt_ = dt;
  }
  return cached_phi_;
}

template <int N>
StateVector<N> InsErrorModel<N>::f(const StateVector<N>& x, double dt) const {
  return transition(dt) * x;
}

template <int N>
auto InsErrorModel<N>::G(const StateVector<N>&) const -> Eigen::Matrix<double, N, kNoiseSize> {
  Eigen::Matrix<double, N, kNoiseSize> G = Eigen::Matrix<double, N, kNoiseSize>::Zero();
  const Eigen::Matrix3d C = lin_.nav.q_nb.toRotationMatrix();
  G.template block<3, 3>(ix::kVel, 0) = C;
  G.template block<3, 3>(ix::kAtt, 3) = -C;
  G.template block<3, 3>(ix::kAccelBias, 6) = Eigen::Matrix3d::Identity();
  G.template block<3, 3>(ix::kGyroBias, 9) = Eigen::Matrix3d::Identity();
  if constexpr (N == 17) {
    G(ix::kClockBias, 12) = 1.0;
    G(ix::kClockDrift, 13) = 1.0;
  }
  return G;
}

template <int N>
auto InsErrorModel<N>::Qc() const -> Eigen::Matrix<double, kNoiseSize, kNoiseSize> {
  Eigen::Matrix<double, kNoiseSize, 1> q;
  q.template segment<3>(0).setConstant(opt_.accel.white_noise_psd);
  q.template segment<3>(3).setConstant(opt_.gyro.white_noise_psd);
  q.template segment<3>(6).setConstant(bias_drive_psd(opt_.accel));
  q.template segment<3>(9).setConstant(bias_drive_psd(opt_.gyro));
  if constexpr (N == 17) {
    q(12) = opt_.clock.bias_psd_m2_per_s;
    q(13) = opt_.clock.drift_psd_m2_per_s3;
  }
  return q.asDiagonal();
}

template <int N>
StateMatrix<N> InsErrorModel<N>::initial_covariance(const Eigen::Vector3d& sp, const Eigen::Vector3d& sv,
                                                    const Eigen::Vector3d& sa) const {
  StateVector<N> d;
  d.template segment<3>(ix::kPos) = sp.cwiseAbs2();
  d.template segment<3>(ix::kVel) = sv.cwiseAbs2();
  d.template segment<3>(ix::kAtt) = sa.cwiseAbs2();
  const double ba2 = opt_.accel.bias_sigma * opt_.accel.bias_sigma + opt_.accel.gm_sigma * opt_.accel.gm_sigma;
  const double bg2 = opt_.gyro.bias_sigma * opt_.gyro.bias_sigma + opt_.gyro.gm_sigma * opt_.gyro.gm_sigma;
  d.template segment<3>(ix::kAccelBias).setConstant(ba2);
  d.template segment<3>(ix::kGyroBias).setConstant(bg2);
  if constexpr (N == 17) {
    d(ix::kClockBias) = opt_.clock.bias_sigma_m * opt_.clock.bias_sigma_m;
    d(ix::kClockDrift) = opt_.clock.drift_sigma_mps * opt_.clock.drift_sigma_mps;
  }
  return d.asDiagonal();
}

template StateMatrix<15> ins_error_dynamics<15>(const InsLinearisation&, const InsErrorModelOptions&);
template StateMatrix<17> ins_error_dynamics<17>(const InsLinearisation&, const InsErrorModelOptions&);
template class InsErrorModel<15>;
template class InsErrorModel<17>;

}  // namespace ultratrack::fusion
