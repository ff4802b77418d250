// SPDX-License-Identifier: GPL-3.0-or-later
// Trajectory description: a start state and a list of segments (duration, along-track acceleration,
// turn rate, climb rate, road grade). Commands change smoothly (quintic blend over ramp_s) at segment
// starts, so body rates and specific force are continuous. Named profiles of [ChoUKF] plus a land vehicle.
// Units: SI (rad, m, s); headings from north towards east.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace ultratrack::ins {

struct Segment {
  double duration_s = 0.0;
  double accel_mps2 = 0.0;      // rate of change of horizontal speed
  double turn_rate_rps = 0.0;   // heading rate (positive: turning right, towards east from north)
  double climb_rate_mps = 0.0;  // vertical speed added to the grade's (up positive)
  double grade_rad = 0.0;       // road slope: vertical speed speed * tan(grade), pitch = grade
};

// A platform vibration tone (engine, road, rotor) the whole body carries, IMU and antennas alike: the position moves
// by d_n(t) = -(a / w^2) sin(w t + phase), w = 2 pi frequency_hz, in the local level frame (north, east, down: a the
// peak linear accelerations), so that velocity and specific force carry its exact derivatives; roll, pitch and yaw
// gain angle_amplitude sin(w t + phase). The ideal IMU, the truth and the antennas' motion carry it consistently
// (ins/trajectory_simulator.hpp). The path length (odometer) does not.
struct Vibration {
  double frequency_hz = 0.0;
  std::array<double, 3> accel_amplitude_n_mps2{};  // peak, north east down
  std::array<double, 3> angle_amplitude_rad{};     // peak, roll pitch yaw
  double phase_rad = 0.0;
};

struct TrajectorySpec {
  double lat0_rad = 0.0;
  double lon0_rad = 0.0;
  double height0_m = 0.0;
  double speed0_mps = 0.0;  // initial horizontal speed
  double heading0_rad = 0.0;
  bool coordinated_turns = false;  // bank into turns (roll = atan(speed * turn_rate / g0)), aircraft-like
  double ramp_s = 1.0;             // command blend time at each segment start (capped at half the segment)
  double roll0_rad = 0.0;          // constant roll and pitch added to the attitude (a vehicle parked on a
  double pitch0_rad = 0.0;         // slope, an IMU mounted tilted); |pitch| well below 90 deg
  std::vector<Segment> segments;
  std::vector<Vibration> vibrations;  // none: a smooth ride

  double duration_s() const;
};

// Names accepted by profile_spec.
const std::vector<std::string>& profile_names();

// The named profile (`static`, `straight`, `circle`, `s`, `spiral`, `land`) lasting duration_s, starting
// at the given position. Throws InputError (file "profile") for an unknown name or non-positive duration.
//   static: at rest, level, heading 0;  straight: from rest, 1 m/s^2 north;
//   circle: 500 km/h turning pi/100 rad/s (coordinated);  s: as circle, the turn reverses every 100 s;
//   spiral: circle climbing 0.2 m/s;  land: car-like cycle of stops, 0-30 m/s, turns and hills.
TrajectorySpec profile_spec(std::string_view name, double duration_s, double lat0_rad, double lon0_rad,
                            double height0_m);

// Segments from a CSV file with the header `duration_s,accel_mps2,turn_rate_dps,climb_rate_mps,grade_deg`
// (blank lines and lines starting with '#' are skipped). The start state comes from `start`.
// Throws InputError naming the file and line for malformed input.
TrajectorySpec read_segments_csv(const std::filesystem::path& file, const TrajectorySpec& start);

}  // namespace ultratrack::ins
