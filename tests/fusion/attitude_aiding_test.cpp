// SPDX-License-Identifier: GPL-3.0-or-later
// GPS attitude aiding ([OhAttINS]; [KimAlign] eqs. 10-17): the measurement model against numerical
// differentiation and [KimAlign]'s published H_G, the innovation across yaw +-180 deg, and closed-loop runs on the
// trajectory simulator's truth with GPS attitudes simulated from it (truth + Gaussian Euler-angle noise):
// a parked MEMS IMU whose heading position/velocity cannot observe, with and without GPS attitude; a moving
// run with dropouts (20 % of epochs unfixed, a 10 s gap) that stays consistent and counts its fallbacks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "fusion/attitude_measurement.hpp"
#include "fusion/gnss_ins_integration.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_error_state.hpp"
#include "fusion_sim.hpp"
#include "ins/attitude.hpp"
#include "ins/earth_model.hpp"
#include "ins/imu_error_model.hpp"
#include "ins/nav_correction.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"

namespace ultratrack::fusion {
namespace {

Eigen::Matrix3d dcm(const ins::EulerAngles& e) { return ins::quaternion_from_euler(e).toRotationMatrix(); }

// Rotation vector of Ca Cb^T from a DCM pair (independent of ins/ quaternion helpers).
Eigen::Vector3d rotation_between(const Eigen::Matrix3d& Ca, const Eigen::Matrix3d& Cb) {
  const Eigen::AngleAxisd aa(Ca * Cb.transpose());
  return aa.angle() * aa.axis();
}

TEST(AttitudeMeasurement, EulerToRotationMapMatchesNumericalDifferentiation) {
  for (const ins::EulerAngles e :
       {ins::EulerAngles{20 * io::kRadPerDeg, -35 * io::kRadPerDeg, 150 * io::kRadPerDeg},
        ins::EulerAngles{-170 * io::kRadPerDeg, 70 * io::kRadPerDeg, -60 * io::kRadPerDeg}}) {
    const Eigen::Matrix3d M = euler_rate_to_rotation_n(e);
    const double h = 1e-6;
    for (int j = 0; j < 3; ++j) {
      ins::EulerAngles p = e, m = e;
      double* pp[] = {&p.roll_rad, &p.pitch_rad, &p.yaw_rad};
      double* mm[] = {&m.roll_rad, &m.pitch_rad, &m.yaw_rad};
      *pp[j] += h;
      *mm[j] -= h;
      const Eigen::Vector3d col = rotation_between(dcm(p), dcm(m)) / (2 * h);
      EXPECT_LT((col - M.col(j)).norm(), 1e-8) << "column " << j;
    }
  }
}

// Seed 000 eq. 16: Euler-angle errors of the INS from its psi-angle error, (droll, dpitch, dyaw) = H_G psi. Our
// psi convention (C_est = (I - [psi x]) C_true) is the seed's, so H_G must equal -M^-1, and must match the
// Euler errors of an attitude really rotated by -psi.
TEST(AttitudeMeasurement, RotationFormCarriesSeedZeroHg) {
  const double beta = 25 * io::kRadPerDeg, gamma = -120 * io::kRadPerDeg;  // pitch, yaw
  const ins::EulerAngles e{8 * io::kRadPerDeg, beta, gamma};
  Eigen::Matrix3d HG;
  HG << -std::cos(gamma) / std::cos(beta), -std::sin(gamma) / std::cos(beta), 0, std::sin(gamma), -std::cos(gamma), 0,
      -std::tan(beta) * std::cos(gamma), -std::tan(beta) * std::sin(gamma), -1;
  EXPECT_LT((HG + euler_rate_to_rotation_n(e).inverse()).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::Vector3d psi(2e-6, -3e-6, 1.5e-6);
  const ins::EulerAngles est = ins::euler_from_dcm((Eigen::Matrix3d::Identity() - ins::skew(psi)) * dcm(e));
  const Eigen::Vector3d de(est.roll_rad - e.roll_rad, est.pitch_rad - e.pitch_rad, est.yaw_rad - e.yaw_rad);
  EXPECT_LT((de - HG * psi).norm(), 1e-10);
}

// The nominal is the truth with a known attitude error e_psi (and position/velocity errors): a GPS attitude equal
// to the truth yields z = e_psi exactly, also across yaw +-180 deg and through a non-identity mounting.
TEST(AttitudeMeasurement, InnovationIsTheInsErrorAcrossYawWrap) {
  NominalState truth;
  truth.nav.lat_rad = 36 * io::kRadPerDeg;
  truth.nav.lon_rad = 127 * io::kRadPerDeg;
  truth.nav.q_nb = ins::quaternion_from_euler({3 * io::kRadPerDeg, -2 * io::kRadPerDeg, 179.95 * io::kRadPerDeg});
  StateVector<15> e = StateVector<15>::Zero();
  e << 4, -3, 2, 0.3, -0.2, 0.1, 1e-3, -2e-3, -0.2 * io::kRadPerDeg, 0, 0, 0, 0, 0, 0;
  const NominalState nom = corrected<15>(truth, StateVector<15>(-e));
  EXPECT_LT(ins::euler_from_quaternion(nom.nav.q_nb).yaw_rad,
            -179.8 * io::kRadPerDeg);  // INS yaw past 180, truth +179.95
  AttitudeAidingOptions o;
  o.q_ba = ins::quaternion_from_euler({1 * io::kRadPerDeg, -0.5 * io::kRadPerDeg, 2 * io::kRadPerDeg});
  GnssAttitude a;
  a.euler_a = ins::euler_from_quaternion(truth.nav.q_nb * o.q_ba);  // what the array frame reads
  a.sigma_euler_rad = Eigen::Vector3d(0.1, 0.1, 0.2) * io::kRadPerDeg;
  const AttitudeMeasurement<15> m(nom, a, o);
  EXPECT_LT((m.z() - e.segment<3>(ix::kAtt)).norm(), 1e-12) << m.z().transpose();
  // Predicted at the true error: zero innovation.
  EXPECT_LT((m.z() - m.h(e)).norm(), 1e-12);
  // Noise: a pure yaw sigma maps to the down axis only, a pure roll sigma to the body x axis in NED.
  const Eigen::Matrix3d R = m.R();
  const Eigen::Vector3d roll_axis = dcm(a.euler_a).col(0);
  const Eigen::Matrix3d Rexp =
      0.01 * io::kRadPerDeg * io::kRadPerDeg * (roll_axis * roll_axis.transpose()) +
      0.01 * io::kRadPerDeg * io::kRadPerDeg * euler_rate_to_rotation_n(a.euler_a).col(1) *
          euler_rate_to_rotation_n(a.euler_a).col(1).transpose() +
      0.04 * io::kRadPerDeg * io::kRadPerDeg * Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
  EXPECT_LT((R - Rexp).cwiseAbs().maxCoeff(), 1e-15);
}

template <int N, class M>
MeasurementJacobian<N> numerical_jacobian(const M& m, const StateVector<N>& at, double step) {
  MeasurementJacobian<N> J(3, N);
  for (int j = 0; j < N; ++j) {
    StateVector<N> d = StateVector<N>::Zero();
    d(j) = j >= ix::kAtt && j < ix::kAtt + 3 ? 1e-5 : step;
    J.col(j) = (m.h(StateVector<N>(at + d)) - m.h(StateVector<N>(at - d))) / (2.0 * d(j));
  }
  return J;
}

TEST(AttitudeMeasurement, JacobianMatchesNumericalDifferentiation) {
  NominalState nom;
  nom.nav.lat_rad = 50 * io::kRadPerDeg;
  nom.nav.lon_rad = 8 * io::kRadPerDeg;
  nom.nav.height_m = 1500;
  nom.nav.v_n = Eigen::Vector3d(120, -80, 5);
  nom.nav.q_nb = ins::quaternion_from_euler({10 * io::kRadPerDeg, -5 * io::kRadPerDeg, 130 * io::kRadPerDeg});
  nom.gyro_bias_b = Eigen::Vector3d(1e-5, 2e-5, -1e-5);
  GnssAttitude a;
  a.euler_a = {10.3 * io::kRadPerDeg, -5.2 * io::kRadPerDeg, 129.5 * io::kRadPerDeg};
  const AttitudeMeasurement<15> m15(nom, a, {});
  const AttitudeMeasurement<17> m17(nom, a, {});
  const MeasurementJacobian<15> J15 = numerical_jacobian<15>(m15, StateVector<15>::Zero(), 0.1);
  EXPECT_LT((m15.H(StateVector<15>::Zero()) - J15).cwiseAbs().maxCoeff(), 1e-8) << J15;
  const MeasurementJacobian<17> J17 = numerical_jacobian<17>(m17, StateVector<17>::Zero(), 0.1);
  EXPECT_LT((m17.H(StateVector<17>::Zero()) - J17).cwiseAbs().maxCoeff(), 1e-8) << J17;
  // Away from zero (the UKF's sigma points) the psi rows stay the identity to first order in |dx_psi|.
  StateVector<15> at = StateVector<15>::Zero();
  at.segment<3>(ix::kAtt) = Eigen::Vector3d(2e-3, -1e-3, 4e-3);
  const MeasurementJacobian<15> Ja = numerical_jacobian<15>(m15, at, 0.1);
  EXPECT_LT((m15.H(at) - Ja).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(AttitudeMeasurement, NearVerticalIsRefused) {
  GnssAttitude a;
  a.euler_a = {0.0, 85 * io::kRadPerDeg, 30 * io::kRadPerDeg};
  AttitudeAidingOptions o;
  EXPECT_FALSE(attitude_usable(a, o));
  EXPECT_THROW(AttitudeMeasurement<15>(NominalState{}, a, o), std::invalid_argument);
  o.max_abs_pitch_rad = 89 * io::kRadPerDeg;
  EXPECT_TRUE(attitude_usable(a, o));
  a.sigma_euler_rad.z() = 0.0;
  EXPECT_FALSE(attitude_usable(a, o));
}

// ---- closed loop on simulated truth ----

struct AttitudeSim {
  std::string profile = "static";
  double duration_s = 180.0;
  std::string preset = "mems";
  FilterKind filter = FilterKind::Ekf;
  std::uint64_t seed = 3;
  bool attitude = true;
  Eigen::Vector3d sigma_euler_rad = Eigen::Vector3d(0.1, 0.1, 0.2) * io::kRadPerDeg;
  double attitude_offset_s = 0.61;  // GPS attitude at 0.61 + k, fixes at 0.37 + k: unrelated times
  double drop_fraction = 0.0;       // attitudes with fixed = 0 (skipped)
  double gap_start_s = 1e9, gap_length_s = 0.0;
  Eigen::Quaterniond q_ba = Eigen::Quaterniond::Identity();
  Eigen::Vector3d att_error0_rad = Eigen::Vector3d(0.5, -0.5, 12.0) * io::kRadPerDeg;  // initial INS attitude error
  Eigen::Vector3d sigma0_att_rad = Eigen::Vector3d(1.0, 1.0, 20.0) * io::kRadPerDeg;
};

struct AttitudeRun {
  std::vector<double> t_s;
  std::vector<Eigen::Vector3d> att_err_rad, att_sigma_rad;  // after each fix epoch
  IntegrationCounters counters;
  long long attitudes_given = 0, attitudes_dropped = 0, expected_fallbacks = 0;
};

AttitudeRun run_attitude_sim(const AttitudeSim& c) {
  const ins::TrajectorySpec spec =
      ins::profile_spec(c.profile, c.duration_s, 36.4 * io::kRadPerDeg, 127.4 * io::kRadPerDeg, 80.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  const ins::TruthInterpolator interp(run.truth);
  const ins::ImuErrorSpec imu_spec = ins::imu_preset(c.preset);
  ins::ImuErrorModel imu(imu_spec, c.seed);
  std::mt19937_64 rng(c.seed * 31 + 7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto gauss3 = [&] { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)); };

  IntegrationOptions opt;
  opt.model = error_model_from_preset(imu_spec);
  opt.sigma_pos_ned_m = Eigen::Vector3d(2, 2, 3);
  opt.sigma_vel_n_mps = Eigen::Vector3d::Constant(0.2);
  opt.sigma_att_rad = c.sigma0_att_rad;
  opt.filter = c.filter;
  opt.attitude.q_ba = c.q_ba;
  StateVector<15> e0 = StateVector<15>::Zero();
  e0.segment<3>(ix::kPos) = Eigen::Vector3d(1.0, -1.5, 2.0);
  e0.segment<3>(ix::kVel) = Eigen::Vector3d(0.1, -0.1, 0.05);
  e0.segment<3>(ix::kAtt) = c.att_error0_rad;
  NominalState truth0;
  truth0.nav = run.truth[0].nav();
  GnssInsIntegration integ(corrected<15>(truth0, StateVector<15>(-e0)).nav, opt);

  AttitudeRun out;
  const Eigen::Vector3d sigma_pos(1.5, 1.5, 3.0);
  const double sigma_vel = 0.05;
  double next_fix = 0.37, next_att = c.attitude_offset_s;
  bool attitude_since_fix = false;
  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) {
    const double t_end = run.truth[k + 1].t_s;
    bool fix_here = false;
    // Queue in time order (attitude first at equal times, as the integration does).
    while (std::min(next_fix, next_att) <= t_end) {
      if (next_att <= next_fix) {
        const double t = next_att;
        next_att += 1.0;
        if (!c.attitude) continue;
        const bool in_gap = t >= c.gap_start_s && t < c.gap_start_s + c.gap_length_s;
        if (in_gap || u01(rng) < c.drop_fraction) {
          ++out.attitudes_dropped;
          continue;
        }
        const ins::EulerAngles ea = ins::euler_from_quaternion(interp.attitude(t) * c.q_ba);
        const Eigen::Vector3d n = c.sigma_euler_rad.cwiseProduct(gauss3());
        GnssAttitude a;
        a.t_s = t;
        a.euler_a = {ea.roll_rad + n.x(), ea.pitch_rad + n.y(), ins::wrap_pi(ea.yaw_rad + n.z())};
        a.sigma_euler_rad = c.sigma_euler_rad;
        integ.add_attitude(a);
        ++out.attitudes_given;
        attitude_since_fix = true;
      } else {
        const double t = next_fix;
        next_fix += 1.0;
        const ins::EcefMotion ant = interp.antenna(t, Eigen::Vector3d::Zero());
        double lat, lon, h;
        test::geodetic_from_ecef(ant.r_e, lat, lon, h);
        const Eigen::Matrix3d C_en = ins::C_en(lat, lon);
        GnssFix fix;
        fix.t_s = t;
        test::geodetic_from_ecef(ant.r_e + C_en * sigma_pos.cwiseProduct(gauss3()), fix.lat_rad, fix.lon_rad,
                                 fix.height_m);
        fix.sigma_pos_ned_m = sigma_pos;
        fix.has_velocity = true;
        fix.v_n_mps = C_en.transpose() * ant.v_e + sigma_vel * gauss3();
        fix.sigma_vel_n_mps = Eigen::Vector3d::Constant(sigma_vel);
        integ.add_fix(fix);
        if (!attitude_since_fix) ++out.expected_fallbacks;
        attitude_since_fix = false;
        fix_here = true;
      }
    }
    integ.add_imu(imu.apply(run.imu[k], t_end - run.truth[k].t_s));
    if (fix_here) {
      out.t_s.push_back(t_end);
      out.att_err_rad.push_back(ins::attitude_error_n(integ.output().nav.q_nb, run.truth[k + 1].q_nb));
      out.att_sigma_rad.push_back(integ.output().sigma_att_rad);
    }
  }
  out.counters = integ.counters();
  return out;
}

double rms_axis(const std::vector<Eigen::Vector3d>& v, int axis, std::size_t from) {
  double s = 0;
  for (std::size_t i = from; i < v.size(); ++i) s += v[i](axis) * v[i](axis);
  return std::sqrt(s / static_cast<double>(v.size() - from));
}

// Seed 000's case: a MEMS IMU cannot gyrocompass (0.5 deg/s gyro bias against a 12 deg/h earth rate) and a
// parked vehicle's position/velocity say nothing about heading. With GPS attitude (yaw 1-sigma 0.2 deg) the
// heading error converges to the GPS attitude level: the RMS over the last minute below the GPS yaw sigma, the
// filter's yaw 1-sigma at most that sigma and the final error inside 4 of it. Without attitude the yaw 1-sigma
// stays large (prior 20 deg; the linear model's faint earth-rate coupling keeps it near 18 deg) and the error
// with it (tens of degrees: the 0.5 deg/s z-gyro bias integrates unseen).
void check_static_heading(FilterKind filter) {
  AttitudeSim c;
  c.filter = filter;
  const AttitudeRun with = run_attitude_sim(c);
  c.attitude = false;
  const AttitudeRun without = run_attitude_sim(c);
  const std::size_t last_minute = with.t_s.size() - 60;
  const double yaw_rms = rms_axis(with.att_err_rad, 2, last_minute);
  const double yaw_sigma = with.att_sigma_rad.back().z();
  std::printf(
      "static MEMS %s: with GPS attitude yaw RMS (last 60 s) %.6f deg, final error %.4f deg, 1-sigma %.4f deg"
      " (GPS yaw sigma %.2f deg); without: final error %.2f deg, 1-sigma %.1f deg\n",
      filter == FilterKind::Ekf ? "EKF" : "UKF", yaw_rms / io::kRadPerDeg, with.att_err_rad.back().z() / io::kRadPerDeg,
      yaw_sigma / io::kRadPerDeg, c.sigma_euler_rad.z() / io::kRadPerDeg,
      without.att_err_rad.back().z() / io::kRadPerDeg, without.att_sigma_rad.back().z() / io::kRadPerDeg);
  EXPECT_LT(yaw_rms, c.sigma_euler_rad.z());
  EXPECT_LE(yaw_sigma, c.sigma_euler_rad.z());
  EXPECT_LT(std::abs(with.att_err_rad.back().z()), 4.0 * yaw_sigma);
  EXPECT_EQ(with.counters.attitude_accepted, with.attitudes_given);
  EXPECT_EQ(with.counters.attitude_rejected, 0);
  EXPECT_GT(without.att_sigma_rad.back().z(), 10.0 * io::kRadPerDeg);
  EXPECT_GT(std::abs(without.att_err_rad.back().z()), 5.0 * io::kRadPerDeg);
  EXPECT_EQ(without.counters.attitude_epochs, 0);
  EXPECT_EQ(without.counters.fixes_without_attitude, without.counters.epochs);
}

TEST(AttitudeAiding, StaticMemsHeadingConvergesOnlyWithGpsAttitudeEkf) { check_static_heading(FilterKind::Ekf); }
TEST(AttitudeAiding, StaticMemsHeadingConvergesOnlyWithGpsAttitudeUkf) { check_static_heading(FilterKind::Ukf); }

// A moving tactical-grade run (land profile, HG1700AE) with a mounted array (1, -0.5, 2 deg off the IMU axes),
// 20 % of the attitude epochs unfixed and a 10 s gap: every attitude error component inside 4 of the filter's
// sigma at every epoch, at least 95 % inside 3; the counts add up and the fallbacks are the fixes whose
// preceding second had no attitude.
TEST(AttitudeAiding, DropoutsStayConsistentAndAreCounted) {
  AttitudeSim c;
  c.profile = "land";
  c.duration_s = 150.0;
  c.preset = "hg1700ae";
  c.seed = 5;
  c.drop_fraction = 0.2;
  c.gap_start_s = 70.0;
  c.gap_length_s = 10.0;
  c.q_ba = ins::quaternion_from_euler({1 * io::kRadPerDeg, -0.5 * io::kRadPerDeg, 2 * io::kRadPerDeg});
  c.att_error0_rad = Eigen::Vector3d(0.05, -0.05, 0.5) * io::kRadPerDeg;
  c.sigma0_att_rad = Eigen::Vector3d(0.1, 0.1, 1.0) * io::kRadPerDeg;
  const AttitudeRun r = run_attitude_sim(c);
  int inside3 = 0, n = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < r.t_s.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      const double ratio = std::abs(r.att_err_rad[i](a)) / r.att_sigma_rad[i](a);
      worst = std::max(worst, ratio);
      inside3 += ratio <= 3.0;
      ++n;
    }
  std::printf(
      "dropouts: %lld attitudes given, %lld dropped, %lld accepted, %lld rejected, %lld fallbacks of %lld "
      "fixes; worst |error|/sigma %.2f, %.1f %% inside 3 sigma; final yaw error %.4f deg (1-sigma %.4f)\n",
      r.attitudes_given, r.attitudes_dropped, r.counters.attitude_accepted, r.counters.attitude_rejected,
      r.counters.fixes_without_attitude, r.counters.epochs, worst, 100.0 * inside3 / n,
      r.att_err_rad.back().z() / io::kRadPerDeg, r.att_sigma_rad.back().z() / io::kRadPerDeg);
  EXPECT_LT(worst, 4.0);
  EXPECT_GE(static_cast<double>(inside3) / n, 0.95);
  EXPECT_GE(r.attitudes_dropped, 10 + 20);  // the gap plus about a fifth of the rest
  EXPECT_EQ(r.counters.attitude_epochs, r.attitudes_given);
  EXPECT_EQ(r.counters.attitude_accepted + r.counters.attitude_rejected, r.attitudes_given);
  EXPECT_LE(r.counters.attitude_rejected, 1);
  // A rejected attitude leaves its fix without one: the count can exceed the expectation by the rejections only.
  EXPECT_GE(r.counters.fixes_without_attitude, r.expected_fallbacks);
  EXPECT_LE(r.counters.fixes_without_attitude, r.expected_fallbacks + r.counters.attitude_rejected);
  EXPECT_GE(r.expected_fallbacks, 10);
  EXPECT_EQ(r.counters.fix_accepted + r.counters.fix_rejected, r.counters.epochs);
}

// Attitude and fix at the same time: both are applied (attitude first), the fix is not a fallback; an attitude
// near vertical is refused before the gate and counted; non-finite ones are invalid; late ones are counted.
TEST(AttitudeAiding, SameTimeNearVerticalInvalidAndLate) {
  const ins::TrajectorySpec spec = ins::profile_spec("static", 5.0, 0.6, 2.1, 50.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  IntegrationOptions opt;
  GnssInsIntegration integ(run.truth[0].nav(), opt);
  const ins::EulerAngles truth_e = ins::euler_from_quaternion(run.truth[0].q_nb);
  GnssAttitude a;
  a.euler_a = truth_e;
  a.sigma_euler_rad = Eigen::Vector3d::Constant(0.1 * io::kRadPerDeg);
  GnssFix fix;
  fix.lat_rad = run.truth[0].lat_rad;
  fix.lon_rad = run.truth[0].lon_rad;
  fix.height_m = run.truth[0].height_m;
  fix.t_s = a.t_s = 1.005;
  integ.add_fix(fix);  // queued first, but the attitude at the same time goes before it
  integ.add_attitude(a);
  GnssAttitude vertical = a;
  vertical.t_s = 2.005;
  vertical.euler_a.pitch_rad = 88 * io::kRadPerDeg;
  integ.add_attitude(vertical);
  GnssAttitude bad = a;
  bad.t_s = 2.5;
  bad.euler_a.yaw_rad = std::nan("");
  integ.add_attitude(bad);
  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) integ.add_imu(run.imu[k]);
  GnssAttitude late = a;
  late.t_s = 1.0;
  integ.add_attitude(late);
  const IntegrationCounters& n = integ.counters();
  EXPECT_EQ(n.attitude_epochs, 2);
  EXPECT_EQ(n.attitude_accepted, 1);
  EXPECT_EQ(n.attitude_unusable, 1);
  EXPECT_EQ(n.invalid, 1);
  EXPECT_EQ(n.attitude_late, 1);
  EXPECT_EQ(n.epochs, 1);
  EXPECT_EQ(n.fix_accepted, 1);
  EXPECT_EQ(n.fixes_without_attitude, 0);
  const auto records = integ.take_update_records();
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0].prn, -1);  // attitude first
  EXPECT_EQ(records[1].prn, 0);
}

// Tight coupling (17 states) takes GPS attitude the same way: with attitude alone a 2 deg heading error of a parked
// ideal IMU is removed to the attitude's accuracy, and the observation epochs' fallback count is untouched.
TEST(AttitudeAiding, TightCouplingTakesAttitudeToo) {
  const ins::TrajectorySpec spec = ins::profile_spec("static", 20.0, 0.6, 2.1, 50.0);
  const ins::SimulatedRun run = ins::simulate(spec, 100.0);
  IntegrationOptions opt;
  opt.coupling = Coupling::kTight;
  opt.sigma_att_rad = Eigen::Vector3d(0.01, 0.01, 0.05);
  ins::NavState init = run.truth[0].nav();
  ins::correct_attitude(init, Eigen::Vector3d(0.0, 0.0, 2.0 * io::kRadPerDeg));
  GnssInsIntegration integ(init, opt);
  for (std::size_t k = 0; k + 1 < run.truth.size(); ++k) {
    if (k % 100 == 50) {
      GnssAttitude a;
      a.t_s = run.truth[k].t_s + 0.003;
      a.euler_a = ins::euler_from_quaternion(run.truth[k].q_nb);
      a.sigma_euler_rad = Eigen::Vector3d::Constant(0.01 * io::kRadPerDeg);
      integ.add_attitude(a);
    }
    integ.add_imu(run.imu[k]);
  }
  const double yaw_err = ins::attitude_error_n(integ.output().nav.q_nb, run.truth.back().q_nb).z();
  EXPECT_LT(std::abs(yaw_err), 4.0 * 0.01 * io::kRadPerDeg) << yaw_err / io::kRadPerDeg;
  EXPECT_EQ(integ.counters().attitude_accepted, 20);
  EXPECT_EQ(integ.covariance().rows(), 17);
}

}  // namespace
}  // namespace ultratrack::fusion
