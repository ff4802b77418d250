// SPDX-License-Identifier: GPL-3.0-or-later
// sim::simulate_imu stops between two IMU intervals when its stop token is requested (`imusim`'s Ctrl-C): the rows
// handed over are exactly those before the request, the truth has one sample more (t = 0), and the result says it
// was interrupted; without a request the run covers the whole trajectory.
#include "sim/imu_simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stop_token>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"

using namespace ultratrack;

TEST(ImuSimulation, AStopRequestEndsTheRunBetweenIntervals) {
  const ins::TrajectorySpec spec = ins::profile_spec("circle", 20.0, 0.6, 2.2, 100.0);
  std::stop_source stop;
  std::size_t imu = 0, truth = 0;
  sim::ImuSimulationCallbacks callbacks;
  callbacks.on_imu = [&](const ins::ImuIncrement&) {
    if (++imu == 250) stop.request_stop();
  };
  callbacks.on_truth = [&](const ins::TruthSample&) { ++truth; };
  const sim::ImuSimulationResult r =
      sim::simulate_imu(spec, 100.0, ins::imu_preset("hg1700ae"), 3, callbacks, stop.get_token());
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.imu_rows, 250u);
  EXPECT_EQ(imu, 250u);
  EXPECT_EQ(truth, 251u);

  imu = truth = 0;
  callbacks.on_imu = [&](const ins::ImuIncrement&) { ++imu; };
  const sim::ImuSimulationResult whole = sim::simulate_imu(spec, 100.0, ins::imu_preset("hg1700ae"), 3, callbacks);
  EXPECT_FALSE(whole.interrupted);
  EXPECT_EQ(whole.imu_rows, static_cast<std::size_t>(std::llround(20.0 * 100.0)));
  EXPECT_EQ(truth, whole.imu_rows + 1);
}
