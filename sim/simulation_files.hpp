// SPDX-License-Identifier: GPL-3.0-or-later
// The files of `ultratrack simulate` in a folder, written by a SimulationSink; every file under a temporary name,
// renamed when complete (io::AtomicFile), also after a stop (summary.json then says "interrupted": true).
//   antenna<k>.<format>.bin  one per antenna, sample-synchronous (signals/sample_writer.hpp)
//   truth.csv       t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,
//                   vel_d_mps,clock_bias_m,clock_drift_mps[,roll_deg,pitch_deg,yaw_deg]: antenna 0, or with
//                   [trajectory] the IMU (body origin) and its attitude (body to NED, z-y-x)
//   satellites.csv  prn,elevation_deg,azimuth_deg,cn0_dbhz,doppler_hz,code_phase_chips at the first sample
//   satellite_truth.csv  sample,t_s,prn,cn0_dbhz,doppler_hz,code_phase_chips of every satellite transmitted, at the
//                   truth rows (antenna 0; code phase at that sample, [0, 1023); Doppler includes the clock drift)
//   imu.csv         ins/imu_csv.hpp columns, increments ending at t_s (trajectory time = GPS time since the start)
//   antenna_truth.csv  t_s,antenna,ecef_x_m,...,vel_z_mps of every antenna at the truth rows ([trajectory])
//   odometer.csv    t_s,pulses,distance_m ([trajectory] odometer = true)
//   antenna_events.csv  kind,antenna,prn,start_s,end_s,cycles (scenarios with [[cycle_slip]] or [[blockage]])
//   cn0_steps.csv   antenna,prn,start_s,first_sample,first_sample_s,cn0_dbhz (scenarios with [[cn0_step]])
//   scenario.toml   the scenario as run (the text the caller gives: TOML is the tools' business)
//   summary.json    the run: navigation, sample files, satellites in view, noise sigma, IMU turn-on biases
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <stop_token>
#include <string>
#include <vector>

#include "ins/imu_error_model.hpp"
#include "ins/odometer.hpp"
#include "sim/simulation.hpp"

namespace ultratrack::ins {
class ImuCsvWriter;
}
namespace ultratrack::signals {
class SampleWriter;
}

namespace ultratrack::sim {

class SimulationFiles : public SimulationSink {
 public:
  // Creates out_dir (InputError when it cannot). scenario_echo: the text of scenario.toml. progress: optional.
  SimulationFiles(const Scenario& scenario, std::filesystem::path out_dir, std::string scenario_echo,
                  std::function<void(const SimulationProgress&)> progress = {});
  ~SimulationFiles() override;

  void begin(const SimulationShape& shape) override;
  void imu(const ins::ImuIncrement& increment) override;
  void odometer(std::span<const ins::OdometerSample> samples) override;
  void satellites(std::span<const signals::SatelliteView> in_view) override;
  void events(std::span<const AntennaEventRow> events, std::span<const Cn0StepRow> steps) override;
  void truth(const TruthRow& row) override;
  void antenna_truth(const AntennaTruthRow& row) override;
  void satellite_truth(std::int64_t sample, double t_s, std::span<const signals::SatelliteView> in_view) override;
  void samples(int antenna, std::span<const std::complex<float>> block) override;
  void progress(const SimulationProgress& progress) override;
  void finish(const SimulationResult& result) override;

  const std::vector<std::filesystem::path>& sample_files() const { return sample_files_; }

 private:
  std::string summary_json(const SimulationResult& result) const;
  std::string inertial_summary(const SimulationResult& result) const;

  const Scenario& scenario_;
  std::filesystem::path out_dir_;
  std::string scenario_echo_;
  std::function<void(const SimulationProgress&)> progress_;
  SimulationShape shape_;
  std::vector<std::filesystem::path> sample_files_;
  std::vector<std::unique_ptr<signals::SampleWriter>> writers_;
  std::unique_ptr<ins::ImuCsvWriter> imu_;
  std::string truth_, antenna_truth_, satellites_, satellite_truth_, events_, cn0_steps_;
};

// simulate() into out_dir through SimulationFiles; the result lists the sample files.
SimulationResult simulate_to_folder(const Scenario& scenario, const std::filesystem::path& out_dir,
                                    const std::string& scenario_echo, std::stop_token stop = {},
                                    std::function<void(const SimulationProgress&)> progress = {});

// odometer.csv (`t_s,pulses,distance_m`), atomically.
void write_odometer_csv(const std::filesystem::path& file, std::span<const ins::OdometerSample> samples);

// JSON members (no braces, trailing comma) with the turn-on biases: deg/h and m/s^2.
std::string turn_on_bias_json(const ins::ImuErrors& errors);

}  // namespace ultratrack::sim
