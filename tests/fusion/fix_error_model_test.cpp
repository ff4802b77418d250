// SPDX-License-Identifier: GPL-3.0-or-later
// Gauss-Markov fix-error states (fusion/fix_error_model.hpp): the discretisation of the augmented model against the
// closed form (Phi = exp(-dt / tau), Qd = sigma^2 (1 - exp(-2 dt / tau))), the measurement's Jacobian against a
// numerical derivative, and the loose filter on fixes with 30 s Gauss-Markov errors: honest (>= 90 % of epochs
// inside 3 sigma) with the states, not without them.
#include "fusion/fix_error_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "fusion/discretisation.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/loose_measurements.hpp"
#include "fusion_sim.hpp"
#include "ins/imu_error_model.hpp"

namespace ultratrack::fusion {
namespace {

using Augmented = FixErrorAugmentedModel<InsErrorModel<15>, 15>;

Augmented make_model(const FixErrorOptions& o, Discretisation method) {
  InsErrorModelOptions mo = error_model_from_preset(ins::imu_preset("hg1700ae"));
  mo.discretisation = method;
  return Augmented(InsErrorModel<15>(mo), o, method);
}

TEST(FixErrorModel, DiscretisationMatchesTheClosedForm) {
  FixErrorOptions o;
  o.correlation_time_s = 30.0;
  o.sigma_ned_m = {1.0, 1.5, 2.0};
  for (const Discretisation method : {Discretisation::VanLoan, Discretisation::SecondOrderSeries}) {
    const Augmented m = make_model(o, method);
    for (const double dt : {0.05, 1.0, 5.0}) {
      const StateVector<18> x0 = StateVector<18>::Zero();
      const StateMatrix<18> Qs = m.G(x0) * m.Qc() * m.G(x0).transpose();
      const DiscreteProcess<18> d = discretise<18>(m.F(x0), Qs, dt, method);
      const double a = dt / o.correlation_time_s;
      // Van Loan is exact; the second-order series errs by a^3 / 6 in Phi and by 2 a^3 sigma^2 / 3 in Qd (its
      // Qd = 2 a sigma^2 (1 - a + a^2 / 3) against 2 a - 2 a^2 + 4 a^3 / 3 - ... of the closed form).
      const double tol_phi = method == Discretisation::VanLoan ? 1e-12 : 0.2 * a * a * a;
      const double tol = method == Discretisation::VanLoan ? 1e-12 : 0.7 * a * a * a;
      for (int i = 0; i < 3; ++i) {
        const double s2 = o.sigma_ned_m(i) * o.sigma_ned_m(i);
        EXPECT_NEAR(d.Phi(15 + i, 15 + i), std::exp(-a), tol_phi) << dt;
        EXPECT_NEAR(d.Qd(15 + i, 15 + i), s2 * (1.0 - std::exp(-2.0 * a)), tol * s2) << dt;
        // The model's own transition is the filter's Phi, and the nominal follows the process mean exactly.
        EXPECT_NEAR(m.transition(dt)(15 + i, 15 + i), d.Phi(15 + i, 15 + i), 1e-15) << dt;
        for (int j = 0; j < 15; ++j) {
          EXPECT_EQ(d.Phi(15 + i, j), 0.0);
          EXPECT_EQ(d.Qd(15 + i, j), 0.0);
        }
      }
      EXPECT_NEAR(propagate_fix_error(Eigen::Vector3d::Ones(), dt, o.correlation_time_s).x(), std::exp(-a), 1e-15);
    }
  }
}

TEST(FixErrorModel, StationaryVarianceIsKeptOverManySteps) {
  // Starting at sigma^2, Phi P Phi' + Qd stays at sigma^2 (the stationary variance of the closed form).
  FixErrorOptions o;
  o.correlation_time_s = 30.0;
  o.sigma_ned_m = {1.0, 1.0, 2.0};
  const Augmented m = make_model(o, Discretisation::VanLoan);
  const StateVector<18> x0 = StateVector<18>::Zero();
  const StateMatrix<18> Qs = m.G(x0) * m.Qc() * m.G(x0).transpose();
  const DiscreteProcess<18> d = discretise<18>(m.F(x0), Qs, 0.2, Discretisation::VanLoan);
  Eigen::Matrix3d P = o.sigma_ned_m.cwiseAbs2().asDiagonal();
  for (int k = 0; k < 3000; ++k)
    P = d.Phi.bottomRightCorner<3, 3>() * P * d.Phi.bottomRightCorner<3, 3>().transpose() +
        d.Qd.bottomRightCorner<3, 3>();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(P(i, i), o.sigma_ned_m(i) * o.sigma_ned_m(i), 1e-9);
}

TEST(FixErrorModel, WhitePartIsTheRemainderWithAFloor) {
  FixErrorOptions o;
  o.sigma_ned_m = {1.0, 1.0, 2.0};
  o.min_white_fraction = 0.1;
  const Eigen::Vector3d w = fix_white_sigma(Eigen::Vector3d(2.0, 1.0, 1.0), o);
  EXPECT_NEAR(w.x(), std::sqrt(3.0), 1e-12);  // sqrt(4 - 1)
  EXPECT_NEAR(w.y(), 0.1, 1e-12);             // nothing left: the floor
  EXPECT_NEAR(w.z(), 0.1, 1e-12);
}

TEST(FixErrorModel, MeasurementJacobianMatchesNumericalDerivative) {
  NominalState nominal;
  nominal.nav.lat_rad = 0.8;
  nominal.nav.lon_rad = 0.15;
  nominal.nav.height_m = 400.0;
  nominal.nav.v_n = {10.0, -3.0, 0.2};
  nominal.nav.q_nb = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  GnssFix fix;
  fix.lat_rad = 0.8 + 1e-6;
  fix.lon_rad = 0.15 - 2e-6;
  fix.height_m = 401.0;
  fix.has_velocity = true;
  const Eigen::Vector3d lever(0.5, 0.2, -1.0), w(0.01, -0.02, 0.1), b(0.3, -0.4, 0.5);
  using Padded = PaddedMeasurement<LooseMeasurement<15>, 15, 18>;
  const FixErrorMeasurement<Padded, 18, 15> m(Padded(LooseMeasurement<15>(nominal, fix, lever, w)), true, b);
  // z: the fix with the nominal fix error taken out.
  const LooseMeasurement<15> plain(nominal, fix, lever, w);
  EXPECT_NEAR((plain.z().head<3>() - m.z().head<3>() - b).norm(), 0.0, 1e-9);
  // At the nominal, central differences of 1e-3 per state (ECEF metres keep smaller steps from resolving); the
  // loose rows' analytic H leaves out terms of relative size |lever| / R_earth (error_model_test.cpp).
  const StateVector<18> x = StateVector<18>::Zero();
  const MeasurementJacobian<18> H = m.H(x);
  for (int j = 0; j < 18; ++j) {
    const double h = 1e-3;
    StateVector<18> xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    const Eigen::VectorXd num = (m.h(xp) - m.h(xm)) / (2.0 * h);
    EXPECT_LT((num - H.col(j)).cwiseAbs().maxCoeff(), 1e-4) << "column " << j;
  }
  EXPECT_TRUE(H.block(0, 15, 3, 3) == -Eigen::Matrix3d::Identity());  // position rows: minus the fix-error state
  EXPECT_TRUE(H.block(3, 15, 3, 3) == Eigen::Matrix3d::Zero());       // velocity rows: no fix error
}

// Share of GNSS epochs (after the first 60 s) with every position axis inside 3 sigma, and the horizontal RMS.
struct Consistency {
  double inside = 0.0, horizontal_rms_m = 0.0;
};
Consistency consistency(const test::RunResult& r) {
  int n = 0, in = 0;
  double h2 = 0.0;
  for (std::size_t k = 0; k < r.t_s.size(); ++k) {
    if (r.t_s[k] < 60.0) continue;
    ++n;
    const Eigen::Vector3d e = r.pos_err_m[k];
    h2 += e.head<2>().squaredNorm();
    if ((e.cwiseAbs().array() <= 3.0 * r.sigma_pos_m[k].array()).all()) ++in;
  }
  return {static_cast<double>(in) / n, std::sqrt(h2 / n)};
}

TEST(FixErrorModel, LooseFilterIsHonestOnGaussMarkovFixes) {
  // 200 s land run, HG1700AE, position-only fixes at 5 Hz with 1 m / 30 s Gauss-Markov errors: taken as white, the
  // filter averages them down and claims centimetres; with the fix-error states >= 90 % of epochs inside 3 sigma, at
  // a horizontal RMS no worse than the white-told run's by more than 25 %.
  for (const FilterKind filter : {FilterKind::Ekf, FilterKind::Ukf}) {
    test::SimConfig cfg;
    cfg.duration_s = 200.0;
    cfg.gnss_period_s = 0.2;
    cfg.velocity = false;
    cfg.sigma_pos_ned_m = {1.0, 1.0, 1.0};
    cfg.fix_error_correlation_s = 30.0;
    cfg.seed = 3;
    const Consistency white = consistency(test::run_simulation(cfg, Coupling::kLoose, filter));
    cfg.fix_error.enabled = true;
    cfg.fix_error.correlation_time_s = 30.0;
    cfg.fix_error.sigma_ned_m = cfg.sigma_pos_ned_m;
    const Consistency gm = consistency(test::run_simulation(cfg, Coupling::kLoose, filter));
    std::printf("%s: told white %.3f inside, %.3f m; fix-error states %.3f inside, %.3f m\n",
                filter == FilterKind::Ekf ? "EKF" : "UKF", white.inside, white.horizontal_rms_m, gm.inside,
                gm.horizontal_rms_m);
    EXPECT_LT(white.inside, 0.6);
    EXPECT_GE(gm.inside, 0.9);
    EXPECT_LE(gm.horizontal_rms_m, 1.25 * white.horizontal_rms_m);
  }
}

}  // namespace
}  // namespace ultratrack::fusion
