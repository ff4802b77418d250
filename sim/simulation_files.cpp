// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/simulation_files.hpp"

#include <fmt/core.h>
#include <fmt/format.h>

#include <GeographicLib/Geocentric.hpp>
#include <algorithm>
#include <numbers>

#include "ins/attitude.hpp"
#include "ins/imu_csv.hpp"
#include "io/atomic_file.hpp"
#include "io/input_error.hpp"
#include "io/json_text.hpp"
#include "io/units.hpp"
#include "signals/sample_writer.hpp"
#include "sim/local_frame.hpp"

namespace ultratrack::sim {
namespace {

const char* const kTruthHeader =
    "t_s,gps_week,tow_s,ecef_x_m,ecef_y_m,ecef_z_m,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,"
    "clock_bias_m,clock_drift_mps";

// One truth.csv row: t_s on its line, true GPS time, position/velocity, clock, attitude when known.
std::string truth_line(const TruthRow& r) {
  double lat = 0, lon = 0, h = 0;
  GeographicLib::Geocentric::WGS84().Reverse(r.r_e_m.x(), r.r_e_m.y(), r.r_e_m.z(), lat, lon, h);
  const Eigen::Vector3d v_n = ned_from_ecef(lat * io::kRadPerDeg, lon * io::kRadPerDeg) * r.v_e_mps;
  std::string row =
      fmt::format("{:.9f},{},{:.9f},{:.4f},{:.4f},{:.4f},{:.10f},{:.10f},{:.4f},{:.5f},{:.5f},{:.5f},{:.5f},{:.6f}",
                  r.t_s, r.gps.week, r.gps.tow_s, r.r_e_m.x(), r.r_e_m.y(), r.r_e_m.z(), lat, lon, h, v_n.x(), v_n.y(),
                  v_n.z(), r.clock_bias_m, r.clock_drift_mps);
  if (r.q_nb) {
    const ins::EulerAngles e = ins::euler_from_quaternion(*r.q_nb);
    row += fmt::format(",{:.8f},{:.8f},{:.8f}", e.roll_rad / io::kRadPerDeg, e.pitch_rad / io::kRadPerDeg,
                       e.yaw_rad / io::kRadPerDeg);
  }
  return row + "\n";
}

}  // namespace

SimulationFiles::SimulationFiles(const Scenario& scenario, std::filesystem::path out_dir, std::string scenario_echo,
                                 std::function<void(const SimulationProgress&)> progress)
    : scenario_(scenario),
      out_dir_(std::move(out_dir)),
      scenario_echo_(std::move(scenario_echo)),
      progress_(std::move(progress)) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir_, ec);
  if (ec) throw io::InputError(out_dir_.string(), "cannot create the output folder: " + ec.message());
}

SimulationFiles::~SimulationFiles() = default;

void SimulationFiles::begin(const SimulationShape& shape) {
  shape_ = shape;
  for (int a = 0; a < shape.antennas; ++a) {
    const auto path = out_dir_ / fmt::format("antenna{}.{}.bin", a, signals::to_string(scenario_.format));
    writers_.push_back(std::make_unique<signals::SampleWriter>(path, scenario_.format, scenario_.two_bit));
    sample_files_.push_back(path);
  }
  if (shape.inertial) imu_ = std::make_unique<ins::ImuCsvWriter>(out_dir_ / "imu.csv");
  truth_ = std::string(kTruthHeader) + (shape.inertial ? ",roll_deg,pitch_deg,yaw_deg\n" : "\n");
  antenna_truth_ = "t_s,antenna,ecef_x_m,ecef_y_m,ecef_z_m,vel_x_mps,vel_y_mps,vel_z_mps\n";
}

void SimulationFiles::imu(const ins::ImuIncrement& increment) { imu_->write(increment); }

void SimulationFiles::odometer(std::span<const ins::OdometerSample> samples) {
  write_odometer_csv(out_dir_ / "odometer.csv", samples);
}

void SimulationFiles::satellites(std::span<const signals::SatelliteView> in_view) {
  satellites_ = "prn,elevation_deg,azimuth_deg,cn0_dbhz,doppler_hz,code_phase_chips\n";
  for (const auto& v : in_view) {
    satellites_ += fmt::format("{},{:.4f},{:.4f},{:.2f},{:.4f},{:.6f}\n", v.prn, v.elevation_rad / io::kRadPerDeg,
                               v.azimuth_rad / io::kRadPerDeg, v.cn0_dbhz, v.doppler_hz, v.code_phase_chips);
  }
}

void SimulationFiles::events(std::span<const AntennaEventRow> events, std::span<const Cn0StepRow> steps) {
  events_ = "kind,antenna,prn,start_s,end_s,cycles\n";
  for (const auto& e : events)
    events_ += fmt::format("{},{},{},{},{},{}\n", e.kind, e.antenna, e.prn, e.start_s, e.end_s, e.cycles);
  cn0_steps_ = "antenna,prn,start_s,first_sample,first_sample_s,cn0_dbhz\n";
  for (const auto& c : steps)
    cn0_steps_ += fmt::format("{},{},{},{},{:.9f},{}\n", c.antenna, c.prn, c.start_s, c.first_sample, c.first_sample_s,
                              c.cn0_dbhz);
}

void SimulationFiles::truth(const TruthRow& row) { truth_ += truth_line(row); }

void SimulationFiles::antenna_truth(const AntennaTruthRow& r) {
  antenna_truth_ += fmt::format("{:.9f},{},{:.4f},{:.4f},{:.4f},{:.5f},{:.5f},{:.5f}\n", r.t_s, r.antenna, r.r_e_m.x(),
                                r.r_e_m.y(), r.r_e_m.z(), r.v_e_mps.x(), r.v_e_mps.y(), r.v_e_mps.z());
}

void SimulationFiles::satellite_truth(std::int64_t sample, double t_s,
                                      std::span<const signals::SatelliteView> in_view) {
  for (const auto& v : in_view)
    satellite_truth_ += fmt::format("{},{:.9f},{},{:.2f},{:.4f},{:.6f}\n", sample, t_s, v.prn, v.cn0_dbhz, v.doppler_hz,
                                    v.code_phase_chips);
}

void SimulationFiles::samples(int antenna, std::span<const std::complex<float>> block) {
  writers_[static_cast<std::size_t>(antenna)]->write(block);
}

void SimulationFiles::progress(const SimulationProgress& progress) {
  if (progress_) progress_(progress);
}

void SimulationFiles::finish(const SimulationResult& result) {
  if (imu_) imu_->commit();
  for (auto& w : writers_) w->finish();
  io::write_file_atomically(out_dir_ / "truth.csv", truth_);
  if (scenario_.signal) {
    if (shape_.inertial) io::write_file_atomically(out_dir_ / "antenna_truth.csv", antenna_truth_);
    io::write_file_atomically(out_dir_ / "satellites.csv", satellites_);
    io::write_file_atomically(out_dir_ / "satellite_truth.csv",
                              "sample,t_s,prn,cn0_dbhz,doppler_hz,code_phase_chips\n" + satellite_truth_);
  }
  io::write_file_atomically(out_dir_ / "scenario.toml", scenario_echo_);
  if (!scenario_.cycle_slips.empty() || !scenario_.blockages.empty())
    io::write_file_atomically(out_dir_ / "antenna_events.csv", events_);
  if (!scenario_.cn0_steps.empty()) io::write_file_atomically(out_dir_ / "cn0_steps.csv", cn0_steps_);
  io::write_file_atomically(out_dir_ / "summary.json", summary_json(result));
}

std::string SimulationFiles::inertial_summary(const SimulationResult& r) const {
  const Scenario& s = scenario_;
  std::string levers;
  for (const auto& l : s.lever_arms_body_m)
    levers += fmt::format("{}[{}, {}, {}]", levers.empty() ? "" : ", ", l[0], l[1], l[2]);
  return fmt::format(
             "  \"trajectory\": \"{}\",\n  \"trajectory_duration_s\": {},\n  \"imu_rate_hz\": {},\n"
             "  \"imu_rows\": {},\n  \"imu_preset\": \"{}\",\n  \"imu_seed\": {},\n",
             io::json_escape(s.trajectory_profile.empty() ? s.trajectory_file : s.trajectory_profile),
             r.trajectory_duration_s, s.imu_rate_hz, r.imu_rows, io::json_escape(s.imu_preset), s.imu_seed) +
         turn_on_bias_json(r.imu_turn_on) +
         fmt::format("  \"lever_arms_body_m\": [{}],\n  \"distance_m\": {:.3f},\n  \"odometer\": {},\n", levers,
                     r.distance_m, s.odometer);
}

std::string SimulationFiles::summary_json(const SimulationResult& r) const {
  const Scenario& s = scenario_;
  const std::string scenario_name = io::json_escape(s.source.filename().string());
  if (!s.signal) {
    return fmt::format("{{\n  \"command\": \"simulate\",\n  \"scenario\": \"{}\",\n  \"signal\": false,\n",
                       scenario_name) +
           inertial_summary(r) +
           fmt::format("  \"truth_rows\": {},\n  \"wall_s\": {:.3f}\n}}\n", r.truth_rows, r.wall_s);
  }
  std::string prns, files;
  for (const auto& v : r.satellites) prns += fmt::format("{}{}", prns.empty() ? "" : ", ", v.prn);
  for (const auto& f : sample_files_)
    files += fmt::format("{}\"{}\"", files.empty() ? "" : ", ", io::json_escape(f.filename().string()));
  return fmt::format("{{\n  \"command\": \"simulate\",\n  \"scenario\": \"{}\",\n  \"navigation\": \"{}\",\n",
                     scenario_name, io::json_escape(std::filesystem::path(r.navigation).filename().string())) +
         (shape_.inertial ? inertial_summary(r) : std::string()) +
         fmt::format(
             "  \"sample_rate_hz\": {},\n  \"if_hz\": {},\n  \"format\": \"{}\",\n  \"antennas\": {},\n"
             "  \"sample_files\": [{}],\n  \"samples_per_antenna\": {},\n  \"signal_s\": {},\n"
             "  \"satellites_in_view\": [{}],\n  \"noise_sigma_per_component\": {},\n  \"interrupted\": {},\n"
             "  \"wall_s\": {:.3f},\n  \"realtime_factor\": {:.3f}\n}}\n",
             s.sample_rate_hz, s.if_hz, signals::to_string(s.format), r.antennas, files, r.samples, r.signal_s, prns,
             r.noise_sigma, r.interrupted, r.wall_s, r.signal_s / std::max(r.wall_s, 1e-9));
}

SimulationResult simulate_to_folder(const Scenario& scenario, const std::filesystem::path& out_dir,
                                    const std::string& scenario_echo, std::stop_token stop,
                                    std::function<void(const SimulationProgress&)> progress) {
  SimulationFiles files(scenario, out_dir, scenario_echo, std::move(progress));
  SimulationResult result = simulate(scenario, files, std::move(stop));
  result.sample_files = files.sample_files();
  return result;
}

void write_odometer_csv(const std::filesystem::path& file, std::span<const ins::OdometerSample> samples) {
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

}  // namespace ultratrack::sim
