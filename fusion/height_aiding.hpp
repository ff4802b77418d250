// SPDX-License-Identifier: GPL-3.0-or-later
// Height aiding for tight integration when an epoch has fewer than 4 usable satellites (land vehicles), with a
// terrain-height state: the filter gains an 18th state, the error of its estimate of the terrain height under
// the vehicle (estimate minus truth, metres). The terrain height is modelled as a first-order Gauss-Markov
// process about a reference height (held from the last epoch with >= 4 satellites, or configured):
//   (h_t - h_ref)' = -(h_t - h_ref) / tau + w,   PSD 2 sigma_t^2 / tau   (stationary 1-sigma sigma_t)
// and each aid is a measurement "the IMU's height equals the terrain height" with white noise sigma0 (bumps,
// suspension, the road's small undulation). Repeated aids are then weighted by the filter itself: their common
// error is a state, not a re-weighting. When the height is held from the filter, the terrain state starts
// as exactly the negative of the INS down-error state (the reference IS the INS height), so the held
// value's own error is carried with its correlations. Metres, seconds.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

struct HeightAidingOptions {
  bool enabled = false;                  // off by default (aircraft; or any vehicle free to change height)
  int min_satellites = 4;                // aid epochs with fewer usable satellites than this
  double sigma0_m = 2.0;                 // white part of each aid (IMU height above the terrain varies by this much)
  double terrain_sigma_m = 10.0;         // stationary 1-sigma of the terrain about the reference height
  double terrain_correlation_s = 100.0;  // terrain correlation time (correlation distance / speed)
  double min_interval_s = 1.0;           // at most one aid per interval
  std::optional<double> fixed_height_m;  // configured reference (IMU, ellipsoidal); else held from full epochs
};

namespace ix {
inline constexpr int kTerrain = 17;  // terrain height error (18-state model: tight + height aiding)
}

// The 18-state process model: the 17-state INS/clock error model plus the terrain Gauss-Markov state
// (F = -1/tau, noise PSD 2 sigma_t^2 / tau). Satisfies ProcessModel<18>.
class TerrainAugmentedModel {
 public:
  static constexpr int kNoiseSize = InsErrorModel<17>::kNoiseSize + 1;

  TerrainAugmentedModel(const InsErrorModelOptions& options, const HeightAidingOptions& aiding);

  void set_linearisation(const InsLinearisation& lin);
  StateVector<18> f(const StateVector<18>& x, double dt) const;
  StateMatrix<18> F(const StateVector<18>& /*x*/) const { return F_; }
  Eigen::Matrix<double, 18, kNoiseSize> G(const StateVector<18>& x) const;
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const;
  // 18 x 18 initial covariance: the 17-state one, terrain variance sigma_t^2, no correlation.
  StateMatrix<18> initial_covariance(const Eigen::Vector3d& sigma_pos_ned_m, const Eigen::Vector3d& sigma_vel_n_mps,
                                     const Eigen::Vector3d& sigma_att_rad) const;

 private:
  InsErrorModel<17> ins_;
  double tau_s_, sigma_m_;
  StateMatrix<18> F_ = StateMatrix<18>::Zero();
  mutable double cached_dt_ = -1.0;
  mutable StateMatrix<18> cached_phi_ = StateMatrix<18>::Identity();
};

// A 17-state measurement used in the 18-state filter: the terrain state does not enter it.
template <class M>
using TerrainPadded = PaddedMeasurement<M, 17, 18>;

// The aid: z = the nominal terrain height; h(dx) = height of the corrected INS nominal + terrain error state
// (IMU truth height = nominal + dx_d; terrain truth = terrain nominal - dx_t; their difference is the white
// noise sigma0).
class TerrainHeightMeasurement {
 public:
  TerrainHeightMeasurement(const NominalState& nominal, double terrain_height_m, double sigma0_m);
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<18>& dx) const;
  MeasurementJacobian<18> H(const StateVector<18>& dx) const;
  Eigen::MatrixXd R() const { return R_; }

 private:
  NominalState nominal_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

// Hold the INS height as the new terrain reference: the terrain error becomes -(INS down error) plus the
// white sigma0 (rows/columns copied with the sign), in place on the 18 x 18 covariance.
void hold_terrain_at_ins_height(StateMatrix<18>& P, double sigma0_m);

}  // namespace ultratrack::fusion
