// SPDX-License-Identifier: GPL-3.0-or-later
// Strapdown mechanisation speed: steps per second (one step = one IMU interval: attitude, velocity,
// position update with earth model and normal gravity), plus the trajectory/IMU simulator and error model.
#include <benchmark/benchmark.h>

#include <numbers>

#include "ins/imu_error_model.hpp"
#include "ins/strapdown.hpp"
#include "ins/trajectory_simulator.hpp"

using namespace ultratrack::ins;

static void BM_StrapdownStep(benchmark::State& state) {
  const TrajectorySpec spec = profile_spec("circle", 10.0, 0.63, 2.2, 1000.0);
  const SimulatedRun run = simulate(spec, 100.0);
  Strapdown ins(run.truth.front().nav());
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == run.imu.size()) {  // restart the short loop of real data (rare; not timed apart)
      ins = Strapdown(run.truth.front().nav());
      k = 0;
    }
    ins.step(run.imu[k++]);
    benchmark::DoNotOptimize(ins.state().q_nb);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_StrapdownStep);

static void BM_TrajectoryGeneratorStep100Hz(benchmark::State& state) {
  TrajectoryGenerator gen(profile_spec("s", 1e6, 0.63, 2.2, 1000.0), 100.0);
  for (auto _ : state) benchmark::DoNotOptimize(gen.advance());
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TrajectoryGeneratorStep100Hz);

static void BM_ImuErrorModelHg1700ae(benchmark::State& state) {
  ImuErrorModel m(imu_preset("hg1700ae"), 1);
  const ImuIncrement ideal{0.01, {1e-5, 2e-5, 3e-5}, {0.0, 0.0, -0.098}};
  for (auto _ : state) benchmark::DoNotOptimize(m.apply(ideal, 0.01));
  state.counters["samples_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ImuErrorModelHg1700ae);
