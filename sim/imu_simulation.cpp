// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/imu_simulation.hpp"

#include <cmath>

namespace ultratrack::sim {

ImuSimulationResult simulate_imu(const ins::TrajectorySpec& spec, double imu_rate_hz, const ins::ImuErrorSpec& errors,
                                 std::uint64_t seed, const ImuSimulationCallbacks& callbacks, std::stop_token stop) {
  ins::TrajectoryGenerator gen(spec, imu_rate_hz);
  ins::ImuErrorModel model(errors, seed);
  if (callbacks.on_truth) callbacks.on_truth(gen.truth());
  ImuSimulationResult r;
  const auto total = static_cast<std::size_t>(std::llround(spec.duration_s() * imu_rate_hz));
  const bool show_progress = callbacks.on_progress && total >= 500000;  // long runs: every 10 %
  while (!gen.done()) {
    if (stop.stop_requested()) {
      r.interrupted = true;
      break;
    }
    if (show_progress && r.imu_rows % (total / 10) == 0 && r.imu_rows > 0)
      callbacks.on_progress(static_cast<int>(100 * r.imu_rows / total));
    const ins::ImuIncrement ideal = gen.advance();
    const ins::ImuIncrement measured = model.apply(ideal, gen.dt_s());
    if (callbacks.on_imu) callbacks.on_imu(measured);
    if (callbacks.on_truth) callbacks.on_truth(gen.truth());
    ++r.imu_rows;
  }
  r.turn_on = model.turn_on_errors();
  r.distance_m = gen.truth().distance_m;
  return r;
}

}  // namespace ultratrack::sim
