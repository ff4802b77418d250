// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/carrier_rate_measurement.hpp"

#include <cmath>
#include <stdexcept>

#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {
std::vector<SatelliteObservable> satellites(const std::vector<CarrierRateRow>& rows) {
  std::vector<SatelliteObservable> out;
  out.reserve(rows.size());
  for (const CarrierRateRow& r : rows) out.push_back(r.sat);
  return out;
}
}  // namespace

double carrier_rate_phase_variance(double start_phase_var_rad2, double end_phase_var_rad2, double window_s) {
  if (!(window_s > 0.0)) throw std::invalid_argument("carrier_rate_phase_variance: window must be positive");
  const double k = signals::kL1Wavelength_m / (2.0 * M_PI * window_s);
  return k * k * (start_phase_var_rad2 + end_phase_var_rad2);
}

CarrierRateMeasurement::CarrierRateMeasurement(const NominalState& nominal, const std::vector<CarrierRateRow>& rows,
                                               const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                               double common_clock_var_m2ps2)
    : replica_(nominal, satellites(rows), lever_arm_b, w_ib_b) {
  const int n = static_cast<int>(rows.size());
  z_.resize(n);
  H_.resize(n, 17);
  R_ = Eigen::MatrixXd::Constant(n, n, common_clock_var_m2ps2);
  const MeasurementJacobian<17> J = replica_.jacobian();
  for (int i = 0; i < n; ++i) {
    z_(i) = rows[i].predicted_rate_mps - rows[i].rate_at_update_mps;
    H_.row(i) = J.row(2 * i + 1);
    R_(i, i) += rows[i].phase_noise_var_m2ps2;
  }
}

Eigen::VectorXd CarrierRateMeasurement::h(const StateVector<17>& dx) const {
  const Eigen::VectorXd e = replica_.errors(dx);
  Eigen::VectorXd out(z_.size());
  for (int i = 0; i < z_.size(); ++i) out(i) = e(2 * i + 1);
  return out;
}

}  // namespace ultratrack::fusion
