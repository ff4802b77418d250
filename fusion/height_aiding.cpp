#include "fusion/height_aiding.hpp"

#include <cmath>

namespace ultratrack::fusion {

double height_aiding_sigma_m(const HeightAidingOptions& o, double sigma_held_m, double dt_s) {
  const double grown = o.growth_mps * std::max(dt_s, 0.0);
  return std::sqrt(o.sigma0_m * o.sigma0_m + sigma_held_m * sigma_held_m + grown * grown);
}

template <int N>
HeightMeasurement<N>::HeightMeasurement(const NominalState& nominal, double height_m, double sigma_m)
    : nominal_(nominal), z_(1), R_(1, 1) {
  z_(0) = height_m;
  R_(0, 0) = sigma_m * sigma_m;
}

template <int N>
Eigen::VectorXd HeightMeasurement<N>::h(const StateVector<N>& dx) const {
  Eigen::VectorXd out(1);
  out(0) = corrected<N>(nominal_, dx).nav.height_m;
  return out;
}

template <int N>
MeasurementJacobian<N> HeightMeasurement<N>::H(const StateVector<N>&) const {
  MeasurementJacobian<N> H = MeasurementJacobian<N>::Zero(1, N);
  H(0, ix::kPos + 2) = 1.0;
  return H;
}

template class HeightMeasurement<15>;
template class HeightMeasurement<17>;

}  // namespace ultratrack::fusion
