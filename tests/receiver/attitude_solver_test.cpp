// SPDX-License-Identifier: GPL-3.0-or-later
// AttitudeSolver against simulator truth (attitude_phase_simulator.hpp): the seed geometry (3 antennas, baselines
// 1 m on the roll axis and 1.025 m on the pitch axis, 3 mm carrier noise per antenna), random skies, random
// attitudes, random integer ambiguities and line biases. Single-epoch success rates with and without the
// constraints, attitude RMS against the solver's own covariance, slips, blockages and a moving sequence.
#include "receiver/attitude_solver.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "attitude_phase_simulator.hpp"
#include "io/why_invalid.hpp"

using namespace ultratrack::receiver;
using testsim::PhaseSimulator;
using ultratrack::io::kRadPerDeg;

namespace {

AttitudeSolverOptions seed_options() {
  AttitudeSolverOptions o;
  o.array.lever_arm_body_m = testsim::seed_lever_arms();
  return o;
}

// Every fixed SD ambiguity pair of one antenna must differ by the true DD integer.
bool ambiguities_correct(const AttitudeSolution& s, PhaseSimulator& sim) {
  if (s.ambiguities.empty()) return false;
  std::map<int, SdAmbiguity> anchor;
  for (const SdAmbiguity& a : s.ambiguities) {
    auto it = anchor.find(a.antenna);
    if (it == anchor.end()) {
      anchor[a.antenna] = a;
      continue;
    }
    if (a.cycles - it->second.cycles != sim.true_dd(a.antenna, a.prn, it->second.prn)) return false;
  }
  return true;
}

struct AngleErrors {
  double roll, pitch, yaw;
};

AngleErrors errors(const AttitudeSolution& s, double roll, double pitch, double yaw) {
  auto wrap = [](double a) { return std::remainder(a, 2.0 * M_PI); };
  return {wrap(s.roll_rad - roll), wrap(s.pitch_rad - pitch), wrap(s.yaw_rad - yaw)};
}

struct MonteCarlo {
  int trials = 0, fixed = 0, correct = 0, wrong = 0;
  double sum_sq[3] = {0, 0, 0}, sum_var[3] = {0, 0, 0};
  int within_3sigma = 0;
  double rms(int i) const { return std::sqrt(sum_sq[i] / correct) / kRadPerDeg; }
  double theory(int i) const { return std::sqrt(sum_var[i] / correct) / kRadPerDeg; }
};

// Single-epoch trials: each with a fresh sky, attitude, integers and line biases, and a reset solver. num_sats > 0:
// a random sky of that many satellites; 0: the nominal constellation at a random time of day (mask 10 deg), times
// with fewer than 8 satellites drawn again.
MonteCarlo run_single_epoch(int num_sats, int trials, bool constrained, std::uint64_t seed) {
  PhaseSimulator sim(testsim::seed_lever_arms(), seed);
  AttitudeSolverOptions o = seed_options();
  o.use_length_constraint = constrained;
  AttitudeSolver solver(o);
  std::uniform_real_distribution<double> tilt(-20.0 * kRadPerDeg, 20.0 * kRadPerDeg), heading(0.0, 2.0 * M_PI);
  MonteCarlo mc;
  for (int t = 0; t < trials; ++t) {
    sim.reseed_biases();
    std::vector<testsim::Sky> sky;
    if (num_sats > 0) {
      sky = sim.random_sky(num_sats);
    } else {
      std::uniform_real_distribution<double> tod(0.0, 86400.0);
      while (sky.size() < 8) sky = sim.nominal_sky({2300, 86400.0 + tod(sim.rng)});
    }
    const double roll = tilt(sim.rng), pitch = tilt(sim.rng), yaw = heading(sim.rng);
    solver.reset();
    const AttitudeSolution s = solver.update(sim.epoch(sky, testsim::dcm_nb(roll, pitch, yaw)));
    ++mc.trials;
    if (!s.fixed) continue;
    ++mc.fixed;
    EXPECT_TRUE(s.valid);
    EXPECT_TRUE(s.new_fix);
    if (!ambiguities_correct(s, sim)) {
      ++mc.wrong;
      continue;
    }
    ++mc.correct;
    const AngleErrors e = errors(s, roll, pitch, yaw);
    const double err[3] = {e.roll, e.pitch, e.yaw};
    bool in3 = true;
    for (int i = 0; i < 3; ++i) {
      mc.sum_sq[i] += err[i] * err[i];
      mc.sum_var[i] += s.covariance_rad2(i, i);
      in3 = in3 && std::abs(err[i]) <= 3.0 * std::sqrt(s.covariance_rad2(i, i));
    }
    mc.within_3sigma += in3 ? 1 : 0;
  }
  return mc;
}

void print(const char* name, const MonteCarlo& mc) {
  std::printf(
      "%s: %d trials, fixed %.2f %%, correct %.2f %%, wrong %.3f %%; RMS roll/pitch/yaw %.3f/%.3f/%.3f deg, "
      "theory %.3f/%.3f/%.3f deg\n",
      name, mc.trials, 100.0 * mc.fixed / mc.trials, 100.0 * mc.correct / mc.trials, 100.0 * mc.wrong / mc.trials,
      mc.correct ? mc.rms(0) : 0.0, mc.correct ? mc.rms(1) : 0.0, mc.correct ? mc.rms(2) : 0.0,
      mc.correct ? mc.theory(0) : 0.0, mc.correct ? mc.theory(1) : 0.0, mc.correct ? mc.theory(2) : 0.0);
}

}  // namespace

TEST(AttitudeSolver, RejectsInvalidOptions) {
  AttitudeSolverOptions o = seed_options();
  EXPECT_EQ(ultratrack::io::why_invalid(o), "");
  o.array.lever_arm_body_m.pop_back();
  EXPECT_NE(ultratrack::io::why_invalid(o), "");
  EXPECT_THROW(AttitudeSolver{o}, std::invalid_argument);
  o = seed_options();
  o.array.lever_arm_body_m[2] = Eigen::Vector3d(2.0, 0.0, 0.0);  // collinear with antenna 1
  EXPECT_NE(ultratrack::io::why_invalid(o), "");
  o = seed_options();
  o.phase_sigma_m = 0.0;
  EXPECT_NE(ultratrack::io::why_invalid(o), "");
}

// Seed geometry, 8 satellites, 2000 single epochs: success >= 99.5 % with the constraints; accuracy within the
// issue's bounds and consistent with the solver's covariance (RMS / theory within 10 %: 2000 samples give the
// RMS to about 1.6 %).
TEST(AttitudeSolver, EightSatellitesSingleEpochSuccessAndAccuracy) {
  const auto t0 = std::chrono::steady_clock::now();
  const MonteCarlo c = run_single_epoch(0, 2000, true, 11);
  const auto t1 = std::chrono::steady_clock::now();
  const MonteCarlo u = run_single_epoch(0, 2000, false, 11);
  const MonteCarlo r = run_single_epoch(8, 2000, true, 13);
  print("random sky of 8 sats, constrained", r);
  print("nominal constellation (>= 8 sats), constrained", c);
  print("nominal constellation (>= 8 sats), unconstrained", u);
  std::printf("constrained: %.2f ms per epoch\n", std::chrono::duration<double, std::milli>(t1 - t0).count() / 2000);
  EXPECT_GE(c.correct, 0.995 * c.trials);
  EXPECT_LE(c.wrong, 1);  // < 0.1 %
  EXPECT_LE(c.rms(2), 0.15);
  EXPECT_LE(c.rms(0), 0.4);
  EXPECT_LE(c.rms(1), 0.4);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.rms(i) / c.theory(i), 1.0, 0.1) << i;
  EXPECT_GE(c.within_3sigma, 0.98 * c.correct);
  // The constraints are what make the single epoch work.
  EXPECT_GT(c.correct, u.correct);
  // A random sky of exactly 8 satellites (elevations 15-90 deg): the same success; accuracy as its covariance says.
  EXPECT_GE(r.correct, 0.995 * r.trials);
  EXPECT_LE(r.wrong, 1);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.rms(i) / r.theory(i), 1.0, 0.1) << i;
}

// Five satellites: fewer fixes, but a fix that is given is right (wrong fixes < 0.1 %).
TEST(AttitudeSolver, FiveSatellitesWrongFixesBelowOnePerMille) {
  const MonteCarlo c = run_single_epoch(5, 2000, true, 12);
  const MonteCarlo u = run_single_epoch(5, 2000, false, 12);
  print("5 sats, constrained", c);
  print("5 sats, unconstrained", u);
  EXPECT_LE(c.wrong, 1);
  EXPECT_GT(c.correct, 0);
  if (c.correct > 100) {
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(c.rms(i) / c.theory(i), 1.0, 0.2) << i;
  }
}

namespace {

// Multi-epoch sessions at 10 Hz: a fresh random sky of num_sats satellites (static over the session), random
// integers and line biases, a random attitude turning at a random yaw rate (up to 10 deg/s: the attitude is free
// per epoch, only the integers are common), white 3 mm noise per antenna and epoch. Each session runs until the
// solver's first fix (one fix decision per session: the decisions are independent) or max_epochs.
struct Sessions {
  int sessions = 0, decisions = 0, wrong = 0, single_epoch = 0;
  std::vector<int> fixed_by;  // [e]: sessions fixed within e + 1 epochs
  double sum_sq[3] = {0, 0, 0}, sum_var[3] = {0, 0, 0};
  int correct = 0, within_3sigma = 0;
  double worst_sigma = 0.0;
  double rms(int i) const { return std::sqrt(sum_sq[i] / correct) / kRadPerDeg; }
  double theory(int i) const { return std::sqrt(sum_var[i] / correct) / kRadPerDeg; }
};

Sessions run_sessions(int num_sats, int sessions, int max_epochs, bool multi_epoch, std::uint64_t seed) {
  PhaseSimulator sim(testsim::seed_lever_arms(), seed);
  AttitudeSolverOptions o = seed_options();
  o.multi_epoch = multi_epoch;
  AttitudeSolver solver(o);
  std::uniform_real_distribution<double> tilt(-20.0 * kRadPerDeg, 20.0 * kRadPerDeg), heading(0.0, 2.0 * M_PI),
      rate(-10.0 * kRadPerDeg, 10.0 * kRadPerDeg);
  Sessions r;
  r.fixed_by.assign(static_cast<std::size_t>(max_epochs), 0);
  for (int n = 0; n < sessions; ++n) {
    sim.reseed_biases();
    const std::vector<testsim::Sky> sky = sim.random_sky(num_sats);
    const double roll = tilt(sim.rng), pitch = tilt(sim.rng), yaw0 = heading(sim.rng), yaw_rate = rate(sim.rng);
    solver.reset();
    ++r.sessions;
    for (int e = 0; e < max_epochs; ++e) {
      const double yaw = std::remainder(yaw0 + yaw_rate * 0.1 * e, 2.0 * M_PI);
      const AttitudeSolution s = solver.update(sim.epoch(sky, testsim::dcm_nb(roll, pitch, yaw), 0.1 * e));
      if (!s.fixed) continue;
      EXPECT_TRUE(s.new_fix);
      ++r.decisions;
      if (e == 0) ++r.single_epoch;
      for (int k = e; k < max_epochs; ++k) ++r.fixed_by[static_cast<std::size_t>(k)];
      if (!ambiguities_correct(s, sim)) {
        ++r.wrong;
        break;
      }
      ++r.correct;
      const AngleErrors err = errors(s, roll, pitch, yaw < 0 ? yaw + 2.0 * M_PI : yaw);
      const double v[3] = {err.roll, err.pitch, err.yaw};
      bool in3 = true;
      for (int i = 0; i < 3; ++i) {
        r.sum_sq[i] += v[i] * v[i];
        r.sum_var[i] += s.covariance_rad2(i, i);
        const double z = std::abs(v[i]) / std::sqrt(s.covariance_rad2(i, i));
        in3 = in3 && z <= 3.0;
        r.worst_sigma = std::max(r.worst_sigma, z);
      }
      r.within_3sigma += in3 ? 1 : 0;
      break;
    }
  }
  return r;
}

void print(const char* name, const Sessions& r) {
  const auto pct = [&](int e) { return 100.0 * r.fixed_by[static_cast<std::size_t>(e)] / r.sessions; };
  std::printf(
      "%s: %d sessions, fixed in the first epoch %.1f %%, within 0.5 s %.1f %%, 1 s %.1f %%, 2 s %.1f %%, "
      "%zu epochs %.1f %%; wrong %d of %d fix decisions; RMS roll/pitch/yaw %.3f/%.3f/%.3f deg, theory "
      "%.3f/%.3f/%.3f deg\n",
      name, r.sessions, 100.0 * r.single_epoch / r.sessions, pct(4), pct(9), pct(19), r.fixed_by.size(),
      pct(static_cast<int>(r.fixed_by.size()) - 1), r.wrong, r.decisions, r.correct ? r.rms(0) : 0.0,
      r.correct ? r.rms(1) : 0.0, r.correct ? r.rms(2) : 0.0, r.correct ? r.theory(0) : 0.0,
      r.correct ? r.theory(1) : 0.0, r.correct ? r.theory(2) : 0.0);
  std::printf("  within 3 sigma %d of %d, worst %.1f sigma\n", r.within_3sigma, r.correct, r.worst_sigma);
}

}  // namespace

// Five satellites over several epochs: the candidates of the first epoch scored on the following ones. 3000
// sessions are 3000 independent fix decisions: were the wrong-fix probability 0.1 %, none wrong would happen with
// probability 0.999^3000 = 5 %; at most one wrong is allowed (probability 20 % at 0.1 %, so a rate of 0.1 % fails
// this test 4 times in 5, a rate of 0.03 % passes it 77 % of the time).
TEST(AttitudeSolver, FiveSatellitesMultiEpochFixesMostSessionsWithoutWrongFixes) {
  const auto t0 = std::chrono::steady_clock::now();
  const Sessions m = run_sessions(5, 3000, 30, true, 31);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  print("5 sats, multi-epoch", m);
  std::printf("multi-epoch: %.3f ms per session\n", ms / m.sessions);
  EXPECT_LE(m.wrong, 1);
  EXPECT_EQ(m.decisions, m.fixed_by.back());
  // Measured 93 % within 1 s and 98.5 % within 3 s (single-epoch only: 45 % and 69 %); floors well below.
  EXPECT_GE(m.fixed_by[9], 0.85 * m.sessions);
  EXPECT_GE(m.fixed_by.back(), 0.95 * m.sessions);
  EXPECT_GE(m.within_3sigma, 0.98 * m.correct);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m.rms(i) / m.theory(i), 1.0, 0.2) << i;
}

// The same sessions with the multi-epoch test off (single-epoch validation every epoch): far fewer fixes.
TEST(AttitudeSolver, FiveSatellitesSingleEpochOnlyFixesFewerSessions) {
  const Sessions single = run_sessions(5, 200, 30, false, 31);
  print("5 sats, single-epoch only", single);
  EXPECT_LE(single.wrong, 1);
  EXPECT_LT(single.fixed_by[9], 0.7 * single.sessions);
}
