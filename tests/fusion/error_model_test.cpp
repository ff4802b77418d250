// SPDX-License-Identifier: GPL-3.0-or-later
// INS error-state model and measurement Jacobians against numerical differentiation of the full nonlinear
// functions: the strapdown mechanisation (ins::Strapdown) for F, the antenna position/velocity and the
// pseudorange/rate predictions for H, each around a nominal INS state that is not the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "fusion/discretisation.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion/loose_measurements.hpp"
#include "fusion/tight_measurements.hpp"
#include "fusion_sim.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/strapdown.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "io/units.hpp"
#include "signals/nominal_constellation.hpp"

namespace ultratrack::fusion {
namespace {

ins::NavState moving_state() {
  ins::NavState s;
  s.lat_rad = 50.0 * io::kRadPerDeg;
  s.lon_rad = 8.0 * io::kRadPerDeg;
  s.height_m = 1500.0;
  s.v_n = Eigen::Vector3d(120.0, -80.0, 5.0);
  s.q_nb = ins::quaternion_from_euler({10.0 * io::kRadPerDeg, -5.0 * io::kRadPerDeg, 130.0 * io::kRadPerDeg});
  return s;
}

// One mechanisation step of a nominal with IMU biases (the nominal's bias fields hold the sensor's bias).
NominalState step(NominalState s, const Eigen::Vector3d& w_b, const Eigen::Vector3d& f_b, double dt) {
  ins::Strapdown sd(s.nav);
  sd.step((w_b + s.gyro_bias_b) * dt, (f_b + s.accel_bias_b) * dt, dt);
  s.nav = sd.state();
  s.clock_bias_m += s.clock_drift_mps * dt;
  return s;
}

// Phi over dt from the mechanisation: central differences of the propagated error for each error direction.
TEST(InsErrorModel, TransitionMatchesNumericalDifferentiationOfMechanisation) {
  const Eigen::Vector3d w_b(0.02, -0.01, 0.05), f_b(1.5, 0.8, -9.6);
  const double dt = 0.01;
  NominalState truth;
  truth.nav = moving_state();
  truth.clock_drift_mps = 3.0;
  const NominalState truth1 = step(truth, w_b, f_b, dt);
  const StateVector<17> eps =
      (StateVector<17>() << 1, 1, 1, 0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-6, 1e-6, 1e-6, 1.0, 0.1)
          .finished();
  StateMatrix<17> Phi_num;
  for (int j = 0; j < 17; ++j) {
    StateVector<17> col = StateVector<17>::Zero();
    for (int sgn : {1, -1}) {
      StateVector<17> e = StateVector<17>::Zero();
      e(j) = sgn * eps(j);
      NominalState est = corrected<17>(truth, StateVector<17>(-e));
      // Biases: the state is the residual in the compensated output; simulate it as a sensor bias.
      est.accel_bias_b = e.segment<3>(ix::kAccelBias);
      est.gyro_bias_b = e.segment<3>(ix::kGyroBias);
      const NominalState est1 = step(est, w_b, f_b, dt);
      NominalState t1 = truth1;
      t1.accel_bias_b = est1.accel_bias_b;  // the residual bias itself is constant over dt
      t1.gyro_bias_b = est1.gyro_bias_b;
      StateVector<17> err = error_state<17>(est1, t1);
      err.segment<6>(ix::kAccelBias) = e.segment<6>(ix::kAccelBias);
      col += sgn * err / (2.0 * eps(j));
    }
    Phi_num.col(j) = col;
  }
  InsErrorModelOptions opt;
  InsLinearisation lin;
  lin.nav = truth.nav;
  lin.f_b = f_b;
  lin.w_ib_b = w_b;
  const StateMatrix<17> F = ins_error_dynamics<17>(lin, opt);
  const StateMatrix<17> Phi = discretise<17>(F, StateMatrix<17>::Zero(), dt, Discretisation::VanLoan).Phi;
  // Compare (Phi - I) / dt, i.e. F, column by column. The mechanisation moves the linearisation point over
  // the step (|F dt| ~ 1e-3 relative): tolerance 2 % of the column's largest entry plus rounding.
  const StateMatrix<17> F_num = (Phi_num - StateMatrix<17>::Identity()) / dt;
  const StateMatrix<17> F_mod = (Phi - StateMatrix<17>::Identity()) / dt;
  for (int j = 0; j < 17; ++j) {
    const double scale = F_mod.col(j).cwiseAbs().maxCoeff();
    for (int i = 0; i < 17; ++i) {
      EXPECT_NEAR(F_num(i, j), F_mod(i, j), 0.02 * scale + 2e-6) << "F(" << i << ", " << j << ")";
    }
  }
  // The sensitive couplings are really there (not a trivially passing zero model).
  EXPECT_GT(std::abs(F(ix::kVel + 0, ix::kAtt + 1)), 9.0);   // f_D x psi
  EXPECT_GT(std::abs(F(ix::kPos + 0, ix::kPos + 2)), 1e-5);  // v_N / R coupling of height into north
}

template <int N, class M>
MeasurementJacobian<N> numerical_jacobian(const M& m, const StateVector<N>& steps) {
  MeasurementJacobian<N> J(m.z().size(), N);
  for (int j = 0; j < N; ++j) {
    StateVector<N> d = StateVector<N>::Zero();
    d(j) = steps(j);
    J.col(j) = (m.h(d) - m.h(StateVector<N>(-d))) / (2.0 * steps(j));
  }
  return J;
}

StateVector<17> jacobian_steps() {
  return (StateVector<17>() << 0.1, 0.1, 0.1, 0.01, 0.01, 0.01, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5, 1e-5,
          0.1, 0.01)
      .finished();
}

// The nominal is the truth with errors: Jacobians are taken about an INS state that is not the truth.
NominalState perturbed_nominal() {
  NominalState truth;
  truth.nav = moving_state();
  StateVector<17> e;
  e << 4, -3, 2, 0.3, -0.2, 0.1, 2e-3, -1e-3, 5e-3, 0, 0, 0, 0, 0, 0, 10, 0.5;
  NominalState n = corrected<17>(truth, StateVector<17>(-e));
  n.accel_bias_b = Eigen::Vector3d(1e-3, -2e-3, 5e-4);
  n.gyro_bias_b = Eigen::Vector3d(1e-5, 2e-5, -1e-5);
  n.clock_bias_m = 1200.0;
  n.clock_drift_mps = 15.0;
  return n;
}

TEST(LooseMeasurement, JacobianMatchesNumericalDifferentiation) {
  const NominalState nom = perturbed_nominal();
  GnssFix fix;
  fix.lat_rad = nom.nav.lat_rad + 1e-6;
  fix.lon_rad = nom.nav.lon_rad;
  fix.height_m = nom.nav.height_m + 3.0;
  fix.has_velocity = true;
  fix.v_n_mps = nom.nav.v_n;
  const Eigen::Vector3d lever(1.5, -0.4, -2.0), w(0.2, -0.1, 0.3);
  const LooseMeasurement<15> m(nom, fix, lever, w);
  const MeasurementJacobian<15> Jn = numerical_jacobian<15>(m, StateVector<15>(jacobian_steps().head<15>()));
  const MeasurementJacobian<15> H = m.H(StateVector<15>::Zero());
  // Analytic H leaves out terms of relative size |lever| / R_earth and |v| / R_earth (< 3e-5 per unit state).
  EXPECT_LT((H - Jn).cwiseAbs().maxCoeff(), 1e-4) << "H\n" << H << "\nnumerical\n" << Jn;
  EXPECT_GT(H.block(0, ix::kAtt, 3, 3).norm(), 1.0);  // lever-arm attitude coupling present
  EXPECT_GT(H.block(3, ix::kGyroBias, 3, 3).norm(), 1.0);
  // Noise-free fix at the truth: the innovation is what the nominal's error makes it.
  EXPECT_EQ(m.size(), 6);
}

TEST(TightMeasurement, JacobianMatchesNumericalDifferentiation) {
  const NominalState nom = perturbed_nominal();
  const signals::GpsTime t0{2300, 300000.0};
  const auto constellation = signals::nominal_constellation(t0);
  // Build a trajectory at the nominal's place for the simulated epoch (truth motion is irrelevant to H).
  const ins::TrajectorySpec spec = ins::profile_spec("straight", 5.0, nom.nav.lat_rad, nom.nav.lon_rad, 1500.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  const ins::TruthInterpolator interp(run.truth);
  const Eigen::Vector3d lever(1.5, -0.4, -2.0), w(0.2, -0.1, 0.3);
  const auto se =
      test::simulate_epoch(interp, lever, constellation.ephemerides, constellation.klobuchar, t0, 1.0, {1200.0, 15.0});
  TightOptions to;
  const auto sats = prepare_satellites(se.epoch, constellation.ephemerides, constellation.klobuchar,
                                       antenna_position_e(nom.nav, lever), to);
  ASSERT_GE(sats.size(), 5u);
  const EpochMeasurement17 m(nom, sats, lever, w, true);
  // Pseudoranges are ~2e7 m (rounding 4e-9 m): attitude steps of 1e-3 rad keep the difference noise at 2e-6.
  StateVector<17> steps = jacobian_steps();
  steps.segment<3>(ix::kAtt).setConstant(1e-3);
  steps.segment<3>(ix::kPos).setConstant(1.0);
  const MeasurementJacobian<17> Jn = numerical_jacobian<17>(m, steps);
  const MeasurementJacobian<17> H = m.H(StateVector<17>::Zero());
  // Left out: earth-frame rotation of the velocity with position (|v| / R ~ 2.3e-5 per metre here).
  EXPECT_LT((H - Jn).cwiseAbs().maxCoeff(), 1e-4) << "H\n" << H << "\nnumerical\n" << Jn;
  EXPECT_EQ(m.size(), 2 * static_cast<int>(sats.size()));
  for (const auto& s : sats) {
    const SatelliteMeasurement17 one(nom, s, lever, w, true);
    EXPECT_LT((one.H(StateVector<17>::Zero()) - numerical_jacobian<17>(one, steps)).cwiseAbs().maxCoeff(), 1e-4);
  }
}

// SatelliteMeasurement17::h computes the corrected nominal's ECEF position, C_en and the earth/transport rates
// from one sine/cosine pair of latitude and longitude (it runs at every UKF sigma point); the reference here is
// the composition it replaces: fusion::corrected, then antenna_position_e / antenna_velocity_n (GeographicLib's
// conversion) and the prediction functions. Error states of sigma-point size and far beyond (km, 0.1 rad,
// 100 m/s), with and without a lever arm (without one the attitude correction is skipped, not computed).
TEST(TightMeasurement, SigmaPointFormEqualsCorrectedNominalComposition) {
  const NominalState nom = perturbed_nominal();
  const signals::GpsTime t0{2300, 300000.0};
  const auto constellation = signals::nominal_constellation(t0);
  const ins::TrajectorySpec spec = ins::profile_spec("straight", 5.0, nom.nav.lat_rad, nom.nav.lon_rad, 1500.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  const ins::TruthInterpolator interp(run.truth);
  const Eigen::Vector3d w(0.2, -0.1, 0.3);
  std::srand(5);
  for (const Eigen::Vector3d& lever : {Eigen::Vector3d(1.5, -0.4, -2.0), Eigen::Vector3d(Eigen::Vector3d::Zero())}) {
    const auto se = test::simulate_epoch(interp, lever, constellation.ephemerides, constellation.klobuchar, t0, 1.0,
                                         {1200.0, 15.0});
    const auto sats = prepare_satellites(se.epoch, constellation.ephemerides, constellation.klobuchar,
                                         antenna_position_e(nom.nav, lever), TightOptions{});
    ASSERT_GE(sats.size(), 5u);
    for (const auto& sat : sats) {
      const SatelliteMeasurement17 m(nom, sat, lever, w, true);
      for (const double scale : {1e-3, 1.0, 100.0}) {
        for (int trial = 0; trial < 20; ++trial) {
          StateVector<17> dx = StateVector<17>::Random();
          dx.segment<3>(ix::kPos) *= 10.0 * scale;  // m
          dx.segment<3>(ix::kVel) *= 1.0 * scale;   // m/s
          dx.segment<3>(ix::kAtt) *= 1e-3 * scale;  // rad
          dx.segment<3>(ix::kAccelBias) *= 1e-2;
          dx.segment<3>(ix::kGyroBias) *= 1e-4 * scale;
          dx(ix::kClockBias) *= 30.0 * scale;
          dx(ix::kClockDrift) *= 3.0 * scale;
          const NominalState c = corrected<17>(nom, dx);
          const Eigen::Vector3d r = antenna_position_e(c.nav, lever);
          const Eigen::Vector3d v = ins::C_en(c.nav.lat_rad, c.nav.lon_rad) *
                                    antenna_velocity_n(c.nav, w - dx.segment<3>(ix::kGyroBias), lever);
          const Eigen::VectorXd h = m.h(dx);
          ASSERT_EQ(h.size(), 2);
          // Rounding: the ECEF position is ~6.4e6 m (one unit in the last place 1e-9 m) and the two conversions
          // round differently (GeographicLib works in degrees): a few ulps of the range; the rate's terms are
          // ~1e3 m/s (2e-13) times the same relative rounding of the line of sight.
          EXPECT_NEAR(h(0), predicted_pseudorange_m(sat, r, c.clock_bias_m), 2e-8) << "PRN " << sat.prn;
          EXPECT_NEAR(h(1), predicted_range_rate_mps(sat, r, v, c.clock_drift_mps), 1e-9) << "PRN " << sat.prn;
        }
      }
    }
  }
}

// The tight prediction at the true antenna state reproduces the independently simulated pseudoranges and
// rates (satellite orbit, SV clock, Sagnac, atmosphere consistent with the simulation and receiver/pvt).
TEST(TightMeasurement, PredictionAtTruthReproducesSimulatedObservables) {
  const signals::GpsTime t0{2300, 300000.0};
  const auto constellation = signals::nominal_constellation(t0);
  const ins::TrajectorySpec spec =
      ins::profile_spec("circle", 20.0, 37.0 * io::kRadPerDeg, 127.0 * io::kRadPerDeg, 300.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  const ins::TruthInterpolator interp(run.truth);
  const Eigen::Vector3d lever(0.5, 0.2, -1.0);
  const double t = 10.0;
  const test::TruthClock clock{-2500.0, 40.0};
  const auto se = test::simulate_epoch(interp, lever, constellation.ephemerides, constellation.klobuchar, t0, t, clock);
  const ins::EcefMotion ant = interp.antenna(t, lever);
  const auto sats = prepare_satellites(se.epoch, constellation.ephemerides, constellation.klobuchar, ant.r_e, {});
  ASSERT_GE(sats.size(), 5u);
  for (const auto& s : sats) {
    // 1 mm: ionosphere/troposphere evaluated at the same place; travel-time iteration converged.
    EXPECT_NEAR(predicted_pseudorange_m(s, ant.r_e, clock.bias_m), s.pseudorange_m, 1e-3) << "PRN " << s.prn;
  }
  // Rates without atmosphere: the delay rates (up to ~2 mm/s at low elevation) are not modelled, as in pvt.
  const auto se_vac = test::simulate_epoch(interp, lever, constellation.ephemerides, {}, t0, t, clock, false);
  TightOptions vacuum;
  vacuum.troposphere = false;
  const auto sats_vac = prepare_satellites(se_vac.epoch, constellation.ephemerides, {}, ant.r_e, vacuum);
  ASSERT_EQ(sats_vac.size(), sats.size());
  for (const auto& s : sats_vac) {
    // 0.5 mm/s: the simulation's rate is a 0.1 s central difference of the pseudorange (the receiver's own
    // velocity term of the travel-time rate, 2 mm/s at 139 m/s, is modelled).
    EXPECT_NEAR(predicted_range_rate_mps(s, ant.r_e, ant.v_e, clock.drift_mps), s.range_rate_mps, 5e-4)
        << "PRN " << s.prn;
  }
}

TEST(InsErrorModel, PresetNoiseSettings) {
  const auto o = error_model_from_preset(ins::imu_preset("hg1700ae"));
  EXPECT_EQ(o.gyro.bias_model, BiasModel::RandomConstant);
  EXPECT_NEAR(o.gyro.bias_sigma, 1.0 * io::kRadPerDeg / 3600.0, 1e-12);
  EXPECT_NEAR(o.accel.bias_sigma, 1e-3 * 9.80665, 1e-9);
  const auto m = error_model_from_preset(ins::imu_preset("mems"));
  EXPECT_GT(m.gyro.bias_random_walk_psd, 0.0);  // turn-on + instability
  ins::ImuErrorSpec gm_only;
  gm_only.gyro.bias_instability_sigma = 1e-4;
  gm_only.gyro.bias_correlation_time_s = 200.0;
  const auto g = error_model_from_preset(gm_only);
  EXPECT_EQ(g.gyro.bias_model, BiasModel::GaussMarkov);
  InsErrorModel<15> model(g);
  EXPECT_NEAR(model.F(StateVector<15>::Zero())(ix::kGyroBias, ix::kGyroBias), -1.0 / 200.0, 1e-15);
  EXPECT_NEAR(model.Qc()(9, 9), 2.0 * 1e-8 / 200.0, 1e-20);
}

}  // namespace
}  // namespace ultratrack::fusion
