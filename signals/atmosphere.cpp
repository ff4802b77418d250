// SPDX-License-Identifier: GPL-3.0-or-later
// Klobuchar (IS-GPS-200 20.3.3.5.2.5, Figure 20-4) and Saastamoinen troposphere with a standard atmosphere.
#include "signals/atmosphere.hpp"

#include <algorithm>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals {

double klobuchar_delay_s(const KlobucharParameters& params, double lat_rad, double lon_rad, double azimuth_rad,
                         double elevation_rad, double tow_s) {
  if (!params.valid) return 0.0;
  // The algorithm works in semicircles (with the IS-GPS-200 value of pi).
  const double E = elevation_rad / kPi;
  const double phi_u = lat_rad / kPi;
  const double lambda_u = lon_rad / kPi;
  const double psi = 0.0137 / (E + 0.11) - 0.022;  // earth-centred angle to the pierce point
  const double phi_i = std::clamp(phi_u + psi * std::cos(azimuth_rad), -0.416, 0.416);
  const double lambda_i = lambda_u + psi * std::sin(azimuth_rad) / std::cos(phi_i * kPi);
  const double phi_m = phi_i + 0.064 * std::cos((lambda_i - 1.617) * kPi);  // geomagnetic latitude
  double t = std::fmod(4.32e4 * lambda_i + tow_s, 86400.0);                 // local time at the pierce point
  if (t < 0.0) t += 86400.0;
  const double F = 1.0 + 16.0 * std::pow(0.53 - E, 3);  // obliquity factor
  double amp = 0.0, per = 0.0, phi_n = 1.0;
  for (int n = 0; n < 4; ++n) {
    amp += params.alpha[n] * phi_n;
    per += params.beta[n] * phi_n;
    phi_n *= phi_m;
  }
  amp = std::max(amp, 0.0);
  per = std::max(per, 72000.0);
  const double x = 2.0 * kPi * (t - 50400.0) / per;  // phase, radians
  if (std::abs(x) >= 1.57) return F * 5e-9;
  const double x2 = x * x;
  return F * (5e-9 + amp * (1.0 - x2 / 2.0 + x2 * x2 / 24.0));
}

double troposphere_delay_m(double lat_rad, double height_m, double elevation_rad) {
  // Standard atmosphere from the height (the model RTKLIB and many receivers use): pressure by the
  // barometric formula from 1013.25 hPa, temperature 15 C at sea level with a -6.5 K/km lapse rate
  // (floored at the 216.65 K tropopause), relative humidity 50 %. Heights are clamped to the range where
  // the pressure formula stays positive.
  const double h = std::clamp(height_m, -500.0, 44000.0);
  const double pressure_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h, 5.2568);
  const double temperature_k = std::max(288.15 - 6.5e-3 * h, 216.65);
  constexpr double kRelativeHumidity = 0.5;
  // Partial pressure of water vapour (hPa) from the saturation pressure at the temperature.
  const double e_hpa = 6.108 * kRelativeHumidity * std::exp((17.15 * temperature_k - 4684.0) / (temperature_k - 38.45));
  // Saastamoinen zenith delays: hydrostatic with the gravity correction for latitude and height, wet.
  const double zhd_m = 0.0022768 * pressure_hpa / (1.0 - 0.00266 * std::cos(2.0 * lat_rad) - 0.00028 * h / 1000.0);
  const double zwd_m = 0.002277 * (1255.0 / temperature_k + 0.05) * e_hpa;
  // Mapping to the elevation: 1/sin(el) with a curvature term that keeps it finite at the horizon
  // (1.001 / sqrt(0.002001 + sin^2 el), the RTCA DO-229 form).
  const double s = std::sin(elevation_rad);
  const double mapping = 1.001 / std::sqrt(0.002001 + s * s);
  return (zhd_m + zwd_m) * mapping;
}

}  // namespace ultratrack::signals
