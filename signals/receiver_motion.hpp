// SPDX-License-Identifier: GPL-3.0-or-later
// How the receiver's antennas move: the synthesiser asks for each antenna's ECEF (WGS-84) position (m) and
// velocity (m/s) at a true GPS time, given as seconds since the scenario start. Anything can drive it:
// a fixed point, a trajectory file (cubic Hermite through ECEF position/velocity samples), or later the
// INS trajectory simulator with body lever arms (tools/ adapts it; signals/ cannot see ins/).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

namespace ultratrack::signals {

struct AntennaState {
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();    // ECEF position of the antenna phase centre
  Eigen::Vector3d v_e_mps = Eigen::Vector3d::Zero();  // ECEF velocity
};

// The contract: antenna_state must be cheap (it is called once per antenna per millisecond of signal),
// must not throw for t_s in [0, duration], and must be smooth enough that position over 1 ms is well
// described by its endpoints (the synthesiser interpolates linearly between 1 ms nodes).
class ReceiverMotion {
 public:
  virtual ~ReceiverMotion() = default;
  virtual int antenna_count() const = 0;
  // t_s: true GPS time since the scenario start, seconds. antenna: 0 .. antenna_count()-1.
  virtual AntennaState antenna_state(int antenna, double t_s) const = 0;
};

// Antennas fixed to the earth at the given ECEF positions (one or more).
class StaticMotion final : public ReceiverMotion {
 public:
  explicit StaticMotion(std::vector<Eigen::Vector3d> r_e_m) : r_e_m_(std::move(r_e_m)) {}
  int antenna_count() const override { return static_cast<int>(r_e_m_.size()); }
  AntennaState antenna_state(int antenna, double) const override { return {r_e_m_[antenna], Eigen::Vector3d::Zero()}; }

 private:
  std::vector<Eigen::Vector3d> r_e_m_;
};

// One ECEF sample of a trajectory.
struct TrajectorySample {
  double t_s = 0.0;  // seconds since the scenario start (true GPS time)
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_e_mps = Eigen::Vector3d::Zero();
};

// A single antenna moving along sampled ECEF positions and velocities: cubic Hermite interpolation
// (position and velocity continuous; exact at the samples). Outside the samples it holds the end state
// extrapolated with the end velocity. Samples must be strictly increasing in time (checked by the reader).
class TrajectoryMotion final : public ReceiverMotion {
 public:
  explicit TrajectoryMotion(std::vector<TrajectorySample> samples);
  int antenna_count() const override { return 1; }
  AntennaState antenna_state(int antenna, double t_s) const override;
  double start_s() const { return samples_.front().t_s; }
  double end_s() const { return samples_.back().t_s; }

 private:
  std::vector<TrajectorySample> samples_;
};

// Reads a trajectory CSV: a header row, then rows of t_s, x, y, z (ECEF m), vx, vy, vz (ECEF m/s).
// Lines starting with '#' are comments. Throws InputError (file, line) on malformed rows, fewer than 2
// rows, times not strictly increasing, or a sample interval longer than 0.1 s (the 10 Hz minimum).
std::vector<TrajectorySample> read_trajectory_csv(const std::filesystem::path& path);

}  // namespace ultratrack::signals
