#include "imu_simulation.hpp"

#include <fmt/core.h>

#include <cmath>
#include <numbers>

#include "ins/imu_csv.hpp"
#include "ins/odometer.hpp"
#include "io/atomic_file.hpp"

namespace ultratrack::tools {

ImuSimulationResult simulate_imu(const ins::TrajectorySpec& spec, double imu_rate_hz, const ins::ImuErrorSpec& errors,
                                 std::uint64_t seed, const std::filesystem::path& imu_csv,
                                 const std::function<void(const ins::TruthSample&)>& on_truth,
                                 const std::string& progress_label) {
  ins::TrajectoryGenerator gen(spec, imu_rate_hz);
  ins::ImuErrorModel model(errors, seed);
  ins::ImuCsvWriter imu_out(imu_csv);
  on_truth(gen.truth());
  ImuSimulationResult r;
  const auto total = static_cast<std::size_t>(std::llround(spec.duration_s() * imu_rate_hz));
  const bool show_progress = !progress_label.empty() && total >= 500000;  // long runs: every 10 %
  while (!gen.done()) {
    if (show_progress && r.imu_rows % (total / 10) == 0 && r.imu_rows > 0)
      fmt::print(stderr, "{}: IMU {}%\n", progress_label, 100 * r.imu_rows / total);
    const ins::ImuIncrement ideal = gen.advance();
    imu_out.write(model.apply(ideal, gen.dt_s()));
    on_truth(gen.truth());
    ++r.imu_rows;
  }
  imu_out.commit();
  r.turn_on = model.turn_on_errors();
  r.distance_m = gen.truth().distance_m;
  return r;
}

void write_odometer_csv(const std::filesystem::path& file, std::span<const ins::TruthSample> truth,
                        double scale_factor_error) {
  ins::OdometerOptions odo;
  odo.scale_factor_error = scale_factor_error;
  const auto samples = ins::simulate_odometer(truth, odo);
  io::AtomicFile f(file);
  f.write("t_s,pulses,distance_m\n");
  for (const auto& s : samples) f.write(fmt::format("{},{},{}\n", s.t_s, s.pulses, s.distance_m));
  f.commit();
}

std::string turn_on_bias_json(const ins::ImuErrors& e) {
  constexpr double kDph = 180.0 / std::numbers::pi * 3600.0;
  return fmt::format(
      "  \"gyro_turn_on_bias_dph\": [{:.6g}, {:.6g}, {:.6g}],\n"
      "  \"accel_turn_on_bias_mps2\": [{:.6g}, {:.6g}, {:.6g}],\n",
      e.gyro.bias.x() * kDph, e.gyro.bias.y() * kDph, e.gyro.bias.z() * kDph, e.accel.bias.x(), e.accel.bias.y(),
      e.accel.bias.z());
}

}  // namespace ultratrack::tools
