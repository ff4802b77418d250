// Height aiding for tight integration when an epoch has fewer than 4 usable satellites (land vehicles): a
// pseudo-measurement of the IMU's ellipsoidal height, held from the last epoch with >= 4 satellites (or a
// configured height: terrain-constant assumption). Its 1-sigma grows with the time since that epoch:
//   sigma^2 = sigma0^2 + sigma_held^2 + (growth * dt)^2
// sigma0: how far the road leaves a constant height at once (antenna motion, small undulation); sigma_held: the
// filter's own vertical 1-sigma when the height was held (the held value is an estimate, not truth); growth:
// the vertical speed the vehicle may keep on average (road grade x speed, e.g. 1 % at 10 m/s = 0.1 m/s).
// The k-th aid since that epoch (at most one per min_interval_s) gets k sigma^2: all of them reuse ONE held
// value whose error is common to them, so their total information grows only like the harmonic series instead
// of k-fold (the filter would otherwise become overconfident in height). Before any 4-satellite epoch the held
// height is the initial state's, with its initial sigma. Applied through the same Ekf/Ukf update and innovation
// gate as any measurement. Metres, seconds.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"

namespace ultratrack::fusion {

struct HeightAidingOptions {
  bool enabled = false;        // off by default (aircraft; or any vehicle free to change height)
  int min_satellites = 4;      // aid epochs with fewer usable satellites than this
  double sigma0_m = 2.0;
  double growth_mps = 0.1;
  double min_interval_s = 1.0;
  std::optional<double> fixed_height_m;  // configured height (IMU, ellipsoidal); else held from the last full epoch
};

// 1-sigma of the pseudo-measurement dt seconds after the height was held with the filter's sigma_held.
double height_aiding_sigma_m(const HeightAidingOptions& options, double sigma_held_m, double dt_s);

// The pseudo-measurement: z = reference height; h(dx) = height of the corrected nominal (truth = nominal with
// dx removed: a down error dx_d means truth height = nominal height + dx_d).
template <int N>
class HeightMeasurement {
 public:
  HeightMeasurement(const NominalState& nominal, double height_m, double sigma_m);
  Eigen::VectorXd z() const { return z_; }
  Eigen::VectorXd h(const StateVector<N>& dx) const;
  MeasurementJacobian<N> H(const StateVector<N>& dx) const;
  Eigen::MatrixXd R() const { return R_; }
  int size() const { return 1; }

 private:
  NominalState nominal_;
  Eigen::VectorXd z_;
  Eigen::MatrixXd R_;
};

extern template class HeightMeasurement<15>;
extern template class HeightMeasurement<17>;

}  // namespace ultratrack::fusion
