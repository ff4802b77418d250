// SPDX-License-Identifier: GPL-3.0-or-later
// Odometer (vehicle motion sensor, VMS) simulation from truth: wheel pulses counted over each output interval
// with every error [KimVMS]'s filter models: a scale-factor error (eq. 1: measured distance = (1 + sf) true
// distance), a time delay (the pulses of time t are those the wheel made at t - delay), pulse quantisation, and
// wheel slip / skid events (pulses scaled by 1 + ratio inside an event: -1 a locked wheel, > 0 a spinning one).
// The mounting misalignment (eqs. 2-10) is a rotation between the IMU body and the vehicle frame (x forward
// along the wheels' track, y right, z down; the frame where the non-holonomic constraints hold):
// C_bv = Rz(yaw) Ry(pitch), v_b = C_bv v_v. Units: m, s, rad.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "ins/trajectory_simulator.hpp"

namespace ultratrack::ins {

// A wheel slip (ratio > 0: the wheel turns faster than the vehicle moves) or skid (ratio < 0; -1 = locked).
struct OdometerSlip {
  double start_s = 0.0, duration_s = 0.0;
  double ratio = 0.0;  // pulses inside [start, start + duration) scaled by 1 + ratio (>= -1)
};

struct OdometerOptions {
  double rate_hz = 10.0;            // output rate (must divide the truth rate into whole samples)
  double meters_per_pulse = 0.02;   // nominal distance per pulse
  double scale_factor_error = 0.0;  // ratio, e.g. 0.01 = pulses 1 % too many
  double delay_s = 0.0;             // pulses lag the motion by this (>= 0)
  std::vector<OdometerSlip> slips;
};

// IMU body from vehicle frame for a mounting misalignment (pitch about the vehicle's y, yaw about its z).
Eigen::Matrix3d C_bv_from_misalignment(double pitch_rad, double yaw_rad);

struct OdometerSample {
  double t_s = 0.0;         // end of the counting interval
  std::int64_t pulses = 0;  // pulses over the interval
  double distance_m = 0.0;  // pulses * meters_per_pulse (what a user would take as distance)
};

// truth: samples at a uniform rate starting at t = 0 (as from simulate()).
std::vector<OdometerSample> simulate_odometer(std::span<const TruthSample> truth, const OdometerOptions& options);

}  // namespace ultratrack::ins
