// SPDX-License-Identifier: GPL-3.0-or-later
// Generic filters: chi-square values, discretisation against closed forms, UKF == linear Kalman filter on a
// linear-Gaussian model, gating, and NEES consistency of both filters over a 100-run Monte Carlo on a
// nonlinear (range-bearing) model.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusion/discretisation.hpp"
#include "fusion/ekf.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ukf.hpp"
#include "receiver/chi_square.hpp"

namespace ultratrack::fusion {
namespace {

TEST(ChiSquare, MatchesTabulatedQuantiles) {
  // Published table values (e.g. NIST/SEMATECH e-Handbook, upper-tail critical values).
  EXPECT_NEAR(receiver::chi_square_lower_quantile(1, 0.95), 3.841459, 1e-6);
  EXPECT_NEAR(receiver::chi_square_lower_quantile(10, 0.95), 18.307038, 1e-6);
  EXPECT_NEAR(receiver::chi_square_lower_quantile(4, 0.99), 13.276704, 1e-6);
  EXPECT_NEAR(receiver::chi_square_cdf(2, 2.0), 1.0 - std::exp(-1.0), 1e-12);  // closed form for 2 dof
}

// Double integrator driven by white acceleration: Phi = [1 dt; 0 1], Qd = q [dt^3/3 dt^2/2; dt^2/2 dt].
TEST(Discretisation, VanLoanAndSeriesMatchDoubleIntegrator) {
  StateMatrix<2> F;
  F << 0, 1, 0, 0;
  StateMatrix<2> Qs = StateMatrix<2>::Zero();
  const double q = 0.3, dt = 0.7;
  Qs(1, 1) = q;
  StateMatrix<2> Phi, Qd;
  Phi << 1, dt, 0, 1;
  Qd << q * dt * dt * dt / 3, q * dt * dt / 2, q * dt * dt / 2, q * dt;
  for (auto m : {Discretisation::VanLoan, Discretisation::SecondOrderSeries}) {
    const DiscreteProcess<2> d = discretise<2>(F, Qs, dt, m);  // F^2 = 0: the series is exact here too
    EXPECT_LT((d.Phi - Phi).norm(), 1e-13);
    EXPECT_LT((d.Qd - Qd).norm(), 1e-13);
  }
}

// Scalar Gauss-Markov: Phi = exp(-dt/tau), Qd = q tau / 2 (1 - exp(-2 dt / tau)).
TEST(Discretisation, VanLoanMatchesGaussMarkovClosedForm) {
  StateMatrix<1> F, Qs;
  const double tau = 2.0, q = 0.5, dt = 3.0;  // dt > tau: the series would be poor, Van Loan exact
  F << -1.0 / tau;
  Qs << q;
  const DiscreteProcess<1> d = discretise<1>(F, Qs, dt, Discretisation::VanLoan);
  EXPECT_NEAR(d.Phi(0, 0), std::exp(-dt / tau), 1e-13);
  EXPECT_NEAR(d.Qd(0, 0), q * tau / 2.0 * (1.0 - std::exp(-2.0 * dt / tau)), 1e-13);
}

// --- linear-Gaussian model: 2-D constant velocity (x, y, vx, vy) -----------------------------------------
struct CvProcess {
  static constexpr int kNoiseSize = 2;
  double q = 0.04;
  StateVector<4> f(const StateVector<4>& x, double dt) const {
    StateVector<4> out = x;
    out.head<2>() += dt * x.tail<2>();
    return out;
  }
  StateMatrix<4> F(const StateVector<4>&) const {
    StateMatrix<4> F = StateMatrix<4>::Zero();
    F(0, 2) = F(1, 3) = 1.0;
    return F;
  }
  Eigen::Matrix<double, 4, 2> G(const StateVector<4>&) const {
    Eigen::Matrix<double, 4, 2> G = Eigen::Matrix<double, 4, 2>::Zero();
    G(2, 0) = G(3, 1) = 1.0;
    return G;
  }
  Eigen::Matrix2d Qc() const { return q * Eigen::Matrix2d::Identity(); }
};

// Linear measurement with k rows (varying per epoch): rows of a fixed matrix.
struct LinearMeasurement {
  Eigen::MatrixXd Hm;
  Eigen::VectorXd zm;
  Eigen::MatrixXd Rm;
  Eigen::VectorXd z() const { return zm; }
  Eigen::VectorXd h(const StateVector<4>& x) const { return Hm * x; }
  MeasurementJacobian<4> H(const StateVector<4>&) const { return Hm; }
  Eigen::MatrixXd R() const { return Rm; }
};

static_assert(ProcessModel<CvProcess, 4>);
static_assert(MeasurementModel<LinearMeasurement, 4>);

TEST(Ukf, EqualsLinearKalmanFilterOnLinearGaussianModel) {
  // Exact in exact arithmetic for any (alpha, beta, kappa) with n + lambda > 0: the centre sigma point has
  // zero deviation, the others are symmetric. alpha = 1, beta = 2, kappa = 0 keeps the weights O(1)
  // (Wm0 = 0, Wc0 = 2, Wi = 1/8), so rounding stays at 1e-15 relative.
  StateVector<4> x0(10.0, -5.0, 1.0, 0.5);
  StateMatrix<4> P0 = StateMatrix<4>::Identity() * 4.0;
  P0(0, 2) = P0(2, 0) = 1.0;
  UkfOptions uo;
  uo.sigma = {1.0, 2.0, 0.0};
  uo.gate.enabled = false;
  EkfOptions eo;
  eo.gate.enabled = false;
  Ukf<4> ukf(x0, P0, uo);
  Ekf<4> ekf(x0, P0, eo);
  // Reference: textbook Kalman filter written out here (standard form), Phi/Qd in closed form.
  StateVector<4> x = x0;
  StateMatrix<4> P = P0;
  CvProcess proc;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  for (int k = 0; k < 60; ++k) {
    const double dt = 0.1 + 0.05 * (k % 7);
    StateMatrix<4> Phi = StateMatrix<4>::Identity();
    Phi(0, 2) = Phi(1, 3) = dt;
    StateMatrix<4> Qd = StateMatrix<4>::Zero();
    for (int a = 0; a < 2; ++a) {
      Qd(a, a) = proc.q * dt * dt * dt / 3;
      Qd(a, a + 2) = Qd(a + 2, a) = proc.q * dt * dt / 2;
      Qd(a + 2, a + 2) = proc.q * dt;
    }
    x = Phi * x;
    P = Phi * P * Phi.transpose() + Qd;
    ukf.predict(proc, dt);
    ekf.predict(proc, dt);
    // 1 to 3 rows, mixing position and velocity.
    const int rows = 1 + k % 3;
    LinearMeasurement m;
    m.Hm = Eigen::MatrixXd::Zero(rows, 4);
    for (int r = 0; r < rows; ++r) m.Hm(r, (r + k) % 4) = 1.0, m.Hm(r, (r + k + 1) % 4) = 0.3 * (r + 1);
    m.Rm = Eigen::MatrixXd::Identity(rows, rows) * (0.5 + 0.1 * rows);
    m.zm = m.Hm * x;
    for (int r = 0; r < rows; ++r) m.zm(r) += n01(rng);
    const Eigen::MatrixXd S = m.Hm * P * m.Hm.transpose() + m.Rm;
    const Eigen::MatrixXd K = P * m.Hm.transpose() * S.inverse();
    x = x + K * (m.zm - m.Hm * x);
    P = (StateMatrix<4>::Identity() - K * m.Hm) * P;
    ASSERT_TRUE(ukf.update(m).accepted);
    ASSERT_TRUE(ekf.update(m).accepted);
    EXPECT_LT((ukf.x() - x).cwiseAbs().maxCoeff(), 1e-9) << "step " << k;
    EXPECT_LT((ukf.P() - P).cwiseAbs().maxCoeff(), 1e-9) << "step " << k;
    EXPECT_LT((ekf.x() - x).cwiseAbs().maxCoeff(), 1e-9) << "step " << k;
    EXPECT_LT((ekf.P() - P).cwiseAbs().maxCoeff(), 1e-9) << "step " << k;
  }
}

// The INS error model is linear (f = Phi x): the UKF propagates it as Phi P Phi' + Qd without sigma points. The
// same model with its transition hidden goes through the 35 sigma points; both must agree to rounding, with a
// full, strongly scaled covariance (clock bias 1e4 m beside attitude 1e-3 rad) and a nonzero mean.
struct SigmaPointsOnly {
  static constexpr int kNoiseSize = InsErrorModel<17>::kNoiseSize;
  const InsErrorModel<17>* m;
  StateVector<17> f(const StateVector<17>& x, double dt) const { return m->f(x, dt); }
  StateMatrix<17> F(const StateVector<17>& x) const { return m->F(x); }
  Eigen::Matrix<double, 17, kNoiseSize> G(const StateVector<17>& x) const { return m->G(x); }
  Eigen::Matrix<double, kNoiseSize, kNoiseSize> Qc() const { return m->Qc(); }
};
static_assert(LinearProcessModel<InsErrorModel<17>, 17>);
static_assert(ProcessModel<SigmaPointsOnly, 17> && !LinearProcessModel<SigmaPointsOnly, 17>);

TEST(Ukf, LinearModelShortcutEqualsSigmaPointPropagation) {
  InsErrorModelOptions o;
  o.accel.bias_sigma = 1e-2;
  o.accel.white_noise_psd = 1e-6;
  o.gyro.bias_sigma = 1e-5;
  o.gyro.white_noise_psd = 1e-9;
  InsErrorModel<17> model(o);
  InsLinearisation lin;
  lin.nav.lat_rad = 0.62;
  lin.nav.lon_rad = 2.39;
  lin.nav.height_m = 1000.0;
  lin.nav.v_n = Eigen::Vector3d(120.0, -70.0, 1.0);
  lin.nav.q_nb = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.1, 0.2, 1.0).normalized()));
  lin.f_b = Eigen::Vector3d(3.0, 9.0, -9.6);  // turning: a large horizontal specific force
  lin.w_ib_b = Eigen::Vector3d(0.01, -0.02, 0.3);
  model.set_linearisation(lin);
  const SigmaPointsOnly sigma_only{&model};
  StateVector<17> scale;
  scale << 3, 3, 5, 0.1, 0.1, 0.2, 1e-3, 1e-3, 5e-3, 1e-2, 1e-2, 1e-2, 1e-5, 1e-5, 1e-5, 1e4, 100;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  StateMatrix<17> A;
  for (int i = 0; i < 17; ++i)
    for (int j = 0; j < 17; ++j) A(i, j) = n01(rng);
  const StateMatrix<17> C = (A * A.transpose() / 17.0 + 0.1 * StateMatrix<17>::Identity());  // correlated, SPD
  const StateMatrix<17> P0 = scale.asDiagonal() * C * scale.asDiagonal();
  StateVector<17> x0;
  for (int i = 0; i < 17; ++i) x0(i) = 0.5 * scale(i) * n01(rng);
  for (Discretisation d : {Discretisation::SecondOrderSeries, Discretisation::VanLoan}) {
    UkfOptions uo;
    uo.discretisation = d;
    Ukf<17> direct(x0, P0, uo), sigma(x0, P0, uo);
    for (int k = 0; k < 25; ++k) {
      const double dt = k % 2 ? 0.02 : 0.013;
      direct.predict(model, dt);
      sigma.predict(sigma_only, dt);
    }
    // Relative to each element's own scale: rounding of 35 weighted outer products is ~1e-14 of it.
    const StateVector<17> sd = sigma.P().diagonal().cwiseSqrt();
    const StateMatrix<17> rel = (direct.P() - sigma.P()).cwiseQuotient(sd * sd.transpose());
    EXPECT_LT(rel.cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_LT((direct.x() - sigma.x()).cwiseQuotient(sd).cwiseAbs().maxCoeff(), 1e-11);
    EXPECT_GT((direct.P() - P0).cwiseQuotient(sd * sd.transpose()).cwiseAbs().maxCoeff(), 1e-3);  // it moved
    EXPECT_EQ(direct.counters().predictions, 25);
  }
}

TEST(Filters, GateRejectsOutlierAndCountsIt) {
  const StateVector<4> x0 = StateVector<4>::Zero();
  const StateMatrix<4> P0 = StateMatrix<4>::Identity();
  LinearMeasurement m;
  m.Hm = Eigen::MatrixXd::Zero(1, 4);
  m.Hm(0, 0) = 1.0;
  m.Rm = Eigen::MatrixXd::Identity(1, 1);
  m.zm = Eigen::VectorXd::Constant(1, 10.0);  // NIS = 100 / 2 = 50 > chi2(0.9999, 1) = 15.1
  Ekf<4> ekf(x0, P0);
  Ukf<4> ukf(x0, P0);
  const UpdateResult re = ekf.update(m), ru = ukf.update(m);
  EXPECT_FALSE(re.accepted);
  EXPECT_FALSE(ru.accepted);
  EXPECT_NEAR(re.nis, 50.0, 1e-12);
  EXPECT_NEAR(ru.nis, 50.0, 1e-9);
  EXPECT_EQ(ekf.counters().rejected, 1);
  EXPECT_EQ(ukf.counters().rejected, 1);
  EXPECT_EQ(ekf.x(), x0);
  m.zm(0) = 3.0;  // NIS 4.5: passes
  EXPECT_TRUE(ekf.update(m).accepted);
  EXPECT_TRUE(ukf.update(m).accepted);
  EXPECT_EQ(ekf.counters().accepted, 1);
}

// --- nonlinear model: constant velocity observed by range and bearing from a station at the origin ---------
struct RangeBearing {
  Eigen::Vector2d zm;
  double sr = 2.0, sb = 0.01;
  Eigen::VectorXd z() const { return zm; }
  static Eigen::VectorXd eval(const StateVector<4>& x) {
    Eigen::VectorXd out(2);
    out << std::hypot(x(0), x(1)), std::atan2(x(1), x(0));
    return out;
  }
  Eigen::VectorXd h(const StateVector<4>& x) const { return eval(x); }
  MeasurementJacobian<4> H(const StateVector<4>& x) const {
    const double r2 = x(0) * x(0) + x(1) * x(1), r = std::sqrt(r2);
    MeasurementJacobian<4> H = MeasurementJacobian<4>::Zero(2, 4);
    H(0, 0) = x(0) / r;
    H(0, 1) = x(1) / r;
    H(1, 0) = -x(1) / r2;
    H(1, 1) = x(0) / r2;
    return H;
  }
  Eigen::MatrixXd R() const { return Eigen::Vector2d(sr * sr, sb * sb).asDiagonal(); }
};

template <class Filter>
std::vector<double> nees_monte_carlo(int runs, int steps, typename Filter::Matrix P0, auto make_options) {
  std::vector<double> mean(steps, 0.0);
  CvProcess proc;
  proc.q = 0.01;
  const double dt = 1.0;
  // Exact discrete noise of the truth, same as the filters' model.
  const DiscreteProcess<4> d =
      discretise<4>(proc.F({}), proc.G({}) * proc.Qc() * proc.G({}).transpose(), dt, Discretisation::VanLoan);
  const Eigen::Matrix4d Lq = d.Qd.llt().matrixL();
  const Eigen::Matrix4d L0 = P0.llt().matrixL();
  for (int run = 0; run < runs; ++run) {
    std::mt19937_64 rng(1000 + run);
    std::normal_distribution<double> n01;
    auto g4 = [&] { return StateVector<4>(n01(rng), n01(rng), n01(rng), n01(rng)); };
    StateVector<4> truth(300.0, 100.0, -3.0, 4.0);
    Filter f(truth + L0 * g4(), P0, make_options());
    for (int k = 0; k < steps; ++k) {
      truth = proc.f(truth, dt) + Lq * g4();
      f.predict(proc, dt);
      RangeBearing m;
      m.zm = RangeBearing::eval(truth) + Eigen::Vector2d(m.sr * n01(rng), m.sb * n01(rng));
      f.update(m);
      const StateVector<4> e = f.x() - truth;
      mean[k] += e.dot(f.P().ldlt().solve(e)) / runs;
    }
  }
  return mean;
}

TEST(Filters, NeesOfBothFiltersInChiSquareBandOnNonlinearModel) {
  const int runs = 100, steps = 40, n = 4;
  // Run-averaged NEES: runs * mean ~ chi2(runs * n). 95 % two-sided band.
  const double lo = receiver::chi_square_lower_quantile(runs * n, 0.025) / runs,
               hi = receiver::chi_square_lower_quantile(runs * n, 0.975) / runs;
  StateMatrix<4> P0 = Eigen::Vector4d(25.0, 25.0, 1.0, 1.0).asDiagonal();
  auto ekf_mean = nees_monte_carlo<Ekf<4>>(runs, steps, P0, [] {
    EkfOptions o;
    o.gate.enabled = false;
    return o;
  });
  auto ukf_mean = nees_monte_carlo<Ukf<4>>(runs, steps, P0, [] {
    UkfOptions o;
    o.gate.enabled = false;
    o.sigma = {0.5, 2.0, 0.0};
    return o;
  });
  int ekf_out = 0, ukf_out = 0;
  double ekf_avg = 0, ukf_avg = 0;
  for (int k = 0; k < steps; ++k) {
    ekf_out += (ekf_mean[k] < lo || ekf_mean[k] > hi);
    ukf_out += (ukf_mean[k] < lo || ukf_mean[k] > hi);
    ekf_avg += ekf_mean[k] / steps;
    ukf_avg += ukf_mean[k] / steps;
  }
  std::printf("NEES band [%.3f, %.3f]; EKF mean %.3f, %d/%d steps outside; UKF mean %.3f, %d/%d outside\n", lo, hi,
              ekf_avg, ekf_out, steps, ukf_avg, ukf_out, steps);
  // 5 % of the steps are expected outside; P(more than 6 of 40 | p = 0.05) < 1.2 % (binomial).
  EXPECT_LE(ekf_out, 6);
  EXPECT_LE(ukf_out, 6);
  EXPECT_GT(ekf_avg, lo);
  EXPECT_LT(ekf_avg, hi);
  EXPECT_GT(ukf_avg, lo);
  EXPECT_LT(ukf_avg, hi);
}

TEST(Ukf, CovarianceStaysSymmetricPsdWithSmallAlpha) {
  // alpha = 1e-3 gives Wc0 ~ -1e6: the update must still leave P symmetric and PSD.
  StateMatrix<4> P0 = Eigen::Vector4d(25.0, 25.0, 1.0, 1.0).asDiagonal();
  UkfOptions o;
  o.sigma = {1e-3, 2.0, 0.0};
  o.gate.enabled = false;
  Ukf<4> f(StateVector<4>(300, 100, -3, 4), P0, o);
  CvProcess proc;
  for (int k = 0; k < 30; ++k) {
    f.predict(proc, 1.0);
    RangeBearing m;
    m.zm = RangeBearing::eval(StateVector<4>(300 - 3 * k, 100 + 4 * k, -3, 4));
    f.update(m);
    EXPECT_EQ(f.P(), f.P().transpose());
    Eigen::SelfAdjointEigenSolver<StateMatrix<4>> es(f.P());
    EXPECT_GE(es.eigenvalues().minCoeff(), -1e-9 * es.eigenvalues().maxCoeff());
  }
}

}  // namespace
}  // namespace ultratrack::fusion
