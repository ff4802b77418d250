// Odometer (vehicle motion sensor) simulation from truth: wheel pulses counted over each output interval,
// with a scale-factor error (seed 004 eq. 1: measured distance = (1 + sf) true distance) and pulse
// quantisation. Units: m, s.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "ins/trajectory_simulator.hpp"

namespace ultratrack::ins {

struct OdometerOptions {
  double rate_hz = 10.0;            // output rate (must divide the truth rate into whole samples)
  double meters_per_pulse = 0.02;   // nominal distance per pulse
  double scale_factor_error = 0.0;  // ratio, e.g. 0.01 = pulses 1 % too many
};

struct OdometerSample {
  double t_s = 0.0;         // end of the counting interval
  std::int64_t pulses = 0;  // pulses over the interval
  double distance_m = 0.0;  // pulses * meters_per_pulse (what a user would take as distance)
};

// truth: samples at a uniform rate starting at t = 0 (as from simulate()).
std::vector<OdometerSample> simulate_odometer(std::span<const TruthSample> truth, const OdometerOptions& options);

}  // namespace ultratrack::ins
