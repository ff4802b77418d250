// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/iq_measurements.hpp"

#include <array>
#include <cmath>
#include <complex>

#include "io/input_error.hpp"
#include "receiver/discriminators.hpp"
#include "signals/ca_code.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kChip_m = signals::kSpeedOfLight_mps / signals::kCaChipRate_hz;
constexpr double kLambda_m = signals::kL1Wavelength_m;

double cn0_hz(const IqSettings& s) { return std::pow(10.0, s.cn0_dbhz / 10.0); }

// sinc(x) cos(x) = sin(2x) / (2x) and sinc(x) sin(x) = sin^2(x) / x, with their x-derivatives; series near 0.
struct Rot {
  double c, s, dc, ds;  // values and d/dx
};
Rot rotation_terms(double x) {
  if (std::abs(x) < 1e-4) {
    const double x2 = x * x;
    return {1.0 - 2.0 * x2 / 3.0, x - x * x2 / 3.0, -4.0 * x / 3.0, 1.0 - x2};
  }
  const double s2 = std::sin(2.0 * x), sx = std::sin(x);
  return {s2 / (2.0 * x), sx * sx / x, std::cos(2.0 * x) / x - s2 / (2.0 * x * x), s2 / x - sx * sx / (x * x)};
}

// The same terms turned by a start phase phi: sinc(x) cos(phi + x), sinc(x) sin(phi + x).
Rot rotate(const Rot& r, double phi) {
  if (phi == 0.0) return r;
  const double c = std::cos(phi), s = std::sin(phi);
  return {r.c * c - r.s * s, r.s * c + r.c * s, r.dc * c - r.ds * s, r.ds * c + r.dc * s};
}

void check(const IqSettings& s) {
  if (!(s.integration_time_s > 0.0) || !std::isfinite(s.cn0_dbhz) || !(s.tap_offset_chips > 0.0) ||
      !(s.tap_offset_chips <= 0.5))
    throw io::InputError("I&Q settings", "need T > 0, finite C/N0 and 0 < tap offset <= 0.5 chip");
  if (!(std::abs(s.code_lag1_correlation) < 1.0))
    throw io::InputError("I&Q settings", "the code's one-chip autocorrelation must lie in (-1, 1)");
}

// Early replica = code advanced by d chips: it correlates with the signal at lag tau - d (E = R(tau - d)).
std::array<double, 3> tap_offsets(const IqSettings& s) { return {s.tap_offset_chips, 0.0, -s.tap_offset_chips}; }

}  // namespace

double iq_amplitude(const IqSettings& s) { return std::sqrt(2.0 * cn0_hz(s) * s.integration_time_s); }

double triangle_correlation(double x) { return std::abs(x) < 1.0 ? 1.0 - std::abs(x) : 0.0; }

double triangle_slope(double x) {
  const double a = std::abs(x);
  if (a == 0.0) return 0.0;
  if (a > 1.0) return 0.0;
  const double one_sided = x < 0.0 ? 1.0 : -1.0;
  return a == 1.0 ? 0.5 * one_sided : one_sided;
}

double code_correlation(double x, double lag1) {
  const double a = std::abs(x);
  if (a < 1.0) return 1.0 - a * (1.0 - lag1);
  if (a < 2.0) return lag1 * (2.0 - a);
  return 0.0;
}

double code_correlation_slope(double x, double lag1) {
  const double a = std::abs(x);
  if (a == 0.0 || a > 2.0) return 0.0;
  const double toward = x < 0.0 ? 1.0 : -1.0;  // sign of d|x|/dx, negated
  if (a < 1.0) return toward * (1.0 - lag1);
  if (a == 1.0) return toward * 0.5 * ((1.0 - lag1) + lag1);
  if (a < 2.0) return toward * lag1;
  return toward * 0.5 * lag1;  // a == 2
}

double ca_code_lag1_correlation(int prn) {
  if (prn < 1 || prn > 32) return 0.0;
  static const std::array<double, 33> table = [] {
    std::array<double, 33> r{};
    for (int p = 1; p <= 32; ++p) {
      const auto& c = signals::ca_code(p);
      long sum = 0;
      for (int i = 0; i < signals::kCaCodeLength_chips; ++i)
        sum += c[static_cast<std::size_t>(i)] * c[static_cast<std::size_t>((i + 1) % signals::kCaCodeLength_chips)];
      r[static_cast<std::size_t>(p)] = static_cast<double>(sum) / signals::kCaCodeLength_chips;
    }
    return r;
  }();
  return table[static_cast<std::size_t>(prn)];
}

TrackingErrors tracking_errors(double range_error_m, double range_rate_error_mps) {
  return {range_error_m / kChip_m, range_rate_error_mps / kLambda_m};
}

Eigen::Vector2d period_replica_errors(double replica_range_start_m, double replica_rate_mps, double signal_range_end_m,
                                      double signal_rate_start_mps, double signal_rate_end_mps, double L) {
  const double slope = signal_rate_end_mps - signal_rate_start_mps;  // rate change over the period
  // Signal range at u: end range minus the integral of the rate from u to L; its mean over [0, L].
  const double signal_mean = signal_range_end_m - signal_rate_start_mps * L / 2.0 - slope * L / 3.0;
  const double replica_mean = replica_range_start_m + replica_rate_mps * L / 2.0;
  return {replica_mean - signal_mean, replica_rate_mps - (signal_rate_start_mps + slope / 3.0)};
}

IqTaps expected_iq(const TrackingErrors& e, const IqSettings& s) {
  check(s);
  const double A = iq_amplitude(s);
  const Rot r = rotate(rotation_terms(kPi * e.frequency_hz * s.integration_time_s), e.phase_rad);
  const auto o = tap_offsets(s);
  IqTaps t;
  for (int k = 0; k < 3; ++k) {
    const double c = A * code_correlation(e.code_chips - o[k], s.code_lag1_correlation);
    t.i[k] = c * r.c;
    t.q[k] = c * r.s;
  }
  return t;
}

Eigen::Matrix<double, 6, 1> iq_phase_derivative(const TrackingErrors& e, const IqSettings& s) {
  const IqTaps t = expected_iq(e, s);
  Eigen::Matrix<double, 6, 1> d;
  d << -t.q[0], -t.q[1], -t.q[2], t.i[0], t.i[1], t.i[2];
  return d;
}

Eigen::Matrix<double, 6, 2> iq_jacobian(const TrackingErrors& e, const IqSettings& s) {
  check(s);
  const double A = iq_amplitude(s);
  const double dx_df = kPi * s.integration_time_s;
  const Rot r = rotate(rotation_terms(dx_df * e.frequency_hz), e.phase_rad);
  const auto o = tap_offsets(s);
  Eigen::Matrix<double, 6, 2> J;
  for (int k = 0; k < 3; ++k) {
    const double R = A * code_correlation(e.code_chips - o[k], s.code_lag1_correlation);
    const double dR = A * code_correlation_slope(e.code_chips - o[k], s.code_lag1_correlation);
    J(k, 0) = dR * r.c;
    J(k, 1) = R * r.dc * dx_df;
    J(3 + k, 0) = dR * r.s;
    J(3 + k, 1) = R * r.ds * dx_df;
  }
  return J;
}

Eigen::Matrix<double, 6, 6> iq_noise_covariance(const IqSettings& s) {
  check(s);
  const auto o = tap_offsets(s);
  Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      C(j, k) = code_correlation(o[j] - o[k], s.code_lag1_correlation);
      C(3 + j, 3 + k) = C(j, k);
    }
  return C;
}

double code_discriminator_chips(const IqTaps& t, const IqSettings& s) {
  const std::complex<float> early(static_cast<float>(t.i[0]), static_cast<float>(t.q[0]));
  const std::complex<float> late(static_cast<float>(t.i[2]), static_cast<float>(t.q[2]));
  return receiver::dll_nelp_chips(early, late, s.tap_offset_chips);
}

double frequency_discriminator_hz(const IqTaps& t, const IqSettings& s) {
  return std::atan2(t.q[1], t.i[1]) / (kPi * s.integration_time_s);
}

DiscriminatorNoise discriminator_noise(const IqSettings& s, bool squaring_loss) {
  check(s);
  const double cn0 = cn0_hz(s), T = s.integration_time_s, D = 2.0 * s.tap_offset_chips;
  const double B = 1.0 / (2.0 * T);
  DiscriminatorNoise n;
  n.code_var_chips2 = B * D / (2.0 * cn0);
  const double phase_var = B / cn0 * (squaring_loss ? 1.0 + 1.0 / (2.0 * T * cn0) : 1.0);
  n.frequency_var_hz2 = phase_var / std::pow(kPi * T, 2);
  n.range_sigma_m = std::sqrt(n.code_var_chips2) * kChip_m;
  n.rate_sigma_mps = std::sqrt(n.frequency_var_hz2) * kLambda_m;
  return n;
}

ReplicaErrors17::ReplicaErrors17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                                 const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b) {
  rows_.reserve(sats.size());
  for (SatelliteObservable s : sats) {
    s.has_rate = true;
    rows_.emplace_back(nominal, s, lever_arm_b, w_ib_b, true);
  }
  nominal_.resize(2 * size());
  const StateVector<17> zero = StateVector<17>::Zero();
  for (int i = 0; i < size(); ++i) nominal_.segment<2>(2 * i) = rows_[i].range_and_rate(zero);
}

Eigen::VectorXd ReplicaErrors17::errors(const StateVector<17>& dx) const {
  Eigen::VectorXd out(2 * size());
  for (int i = 0; i < size(); ++i) out.segment<2>(2 * i) = errors(i, dx);
  return out;
}

Eigen::Vector2d ReplicaErrors17::errors(int satellite, const StateVector<17>& dx) const {
  return nominal_.segment<2>(2 * satellite) - rows_[satellite].range_and_rate(dx);
}

MeasurementJacobian<17> ReplicaErrors17::jacobian() const {
  MeasurementJacobian<17> J(2 * size(), 17);
  const StateVector<17> zero = StateVector<17>::Zero();
  for (int i = 0; i < size(); ++i) J.middleRows<2>(2 * i) = -rows_[i].H(zero);
  return J;
}

IqEpochMeasurement17::IqEpochMeasurement17(const NominalState& nominal, const std::vector<SatelliteObservable>& sats,
                                           const Eigen::Vector3d& lever_arm_b, const Eigen::Vector3d& w_ib_b,
                                           const IqSettings& settings, const std::vector<IqTaps>& measured)
    : replica_(nominal, sats, lever_arm_b, w_ib_b), settings_(settings) {
  check(settings);
  if (measured.size() != sats.size())
    throw io::InputError("I&Q measurement", "one set of taps per satellite is needed");
  const int n = replica_.size();
  z_.resize(kIqRowsPerChannel * n);
  R_ = Eigen::MatrixXd::Zero(z_.size(), z_.size());
  const Eigen::Matrix<double, 6, 6> C = iq_noise_covariance(settings);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      z_(6 * i + k) = measured[i].i[k];
      z_(6 * i + 3 + k) = measured[i].q[k];
    }
    R_.block<6, 6>(6 * i, 6 * i) = C;
  }
}

TrackingErrors IqEpochMeasurement17::errors_of(const Eigen::VectorXd& e, int i) const {
  TrackingErrors t = tracking_errors(e(2 * i), e(2 * i + 1));
  // Signal minus replica phase: a shorter signal range advances its carrier as it advances its code.
  if (settings_.absolute_carrier_phase) t.phase_rad = 2.0 * kPi * e(2 * i) / kLambda_m;
  return t;
}

Eigen::VectorXd IqEpochMeasurement17::h(const StateVector<17>& dx) const {
  const Eigen::VectorXd e = replica_.errors(dx);
  Eigen::VectorXd out(z_.size());
  for (int i = 0; i < replica_.size(); ++i) {
    const IqTaps t = expected_iq(errors_of(e, i), settings_);
    for (int k = 0; k < 3; ++k) {
      out(6 * i + k) = t.i[k];
      out(6 * i + 3 + k) = t.q[k];
    }
  }
  return out;
}

MeasurementJacobian<17> IqEpochMeasurement17::H(const StateVector<17>& dx) const {
  const Eigen::VectorXd e = replica_.errors(dx);
  const MeasurementJacobian<17> Je = replica_.jacobian();
  MeasurementJacobian<17> out(z_.size(), 17);
  Eigen::Matrix2d scale = Eigen::Matrix2d::Zero();  // d(code, freq) / d(range, rate)
  scale(0, 0) = 1.0 / kChip_m;
  scale(1, 1) = 1.0 / kLambda_m;
  for (int i = 0; i < replica_.size(); ++i) {
    const TrackingErrors te = errors_of(e, i);
    const Eigen::Matrix<double, 6, 2> J = iq_jacobian(te, settings_);
    out.middleRows<6>(6 * i) = J * scale * Je.middleRows<2>(2 * i);
    if (settings_.absolute_carrier_phase)
      out.middleRows<6>(6 * i) += iq_phase_derivative(te, settings_) * (2.0 * kPi / kLambda_m) * Je.row(2 * i);
  }
  return out;
}

DiscriminatorEpochMeasurement17::DiscriminatorEpochMeasurement17(const NominalState& nominal,
                                                                 const std::vector<SatelliteObservable>& sats,
                                                                 const Eigen::Vector3d& lever_arm_b,
                                                                 const Eigen::Vector3d& w_ib_b,
                                                                 const Eigen::VectorXd& measured, double range_sigma_m,
                                                                 double rate_sigma_mps, bool use_rate)
    : replica_(nominal, sats, lever_arm_b, w_ib_b), rate_(use_rate) {
  if (measured.size() != 2 * replica_.size())
    throw io::InputError("discriminator measurement", "a range and a rate error per satellite are needed");
  if (!(range_sigma_m > 0.0) || (use_rate && !(rate_sigma_mps > 0.0)))
    throw io::InputError("discriminator measurement", "sigmas must be positive");
  z_ = select(measured);
  const int n = replica_.size();
  R_ = Eigen::MatrixXd::Zero(z_.size(), z_.size());
  for (int i = 0; i < n; ++i) {
    if (rate_) {
      R_(2 * i, 2 * i) = range_sigma_m * range_sigma_m;
      R_(2 * i + 1, 2 * i + 1) = rate_sigma_mps * rate_sigma_mps;
    } else {
      R_(i, i) = range_sigma_m * range_sigma_m;
    }
  }
}

Eigen::VectorXd DiscriminatorEpochMeasurement17::select(const Eigen::VectorXd& both) const {
  if (rate_) return both;
  Eigen::VectorXd out(both.size() / 2);
  for (int i = 0; i < out.size(); ++i) out(i) = both(2 * i);
  return out;
}

Eigen::VectorXd DiscriminatorEpochMeasurement17::h(const StateVector<17>& dx) const {
  return select(replica_.errors(dx));
}

MeasurementJacobian<17> DiscriminatorEpochMeasurement17::H(const StateVector<17>&) const {
  const MeasurementJacobian<17> J = replica_.jacobian();
  if (rate_) return J;
  MeasurementJacobian<17> out(J.rows() / 2, 17);
  for (int i = 0; i < out.rows(); ++i) out.row(i) = J.row(2 * i);
  return out;
}

}  // namespace ultratrack::fusion
