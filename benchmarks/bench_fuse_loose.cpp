// SPDX-License-Identifier: GPL-3.0-or-later
// Loose GNSS/INS integration figures (docs/validation.md), not timing: `ultratrack fuse`'s engine in process
// on simulated data. (1) Position RMS against the simulator's truth versus the GNSS-only RMS on the [ChoUKF]
// trajectories and the land profile, HG1700AE at 100 Hz, 1 Hz fixes (white 1.5/1.5/3 m, 0.05 m/s).
// The 60 s outage Monte Carlo lives with the filter's tests (tests/fusion/integration_test.cpp,
// ULTRATRACK_FUSION_MC_RUNS=100). Run by hand: `nice -n 5 build/benchmarks/bench_fuse_loose`.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/trajectory_simulator.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/units.hpp"
#include "pipelines/fuse.hpp"
#include "pipelines/gnss_fix_simulation.hpp"

using namespace ultratrack;

namespace {

struct Scenario {
  std::vector<ins::NavState> truth;
  std::vector<ins::TruthSample> truth_samples;
  std::vector<ins::ImuIncrement> ideal;
};

Scenario make_scenario(const std::string& profile, double duration_s, double rate_hz) {
  const auto spec = ins::profile_spec(profile, duration_s, 36.37 * io::kRadPerDeg, 127.36 * io::kRadPerDeg, 300.0);
  ins::SimulatedRun run = ins::simulate(spec, rate_hz);
  Scenario s;
  for (const auto& t : run.truth) s.truth.push_back(t.nav());
  s.truth_samples = std::move(run.truth);
  s.ideal = std::move(run.imu);
  return s;
}

std::vector<ins::ImuIncrement> corrupt(const Scenario& s, const std::string& preset, std::uint64_t seed) {
  ins::ImuErrorModel model(ins::imu_preset(preset), seed);
  std::vector<ins::ImuIncrement> out;
  out.reserve(s.ideal.size());
  double t_prev = 0.0;
  for (const auto& inc : s.ideal) {
    out.push_back(model.apply(inc, inc.t_s - t_prev));
    t_prev = inc.t_s;
  }
  return out;
}

pipelines::FuseResult run_once(const Scenario& s, const ins::TruthInterpolator& truth, const std::string& preset,
                               std::uint64_t seed, fusion::FilterKind filter,
                               std::vector<std::pair<double, double>> outages, double gnss_rate_hz) {
  ultratrack::pipelines::GnssFixSimulationOptions g;
  g.rate_hz = gnss_rate_hz;
  g.first_time_s = 0.0;
  g.seed = seed + 1000;
  const auto fixes = ultratrack::pipelines::simulate_gnss_fixes(truth, g);
  pipelines::FuseSettings settings;
  settings.filter = filter;
  settings.align = pipelines::AlignMode::Motion;
  settings.config.imu_preset = preset;
  settings.config.velocity_sigma_mps = 0.05;
  settings.outages = std::move(outages);
  return pipelines::fuse(corrupt(s, preset, seed), fixes, ultratrack::pipelines::truth_samples_from_nav(s.truth),
                         settings);
}

void BM_LooseRms(benchmark::State& state, std::string profile, fusion::FilterKind filter) {
  const Scenario s = make_scenario(profile, 300.0, 100.0);
  const ins::TruthInterpolator truth(s.truth_samples);
  pipelines::FuseResult r;
  for (auto _ : state) r = run_once(s, truth, "hg1700ae", 21, filter, {}, 1.0);
  if (!r.rms_all || !r.gnss_rms) {
    state.SkipWithError("no truth comparison");
    return;
  }
  // After convergence (heading 1-sigma < 1 deg) when it happens; the straight run from rest never separates
  // heading from the east accelerometer bias (constant specific force), so all rows after alignment count there.
  const pipelines::ErrorRms& e = r.rms_converged ? *r.rms_converged : *r.rms_all;
  state.counters["fused_h_rms_m"] = e.horizontal_m;
  state.counters["fused_3d_rms_m"] = e.position_3d_m;
  state.counters["gnss_h_rms_m"] = r.gnss_rms->horizontal_m;
  state.counters["gnss_3d_rms_m"] = r.gnss_rms->position_3d_m;
  state.counters["heading_rms_deg"] = e.heading_deg;
  state.counters["within_3sigma"] = e.within_3sigma;
  state.counters["converged_at_s"] = r.converged_at_s ? *r.converged_at_s : -1.0;
  state.counters["final_heading_sigma_deg"] = r.final_sigma.attitude_ned_rad.z() * 180.0 / std::numbers::pi;
  state.counters["rejected"] = static_cast<double>(r.counters.rejected);
}

}  // namespace

BENCHMARK_CAPTURE(BM_LooseRms, straight_ekf, "straight", fusion::FilterKind::Ekf)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_LooseRms, circle_ekf, "circle", fusion::FilterKind::Ekf)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_LooseRms, s_ekf, "s", fusion::FilterKind::Ekf)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_LooseRms, spiral_ekf, "spiral", fusion::FilterKind::Ekf)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_LooseRms, land_ekf, "land", fusion::FilterKind::Ekf)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_LooseRms, land_ukf, "land", fusion::FilterKind::Ukf)->Iterations(1)->Unit(benchmark::kSecond);
