// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/imu_error_model.hpp"

#include <cmath>
#include <numbers>

#include "ins/ins_error.hpp"
#include "io/units.hpp"

namespace ultratrack::ins {
namespace {

constexpr double kDegPerHour = io::kRadPerSecPerDegPerHour;  // rad/s
constexpr double kDegPerSqrtHour = io::kRadPerDeg / 60.0;    // rad/sqrt(s)
constexpr double kG = 9.80665;
constexpr double kFoot = 0.3048;

ImuErrorSpec make_hg1700ae() {
  // Seed 000 Table 1 (1 sigma): gyro random bias 1 deg/h, white noise 80 urad, random walk 0.125 deg/sqrt(h);
  // accelerometer random bias 1 mg, white noise 0.008 ft/s, random walk 0.065 ft/s/sqrt(h).
  // The table gives no bias instability, scale factor or misalignment: those stay zero.
  ImuErrorSpec s;
  s.gyro.bias_sigma = 1.0 * kDegPerHour;
  s.gyro.output_white_noise = 80e-6;
  s.gyro.random_walk = 0.125 * kDegPerSqrtHour;
  s.accel.bias_sigma = 1e-3 * kG;
  s.accel.output_white_noise = 0.008 * kFoot;
  s.accel.random_walk = 0.065 * kFoot / 60.0;
  return s;
}

ImuErrorSpec make_dmu6x() {
  // Seed 003 Table 1: gyro bias +-1 deg/s, accelerometer bias +-10 mg (taken as 1 sigma). Noise, scale
  // factor and misalignment are typical values of that MEMS class (Crossbow DMU-6X data sheet order).
  ImuErrorSpec s;
  s.gyro.bias_sigma = 1.0 * io::kRadPerDeg;
  s.gyro.bias_instability_sigma = 0.01 * io::kRadPerDeg;
  s.gyro.bias_correlation_time_s = 300.0;
  s.gyro.random_walk = 2.25 * kDegPerSqrtHour;
  s.gyro.scale_factor_sigma = 0.01;
  s.gyro.misalignment_sigma = 1e-3;
  s.accel.bias_sigma = 10e-3 * kG;
  s.accel.bias_instability_sigma = 0.5e-3 * kG;
  s.accel.bias_correlation_time_s = 300.0;
  s.accel.random_walk = 0.15 / 60.0;
  s.accel.scale_factor_sigma = 0.01;
  s.accel.misalignment_sigma = 1e-3;
  return s;
}

ImuErrorSpec make_navigation() {
  // Navigation grade (issue 4): 0.01 deg/h gyro bias, 25 ug accelerometer bias; RLG-class noise.
  ImuErrorSpec s;
  s.gyro.bias_sigma = 0.01 * kDegPerHour;
  s.gyro.random_walk = 0.002 * kDegPerSqrtHour;
  s.gyro.scale_factor_sigma = 5e-6;
  s.gyro.misalignment_sigma = 5e-6;
  s.accel.bias_sigma = 25e-6 * kG;
  s.accel.random_walk = 0.002 / 60.0;
  s.accel.scale_factor_sigma = 50e-6;
  s.accel.misalignment_sigma = 5e-6;
  return s;
}

ImuErrorSpec make_mems() {
  // Consumer MEMS (smartphone class, factory calibrated): 0.5 deg/s and 30 mg turn-on biases,
  // 10 deg/h and 0.1 mg instabilities, 0.5 deg/sqrt(h) and 0.1 m/s/sqrt(h) random walks, 0.5 % scale factor.
  ImuErrorSpec s;
  s.gyro.bias_sigma = 0.5 * io::kRadPerDeg;
  s.gyro.bias_instability_sigma = 10.0 * kDegPerHour;
  s.gyro.bias_correlation_time_s = 100.0;
  s.gyro.random_walk = 0.5 * kDegPerSqrtHour;
  s.gyro.scale_factor_sigma = 5e-3;
  s.gyro.misalignment_sigma = 5e-3;
  s.gyro.quantum = 1e-5;
  s.accel.bias_sigma = 30e-3 * kG;
  s.accel.bias_instability_sigma = 0.1e-3 * kG;
  s.accel.bias_correlation_time_s = 100.0;
  s.accel.random_walk = 0.1 / 60.0;
  s.accel.scale_factor_sigma = 5e-3;
  s.accel.misalignment_sigma = 5e-3;
  s.accel.quantum = 1e-4;
  return s;
}

ImuErrorSpec make_datasheet(double gyro_bias_dps, double gyro_instability_dph, double arw_dpsh, double accel_bias_mg,
                            double accel_instability_mg, double vrw_mpspsh, double correlation_time_s) {
  ImuErrorSpec s;
  s.gyro.bias_sigma = gyro_bias_dps * io::kRadPerDeg;
  s.gyro.bias_instability_sigma = gyro_instability_dph * kDegPerHour;
  s.gyro.bias_correlation_time_s = correlation_time_s;
  s.gyro.random_walk = arw_dpsh * kDegPerSqrtHour;
  s.accel.bias_sigma = accel_bias_mg * 1e-3 * kG;
  s.accel.bias_instability_sigma = accel_instability_mg * 1e-3 * kG;
  s.accel.bias_correlation_time_s = correlation_time_s;
  s.accel.random_walk = vrw_mpspsh / 60.0;
  return s;
}

// Datasheet presets (docs/imu_models.md gives each value's source; turn-on biases are the datasheets' initial
// or repeatability figures taken as 1 sigma; in-run instability with the correlation time named there).
ImuErrorSpec
make_adis16405() {  // ADIS16405: 3 deg/s, 0.007 deg/s in run, 2 deg/sqrt(h); 50 mg, 0.2 mg, 0.2 m/s/sqrt(h)
  return make_datasheet(3.0, 0.007 * 3600.0, 2.0, 50.0, 0.2, 0.2, 100.0);
}
ImuErrorSpec make_adis16465() {  // ADIS16465-1: 2 deg/h in run, 0.15 deg/sqrt(h); 3.6 ug in run, 0.012 m/s/sqrt(h)
  return make_datasheet(0.2, 2.0, 0.15, 5.0, 3.6e-3, 0.012, 100.0);
}
ImuErrorSpec make_bmi088() {  // BMI088: 1 deg/s offset, 0.014 deg/s/sqrt(Hz); 20 mg offset, 175 ug/sqrt(Hz)
  return make_datasheet(1.0, 10.0, 0.014 * 60.0, 20.0, 0.1, 175e-6 * kG * 60.0, 100.0);
}
ImuErrorSpec make_stim300() {  // STIM300 (10 g): 4 deg/h repeatability, 0.5 deg/h, 0.15 deg/sqrt(h); 0.75 mg, 0.05 mg
  ImuErrorSpec s = make_datasheet(4.0 / 3600.0, 0.5, 0.15, 0.75, 0.05, 0.07, 3600.0);
  s.gyro.scale_factor_sigma = 500e-6;
  s.accel.scale_factor_sigma = 300e-6;
  s.gyro.misalignment_sigma = 1e-3;
  s.accel.misalignment_sigma = 1e-3;
  return s;
}

}  // namespace

const std::vector<std::string>& imu_preset_names() {
  static const std::vector<std::string> names{"ideal",     "hg1700ae",  "dmu6x",  "navigation", "mems",
                                              "adis16405", "adis16465", "bmi088", "stim300"};
  return names;
}

ImuErrorSpec imu_preset(std::string_view name) {
  if (name == "ideal") return ImuErrorSpec{};
  if (name == "hg1700ae") return make_hg1700ae();
  if (name == "dmu6x") return make_dmu6x();
  if (name == "navigation") return make_navigation();
  if (name == "mems") return make_mems();
  if (name == "adis16405") return make_adis16405();
  if (name == "adis16465") return make_adis16465();
  if (name == "bmi088") return make_bmi088();
  if (name == "stim300") return make_stim300();
  std::string known;
  for (const auto& n : imu_preset_names()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("imu preset", "unknown preset '" + std::string(name) + "' (known: " + known + ")");
}

ImuErrors draw_imu_errors(const ImuErrorSpec& spec, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto draw = [&](const SensorErrorSpec& s) {
    SensorErrors e;
    for (int i = 0; i < 3; ++i) e.bias[i] = s.bias_sigma * n(rng);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        e.scale_misalignment(i, j) = (i == j ? s.scale_factor_sigma : s.misalignment_sigma) * n(rng);
      }
    }
    return e;
  };
  ImuErrors e;
  e.gyro = draw(spec.gyro);
  e.accel = draw(spec.accel);
  return e;
}

ImuErrorModel::ImuErrorModel(const ImuErrorSpec& spec, std::uint64_t seed) : spec_(spec), rng_(seed) {
  errors_ = draw_imu_errors(spec_, rng_);
  start_gauss_markov();
}

ImuErrorModel::ImuErrorModel(const ImuErrorSpec& spec, const ImuErrors& turn_on, std::uint64_t seed)
    : spec_(spec), errors_(turn_on), rng_(seed) {
  start_gauss_markov();
}

void ImuErrorModel::start_gauss_markov() {  // in its stationary distribution from the first sample
  gm_gyro_ = spec_.gyro.bias_instability_sigma * gauss3();
  gm_accel_ = spec_.accel.bias_instability_sigma * gauss3();
}

Eigen::Vector3d ImuErrorModel::gauss3() { return {normal_(rng_), normal_(rng_), normal_(rng_)}; }

Eigen::Vector3d ImuErrorModel::corrupt(const SensorErrorSpec& s, const SensorErrors& e, Eigen::Vector3d& gm,
                                       Channel& ch, const Eigen::Vector3d& ideal, double dt) {
  Eigen::Vector3d out = ideal + e.scale_misalignment * ideal;
  if (s.bias_instability_sigma > 0.0) {  // exact discretisation of the first-order Gauss-Markov process
    const double phi = std::exp(-dt / s.bias_correlation_time_s);
    const Eigen::Vector3d gm_new = phi * gm + s.bias_instability_sigma * std::sqrt(1.0 - phi * phi) * gauss3();
    out += 0.5 * (gm + gm_new) * dt;
    gm = gm_new;
  }
  out += e.bias * dt;
  if (s.random_walk > 0.0) out += s.random_walk * std::sqrt(dt) * gauss3();
  if (s.output_white_noise > 0.0) {  // white noise on the accumulated output: the increment sees its difference
    const Eigen::Vector3d w = s.output_white_noise * gauss3();
    out += w - ch.prev_white;
    ch.prev_white = w;
  }
  if (s.quantum > 0.0) {  // the sensor outputs whole quanta and keeps the remainder for the next interval
    const Eigen::Vector3d total = out + ch.residual;
    for (int i = 0; i < 3; ++i) out[i] = std::round(total[i] / s.quantum) * s.quantum;
    ch.residual = total - out;
  }
  return out;
}

ImuIncrement ImuErrorModel::apply(const ImuIncrement& ideal, double dt_s) {
  ImuIncrement m;
  m.t_s = ideal.t_s;
  m.dtheta_b = corrupt(spec_.gyro, errors_.gyro, gm_gyro_, gyro_ch_, ideal.dtheta_b, dt_s);
  m.dv_b = corrupt(spec_.accel, errors_.accel, gm_accel_, accel_ch_, ideal.dv_b, dt_s);
  return m;
}

}  // namespace ultratrack::ins
