// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/height_aiding.hpp"

#include <cmath>
#include <stdexcept>

#include "fusion/discretisation.hpp"

namespace ultratrack::fusion {

TerrainAugmentedModel::TerrainAugmentedModel(const InsErrorModelOptions& options, const HeightAidingOptions& aiding)
    : ins_(options), tau_s_(aiding.terrain_correlation_s), sigma_m_(aiding.terrain_sigma_m) {
  if (!(tau_s_ > 0.0) || !(sigma_m_ > 0.0) || !std::isfinite(tau_s_) || !std::isfinite(sigma_m_))
    throw std::invalid_argument("terrain height: sigma and correlation time must be positive");
  set_linearisation(InsLinearisation{});
}

void TerrainAugmentedModel::set_linearisation(const InsLinearisation& lin) {
  ins_.set_linearisation(lin);
  F_.setZero();
  F_.topLeftCorner<17, 17>() = ins_.F(StateVector<17>::Zero());
  F_(ix::kTerrain, ix::kTerrain) = -1.0 / tau_s_;
  cached_dt_ = -1.0;
}

StateVector<18> TerrainAugmentedModel::f(const StateVector<18>& x, double dt) const {
  if (dt != cached_dt_) {
    cached_phi_ = discretise<18>(F_, StateMatrix<18>::Zero(), dt, ins_.options().discretisation).Phi;
    cached_dt_ = dt;
  }
  return cached_phi_ * x;
}

auto TerrainAugmentedModel::G(const StateVector<18>&) const -> Eigen::Matrix<double, 18, kNoiseSize> {
  Eigen::Matrix<double, 18, kNoiseSize> g = Eigen::Matrix<double, 18, kNoiseSize>::Zero();
  g.topLeftCorner<17, kNoiseSize - 1>() = ins_.G(StateVector<17>::Zero());
  g(ix::kTerrain, kNoiseSize - 1) = 1.0;
  return g;
}

auto TerrainAugmentedModel::Qc() const -> Eigen::Matrix<double, kNoiseSize, kNoiseSize> {
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> q = Eigen::Matrix<double, kNoiseSize, kNoiseSize>::Zero();
  q.topLeftCorner<kNoiseSize - 1, kNoiseSize - 1>() = ins_.Qc();
  q(kNoiseSize - 1, kNoiseSize - 1) = 2.0 * sigma_m_ * sigma_m_ / tau_s_;
  return q;
}

StateMatrix<18> TerrainAugmentedModel::initial_covariance(const Eigen::Vector3d& sp, const Eigen::Vector3d& sv,
                                                          const Eigen::Vector3d& sa) const {
  StateMatrix<18> P = StateMatrix<18>::Zero();
  P.topLeftCorner<17, 17>() = ins_.initial_covariance(sp, sv, sa);
  P(ix::kTerrain, ix::kTerrain) = sigma_m_ * sigma_m_;
  return P;
}

TerrainHeightMeasurement::TerrainHeightMeasurement(const NominalState& nominal, double terrain_height_m,
                                                   double sigma0_m)
    : nominal_(nominal), z_(1), R_(1, 1) {
  z_(0) = terrain_height_m;
  R_(0, 0) = sigma0_m * sigma0_m;
}

Eigen::VectorXd TerrainHeightMeasurement::h(const StateVector<18>& dx) const {
  Eigen::VectorXd out(1);
  out(0) = corrected<17>(nominal_, dx.head<17>()).nav.height_m + dx(ix::kTerrain);
  return out;
}

MeasurementJacobian<18> TerrainHeightMeasurement::H(const StateVector<18>&) const {
  MeasurementJacobian<18> H = MeasurementJacobian<18>::Zero(1, 18);
  H(0, ix::kPos + 2) = 1.0;  // a down error dx_d: truth height = nominal height + dx_d
  H(0, ix::kTerrain) = 1.0;
  return H;
}

void hold_terrain_at_ins_height(StateMatrix<18>& P, double sigma0_m) {
  const StateVector<18> down = P.col(ix::kPos + 2);
  P.col(ix::kTerrain) = -down;
  P.row(ix::kTerrain) = -down.transpose();
  P(ix::kTerrain, ix::kTerrain) = down(ix::kPos + 2) + sigma0_m * sigma0_m;
}

}  // namespace ultratrack::fusion
