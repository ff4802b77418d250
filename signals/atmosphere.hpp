// SPDX-License-Identifier: GPL-3.0-or-later
// Signal delays through the atmosphere, shared by the synthesiser and the receiver so both use the same
// model: the broadcast Klobuchar ionosphere (IS-GPS-200 20.3.3.5.2.5, L1) and a standard troposphere
// (Saastamoinen zenith delays with a standard atmosphere and a simple elevation mapping).
// Angles in radians, delays in seconds (ionosphere) or metres (troposphere).
#pragma once

#include "signals/ephemeris.hpp"

namespace ultratrack::signals {

// L1 ionospheric group delay in seconds at the receiver (lat, lon geodetic), satellite azimuth/elevation,
// and GPS time of week. Returns 0 when params.valid is false.
double klobuchar_delay_s(const KlobucharParameters& params, double lat_rad, double lon_rad, double azimuth_rad,
                         double elevation_rad, double tow_s);

// Tropospheric delay in metres for a receiver at geodetic latitude / ellipsoidal height and a satellite
// at the given elevation. Zero below the horizon is not modelled: callers mask low satellites.
double troposphere_delay_m(double lat_rad, double height_m, double elevation_rad);

}  // namespace ultratrack::signals
