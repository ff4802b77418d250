// Runs a scenario through the IF synthesiser and writes the outputs of `ultratrack simulate` into a folder:
// antenna<k>.<format>.bin (one per antenna, sample-synchronous), truth.csv (receiver truth at the truth
// rate), satellites.csv (what the receiver should find at the first sample), scenario.toml (as run) and
// summary.json. Every file is written under a temporary name and renamed when complete; Ctrl-C stops the
// run early and still finishes the files (summary.json says "interrupted": true).
//
// truth.csv: t_s is receiver time (sample index / fs); gps_week, tow_s the true GPS time of that sample;
// position/velocity of antenna 0 (ECEF and geodetic, NED velocity); clock_bias_m = c * (receiver clock -
// GPS time), clock_drift_mps its rate. satellites.csv: doppler_hz as the receiver sees it (receiver
// clock drift included, IF removed), code_phase_chips the chip received at sample 0, in [0, 1023).
//
// With [trajectory] (an inertial scenario) one trajectory drives everything: DIR/imu.csv (ins/imu_csv.hpp
// columns, increments ending at t_s, trajectory time = true GPS time since the [time] start, errors from
// the [imu] preset and seed), the antennas (InsTruthMotion: IMU position + C_en C_nb lever arm) and
// truth.csv, whose position and velocity are then the IMU's (body origin, not an antenna) and which gains
// roll_deg,pitch_deg,yaw_deg (body to NED, z-y-x). antenna_truth.csv: t_s, antenna, ECEF position and
// velocity of every antenna at the truth rows. DIR/odometer.csv when [trajectory] odometer = true.
// antenna_events.csv (scenarios with [[cycle_slip]] or [[blockage]]): kind,antenna,prn,start_s,end_s,cycles, the
// injected events (prn 0 = all satellites; end_s = when the signal is back), for detection tests.
// cn0_steps.csv (scenarios with [[cn0_step]]): antenna,prn,start_s,first_sample,first_sample_s,cn0_dbhz, one row
// per step and transmitted satellite it applies to (below the mask too), in the scenario's order.
// Without [signal] there is no receiver: truth.csv's t_s is the GPS time since the start, its clock columns
// the deterministic clock model (bias + drift t), and no sample, satellite or antenna file is written.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "ins/imu_error_model.hpp"
#include "ins/trajectory.hpp"
#include "ins/truth_interpolator.hpp"
#include "scenario.hpp"
#include "signals/ephemeris.hpp"
#include "signals/if_synthesiser.hpp"
#include "signals/receiver_motion.hpp"

namespace ultratrack::tools {

// Broadcast data for a scenario: one ephemeris per PRN selected for the start time (healthy only unless
// the scenario includes unhealthy ones), ionosphere and UTC parameters.
struct NavigationSource {
  std::string name;  // the RINEX file or "nominal"
  std::vector<signals::Ephemeris> ephemerides;
  signals::KlobucharParameters klobuchar;
  signals::UtcParameters utc;
};

NavigationSource load_navigation(const Scenario& scenario);
// The antennas' motion: InsTruthMotion on `truth` with the scenario's lever arms for an inertial scenario
// (truth required then), else the static position(s) or the trajectory file.
std::shared_ptr<const signals::ReceiverMotion> make_motion(
    const Scenario& scenario, std::shared_ptr<const ins::TruthInterpolator> truth = nullptr);
// The trajectory and IMU errors of an inertial scenario (InputError naming the scenario file).
ins::TrajectorySpec trajectory_spec(const Scenario& scenario);
ins::ImuErrorSpec imu_error_spec(const Scenario& scenario);
// Throws InputError naming the scenario file when the options are not usable.
signals::SynthesiserOptions synthesiser_options(const Scenario& scenario, const NavigationSource& nav);

struct SimulationResult {
  std::vector<std::filesystem::path> sample_files;
  std::vector<signals::SatelliteView> satellites;  // in view at the first sample
  std::int64_t samples = 0;                        // per antenna
  double signal_s = 0.0;
  double wall_s = 0.0;
  double noise_sigma = 0.0;  // per output component, output units
  bool interrupted = false;
  std::size_t imu_rows = 0;  // inertial scenarios
  std::size_t truth_rows = 0;
};

// progress: where to print progress lines (nullptr: silent).
SimulationResult run_simulation(const Scenario& scenario, const std::filesystem::path& out_dir,
                                std::FILE* progress = nullptr);

}  // namespace ultratrack::tools
