// SPDX-License-Identifier: GPL-3.0-or-later
// IMU error models applied to ideal increments: turn-on bias, bias instability (first-order Gauss-Markov),
// angle/velocity random walk, white noise on the integrated output, scale factor, misalignment,
// quantisation. Named presets (`ideal`, `hg1700ae`, `dmu6x`, `navigation`, `mems`, and the datasheet parts
// `adis16405`, `adis16465`, `bmi088`, `stim300`: docs/imu_models.md); all randomness from a
// seeded std::mt19937_64. Gyro quantities in rad, rad/s, rad/sqrt(s); accelerometer in m/s, m/s^2, m/s/sqrt(s).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "ins/nav_state.hpp"

namespace ultratrack::ins {

// 1-sigma values per axis for one sensor triad.
struct SensorErrorSpec {
  double bias_sigma = 0.0;              // turn-on bias [rad/s | m/s^2]
  double bias_instability_sigma = 0.0;  // steady-state sigma of the Gauss-Markov bias [rad/s | m/s^2]
  double bias_correlation_time_s = 3600.0;
  double random_walk = 0.0;         // ARW [rad/sqrt(s)] | VRW [m/s/sqrt(s)]
  double output_white_noise = 0.0;  // white noise on the integrated output [rad | m/s], does not accumulate
  double scale_factor_sigma = 0.0;  // [ratio]
  double misalignment_sigma = 0.0;  // axis misalignment [rad]
  double quantum = 0.0;             // output quantisation step [rad | m/s]; 0 = none
};

struct ImuErrorSpec {
  SensorErrorSpec gyro;
  SensorErrorSpec accel;
};

const std::vector<std::string>& imu_preset_names();
// Throws InputError (file "imu preset") for an unknown name.
ImuErrorSpec imu_preset(std::string_view name);

// The errors one unit has (drawn once from the spec at turn-on).
struct SensorErrors {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();                // turn-on bias
  Eigen::Matrix3d scale_misalignment = Eigen::Matrix3d::Zero();  // output = (I + M) * input
};
struct ImuErrors {
  SensorErrors gyro;
  SensorErrors accel;
};

ImuErrors draw_imu_errors(const ImuErrorSpec& spec, std::mt19937_64& rng);

// Corrupts a stream of ideal increments. The constructor draws the turn-on errors from the seed unless
// they are given explicitly (for single-error experiments).
class ImuErrorModel {
 public:
  ImuErrorModel(const ImuErrorSpec& spec, std::uint64_t seed);
  ImuErrorModel(const ImuErrorSpec& spec, const ImuErrors& turn_on, std::uint64_t seed);

  // The measured increment for the ideal one over (t_prev, ideal.t_s]; dt_s = interval length.
  ImuIncrement apply(const ImuIncrement& ideal, double dt_s);

  const ImuErrors& turn_on_errors() const { return errors_; }
  // Current total bias (turn-on + Gauss-Markov), for truth logging.
  Eigen::Vector3d gyro_bias() const { return errors_.gyro.bias + gm_gyro_; }
  Eigen::Vector3d accel_bias() const { return errors_.accel.bias + gm_accel_; }

 private:
  struct Channel {
    Eigen::Vector3d residual = Eigen::Vector3d::Zero();  // quantisation remainder carried forward
    Eigen::Vector3d prev_white = Eigen::Vector3d::Zero();
  };
  Eigen::Vector3d corrupt(const SensorErrorSpec& s, const SensorErrors& e, Eigen::Vector3d& gm, Channel& ch,
                          const Eigen::Vector3d& ideal, double dt);
  Eigen::Vector3d gauss3();
  void start_gauss_markov();

  ImuErrorSpec spec_;
  ImuErrors errors_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Vector3d gm_gyro_ = Eigen::Vector3d::Zero(), gm_accel_ = Eigen::Vector3d::Zero();
  Channel gyro_ch_, accel_ch_;
};

}  // namespace ultratrack::ins
