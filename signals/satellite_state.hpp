// SPDX-License-Identifier: GPL-3.0-or-later
// Satellite position, velocity and clock from the broadcast ephemeris (IS-GPS-200 Table 20-IV),
// and the Sagnac-corrected geometric range. Frames: ECEF (WGS-84) at the instant named in each function.
#pragma once

#include <Eigen/Core>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::signals {

struct SatelliteState {
  Eigen::Vector3d r_e_m = Eigen::Vector3d::Zero();    // ECEF position at transmit time, ECEF axes of that time
  Eigen::Vector3d v_e_mps = Eigen::Vector3d::Zero();  // ECEF velocity (includes the earth-rotation term)
  double clock_bias_s = 0.0;                          // af0 + af1 dt + af2 dt^2 + relativistic term (TGD not included)
  double clock_drift_sps = 0.0;                       // af1 + 2 af2 dt + d(relativistic)/dt
  double relativistic_s = 0.0;                        // F e sqrt(A) sin(E_k), already in clock_bias_s
  double tgd_s = 0.0;                                 // copied from the ephemeris; an L1 C/A user subtracts it
};

// State at GPS system time t (the satellite's transmit time, corrected for the SV clock by the caller
// when it matters). Kepler's equation is iterated until |dE| < 1e-12 rad.
SatelliteState satellite_state(const Ephemeris& eph, const GpsTime& t);

// The SV clock offset (af polynomial + relativistic - TGD: what an L1 C/A user applies) at time t.
double l1_ca_clock_correction_s(const Ephemeris& eph, const GpsTime& t);

// Rotates a satellite position given in the ECEF frame of its transmit time into the ECEF frame of the
// receive time, travel_time_s later (the Sagnac / earth-rotation correction).
Eigen::Vector3d rotate_to_receive_frame(const Eigen::Vector3d& r_e_transmit, double travel_time_s);

// Geometric range from the satellite (position at transmit time, transmit-time ECEF) to the receiver
// (position at receive time, receive-time ECEF), Sagnac included; travel time iterated internally.
double geometric_range_m(const Eigen::Vector3d& r_sat_e_transmit, const Eigen::Vector3d& r_rx_e_receive);

}  // namespace ultratrack::signals
