// SPDX-License-Identifier: GPL-3.0-or-later
// Continuous-time INS error dynamics in NED for the error state of ins_error_state.hpp (15 or 17 states),
// linearised about the current nominal: position, velocity and psi-angle attitude errors driven by the
// residual IMU biases and white sensor noise, including the position/velocity dependence of earth rate,
// transport rate and gravity (exact first order for the error definitions; at rest it reduces to [KimAlign]
// eqs. 5-9: T = [C_nb 0; 0 -C_nb]). Biases: random constant or first-order Gauss-Markov. Clock (17 states):
// bias' = drift + w_b, drift' = w_d. Units: m, m/s, rad, m/s^2, rad/s; PSDs in units^2/Hz.
// Satisfies the ProcessModel concept (filter_types.hpp): f(x, dt) = Phi(dt) x with the model's own
// discretisation, so the UKF and EKF propagate identically.
#pragma once

#include <Eigen/Core>

#include "fusion/discretisation.hpp"
#include "fusion/filter_types.hpp"
#include "fusion/ins_error_state.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_state.hpp"

namespace ultratrack::fusion {

enum class BiasModel {
  RandomConstant,  // b' = 0 (+ optional small random walk)
  GaussMarkov,     // b' = -b / tau + w, PSD 2 sigma^2 / tau
};

struct SensorNoiseModel {
  BiasModel bias_model = BiasModel::RandomConstant;
  double bias_sigma = 0.0;  // initial 1-sigma of the residual bias (turn-on) [m/s^2 | rad/s]
  double gm_sigma = 0.0;    // steady-state sigma of the Gauss-Markov part
  double correlation_time_s = 3600.0;
  double bias_random_walk_psd = 0.0;  // extra random-walk PSD on the bias [(m/s^2)^2/Hz | (rad/s)^2/Hz]
  double white_noise_psd = 0.0;       // VRW^2 [(m/s)^2/s] | ARW^2 [rad^2/s]
};

struct ClockNoiseModel {
  // Defaults: a TCXO (h0 = 2e-19, h-2 = 2e-20): S_b = c^2 h0 / 2, S_d = c^2 2 pi^2 h-2.
  double bias_psd_m2_per_s = 0.009;     // white frequency noise on the bias [m^2/s]
  double drift_psd_m2_per_s3 = 0.0355;  // random-walk frequency [m^2/s^3]
  double bias_sigma_m = 1e4;            // initial 1-sigma
  double drift_sigma_mps = 100.0;
};

struct InsErrorModelOptions {
  SensorNoiseModel accel;
  SensorNoiseModel gyro;
  ClockNoiseModel clock;  // 17-state model only
  Discretisation discretisation = Discretisation::SecondOrderSeries;
};

// Noise settings from an ins/ IMU error preset: turn-on bias sigma -> initial bias sigma; bias instability
// (if any) -> Gauss-Markov with the preset's correlation time; random walks -> white-noise PSDs.
// Turn-on bias plus instability: random constant with the instability's short-term random walk 2 s^2/tau;
// instability alone: Gauss-Markov. Scale factor and misalignment are not states: they are added to the
// bias sigma as sf * typical input (typical_rate_rps for the gyro, g for the accelerometer).
InsErrorModelOptions error_model_from_preset(const ins::ImuErrorSpec& spec, double typical_rate_rps = 0.1);

// The linearisation point: nominal nav state and the compensated specific force and body rate there.
struct InsLinearisation {
  ins::NavState nav;
  Eigen::Vector3d f_b = Eigen::Vector3d::Zero();     // compensated specific force [m/s^2]
  Eigen::Vector3d w_ib_b = Eigen::Vector3d::Zero();  // compensated body rate [rad/s]
};

// What the covariance propagation needs from the compensated IMU steps since the last predict: their length,
// their velocity increment in NED (each step's dv rotated at its mid-attitude) and the latest body rate. The
// INS runs at the IMU rate; the filter predicts over several steps at once with the mean specific force.
struct ImuStepAccumulator {
  double dt_s = 0.0;
  Eigen::Vector3d dv_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_ib_b = Eigen::Vector3d::Zero();

  // One step from attitude q0 to q1 with compensated increments dth, dv over dt > 0.
  void add(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, const Eigen::Vector3d& dth,
           const Eigen::Vector3d& dv, double dt) {
    dt_s += dt;
    dv_n += q0.slerp(0.5, q1) * dv;
    w_ib_b = dth / dt;
  }
  // The linearisation point for predicting over the accumulated steps (dt_s > 0), ending at nav.
  InsLinearisation linearisation(const ins::NavState& nav) const {
    return {nav, nav.q_nb.conjugate() * (dv_n / dt_s), w_ib_b};
  }
  // After a predict: the body rate stays (measurement models use the latest one).
  void clear() {
    dt_s = 0.0;
    dv_n.setZero();
  }
  // The filter predicted with the model linearised over the accumulated steps ending at nav, then cleared (nothing
  // when no step has accumulated).
  template <class Filter, class Model>
  void predict(Filter& filter, Model& model, const ins::NavState& nav) {
    if (dt_s <= 0.0) return;
    model.set_linearisation(linearisation(nav));
    filter.predict(model, dt_s);
    clear();
  }
};

template <int N>
class InsErrorModel {
  static_assert(N == 15 || N == 17, "INS error model: 15 or 17 states");

 public:
  // Noise vector: accel white (3), gyro white (3), accel bias drive (3), gyro bias drive (3)[, clock bias,
  // clock drift].
  static constexpr int kNoiseSize = N == 15 ? 12 : 14;

  explicit InsErrorModel(const InsErrorModelOptions& options);

  void set_linearisation(const InsLinearisation& lin);
  const InsLinearisation& linearisation() const { return lin_; }

  // ProcessModel interface.
  StateVector<N> f(const StateVector<N>& x, double dt) const;
  // Phi(dt) of f (LinearProcessModel: the UKF propagates its covariance with it directly).
  const StateMatrix<N>& transition(double dt) const;
  StateMatrix<N> F(const StateVector<N>& /*x*/) const { return F_; }
  Eigen::Matrix<double, N, kNoiseSize> G(const StateVector<N>& /*x*/) const;
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const;

  // Initial covariance from the option's bias / clock sigmas and the given nav sigmas.
  StateMatrix<N> initial_covariance(const Eigen::Vector3d& sigma_pos_ned_m, const Eigen::Vector3d& sigma_vel_n_mps,
                                    const Eigen::Vector3d& sigma_att_rad) const;

  const InsErrorModelOptions& options() const { return opt_; }

 private:
  InsErrorModelOptions opt_;
  InsLinearisation lin_;
  StateMatrix<N> F_ = StateMatrix<N>::Zero();
  mutable double cached_dt_ = -1.0;  // Phi of the last dt, reused for all sigma points
  mutable StateMatrix<N> cached_phi_ = StateMatrix<N>::Identity();
};

// Continuous error dynamics F (N x N) at a linearisation point (what InsErrorModel::F returns).
template <int N>
StateMatrix<N> ins_error_dynamics(const InsLinearisation& lin, const InsErrorModelOptions& options);

extern template class InsErrorModel<15>;
extern template class InsErrorModel<17>;

}  // namespace ultratrack::fusion
