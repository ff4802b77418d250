// SPDX-License-Identifier: GPL-3.0-or-later
// Receiver motion and clock models of the synthesiser: Hermite trajectory exact for quadratic motion,
// trajectory CSV errors, the clock's deterministic part exact, and its random walks with the stated
// variance growth (closed forms: var = q^2 T).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "signals/input_error.hpp"
#include "signals/receiver_clock.hpp"
#include "signals/receiver_motion.hpp"
#include "support/test_data.hpp"

namespace ultratrack::signals {
namespace {

TEST(TrajectoryMotion, HermiteIsExactForConstantAcceleration) {
  const Eigen::Vector3d r0(-3.8e6, 3.5e6, 3.6e6), v0(10, -5, 2), a(3, 1, -2);
  std::vector<TrajectorySample> s;
  for (int i = 0; i <= 10; ++i) {
    const double t = 0.1 * i;
    s.push_back({t, r0 + v0 * t + 0.5 * a * t * t, v0 + a * t});
  }
  const TrajectoryMotion m(s);
  for (double t : {0.0, 0.037, 0.25, 0.5, 0.9999, 1.0}) {
    const auto st = m.antenna_state(0, t);
    EXPECT_LT((st.r_e_m - (r0 + v0 * t + 0.5 * a * t * t)).norm(), 1e-6) << t;
    // The samples' ECEF positions carry ~5e-10 m rounding each; over 0.1 s that is ~1e-8 m/s of velocity.
    EXPECT_LT((st.v_e_mps - (v0 + a * t)).norm(), 5e-8) << t;
  }
  // Past the end: held at the end velocity.
  const auto after = m.antenna_state(0, 1.5);
  EXPECT_LT((after.v_e_mps - (v0 + a)).norm(), 1e-12);
}

TEST(TrajectoryMotion, CsvReaderChecksRowsAndRate) {
  const auto dir = test::scratch_dir();
  const auto write = [&](const char* name, const char* text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  const auto ok = read_trajectory_csv(write("ok.csv", "t_s,x,y,z,vx,vy,vz\n0,1,2,3,0,0,0\n# note\n0.1,1,2,3,0,0,0\n"));
  EXPECT_EQ(ok.size(), 2u);
  const auto expect_error = [&](const std::filesystem::path& p, const char* text, int line) {
    try {
      read_trajectory_csv(p);
      ADD_FAILURE() << "no error for " << p;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
      EXPECT_EQ(e.line(), line) << e.what();
    }
  };
  expect_error(write("short.csv", "t,x,y,z,vx,vy,vz\n0,1,2,3,0,0\n"), "expected 7 numbers", 2);
  expect_error(write("back.csv", "0,1,2,3,0,0,0\n0.1,1,2,3,0,0,0\n0.05,1,2,3,0,0,0\n"), "does not increase", 3);
  expect_error(write("slow.csv", "0,1,2,3,0,0,0\n0.5,1,2,3,0,0,0\n"), "at least 10 Hz", 2);
  expect_error(write("one.csv", "0,1,2,3,0,0,0\n"), "at least two rows", 0);
  expect_error(dir / "absent.csv", "cannot open", 0);
}

TEST(ReceiverClock, DeterministicPartIsExact) {
  ReceiverClock c({1e-4, 2e-7, 0.0, 0.0}, 1);
  const auto s = c.at(12.5);
  EXPECT_DOUBLE_EQ(s.bias_s, 1e-4 + 2e-7 * 12.5);
  EXPECT_DOUBLE_EQ(s.drift_sps, 2e-7);
}

// Over many seeds: var(drift(T) - drift(0)) = q_d^2 T for random-walk FM, and var(b(T) - b(0)) = q_b^2 T
// for white FM alone. 400 clocks: the sample variance has a relative sigma of 7 %; 25 % is > 3 sigma.
TEST(ReceiverClock, RandomWalksGrowWithTheStatedDensities) {
  const double T = 0.5, qd = 1e-9, qb = 2e-10;
  double vd = 0, vb = 0;
  const int n = 400;
  for (int seed = 0; seed < n; ++seed) {
    ReceiverClock drift_only({0.0, 0.0, 0.0, qd}, static_cast<std::uint64_t>(seed));
    const double d = drift_only.at(T).drift_sps;
    vd += d * d;
    ReceiverClock bias_only({0.0, 0.0, qb, 0.0}, static_cast<std::uint64_t>(seed) + 100000);
    const double b = bias_only.at(T).bias_s;
    vb += b * b;
  }
  EXPECT_NEAR(vd / n / (qd * qd * T), 1.0, 0.25);
  EXPECT_NEAR(vb / n / (qb * qb * T), 1.0, 0.25);
  // Same seed, same path, whatever the order of the queries.
  ReceiverClock a({0.0, 1e-7, qb, qd}, 5), b({0.0, 1e-7, qb, qd}, 5);
  const double late = a.at(0.3).bias_s;
  a.at(0.1);
  EXPECT_EQ(b.at(0.1).bias_s, a.at(0.1).bias_s);
  EXPECT_EQ(b.at(0.3).bias_s, late);
}

}  // namespace
}  // namespace ultratrack::signals
