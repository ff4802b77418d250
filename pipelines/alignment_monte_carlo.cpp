// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/alignment_monte_carlo.hpp"

#include <cmath>
#include <random>

#include "ins/earth_model.hpp"

namespace ultratrack::pipelines {

StationaryInputs simulate_stationary_inputs(const StationaryScenario& sc, std::uint64_t seed) {
  StationaryInputs in;
  ins::ImuErrorModel model(sc.imu, seed);
  in.errors = model.turn_on_errors();
  const Eigen::Quaterniond q_nb = ins::quaternion_from_euler(sc.attitude);
  const Eigen::Matrix3d C_bn = q_nb.toRotationMatrix().transpose();
  const Eigen::Vector3d w_ib_b = C_bn * ins::earth_rate_n(sc.lat_rad);
  const Eigen::Vector3d f_b = C_bn * -ins::gravity_n(sc.lat_rad, sc.height_m);
  const double dt = 1.0 / sc.imu_rate_hz;
  const long rows = std::lround(sc.duration_s * sc.imu_rate_hz);
  in.imu.reserve(rows);
  for (long k = 1; k <= rows; ++k) in.imu.push_back(model.apply({k * dt, w_ib_b * dt, f_b * dt}, dt));
  const ins::EulerAngles array = ins::euler_from_quaternion(q_nb * sc.q_ba);
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double t = sc.attitude_offset_s; t < sc.duration_s; t += 1.0 / sc.attitude_rate_hz) {
    fusion::GnssAttitude a;
    a.t_s = t;
    a.euler_a = {array.roll_rad + sc.gps_sigma_euler_rad.x() * n(rng),
                 array.pitch_rad + sc.gps_sigma_euler_rad.y() * n(rng),
                 ins::wrap_pi(array.yaw_rad + sc.gps_sigma_euler_rad.z() * n(rng))};
    a.sigma_euler_rad = sc.gps_sigma_euler_rad;
    in.gps.push_back(a);
  }
  return in;
}

AlignmentMonteCarloResult alignment_monte_carlo(const StationaryScenario& sc, fusion::StationaryAlignmentOptions o,
                                                int runs, std::uint64_t first_seed) {
  o.lat_rad = sc.lat_rad;
  o.height_m = sc.height_m;
  o.duration_s = sc.duration_s - sc.attitude_offset_s - 1.0 / sc.imu_rate_hz;  // ends on the last IMU row
  AlignmentMonteCarloResult r;
  r.runs = runs;
  AxisStatistics* axes[3] = {&r.roll, &r.pitch, &r.yaw};
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero(), sigma = Eigen::Vector3d::Zero();
  for (int k = 0; k < runs; ++k) {
    const StationaryInputs in = simulate_stationary_inputs(sc, first_seed + k);
    const fusion::StationaryAlignmentResult a = fusion::align_stationary(in.imu, in.gps, o);
    const ins::EulerAngles e = ins::euler_from_quaternion(a.nav.q_nb);
    const Eigen::Vector3d err(e.roll_rad - sc.attitude.roll_rad, e.pitch_rad - sc.attitude.pitch_rad,
                              ins::wrap_pi(e.yaw_rad - sc.attitude.yaw_rad));
    sum += err;
    sum2 += err.cwiseAbs2();
    sigma += a.sigma_euler_rad;
    for (int i = 0; i < 3; ++i)
      if (std::abs(err(i)) > 3.0 * a.sigma_euler_rad(i)) ++axes[i]->outside_3sigma;
  }
  for (int i = 0; i < 3; ++i) {
    axes[i]->mean = sum(i) / runs;
    axes[i]->rms = std::sqrt(sum2(i) / runs);
    axes[i]->std =
        runs > 1 ? std::sqrt(std::max(0.0, (sum2(i) - runs * axes[i]->mean * axes[i]->mean) / (runs - 1))) : 0.0;
    axes[i]->mean_sigma = sigma(i) / runs;
  }
  return r;
}

}  // namespace ultratrack::pipelines
