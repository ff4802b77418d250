// SPDX-License-Identifier: GPL-3.0-or-later
// The nominal 24-slot constellation as broadcast ephemerides.
//
// Slots: GPS SPS Performance Standard (4th ed., 2001) Table 3-1, "Reference Orbit Slot Assignments as of
// the Defined Epoch": RAAN and argument of latitude per slot at 1993-07-01 00:00 UTC, Greenwich hour angle
// 18h36m14.4s. (D3's argument of latitude is 35.156 deg in the SPS PS text; a textbook reproduction prints
// 35.136.) The geometry is carried to the requested time as a repeating ground track: the node moves in
// earth-fixed longitude at (OMEGA_DOT - omega_e) and the argument of latitude at twice (omega_e -
// OMEGA_DOT), so the earth-fixed constellation repeats every 2 pi / (omega_e - OMEGA_DOT) (~1 sidereal
// day), as the control segment keeps it. A = 26559.7 km exactly; delta_n makes the mean motion match.
// Eccentricities are small (0.0005-0.0025, deterministic per PRN), so the true argument of latitude is
// within 2e rad (< 0.3 deg) of the slot's.
#include "signals/nominal_constellation.hpp"

#include <array>
#include <cmath>

#include "signals/gps_constants.hpp"

namespace ultratrack::signals {
namespace {

struct Slot {
  const char* name;
  double raan_deg;
  double arg_lat_deg;
};

constexpr std::array<Slot, 24> kSlots = {{
    {"A1", 272.847, 268.126}, {"A2", 272.847, 161.786}, {"A3", 272.847, 11.676},  {"A4", 272.847, 41.806},
    {"B1", 332.847, 80.956},  {"B2", 332.847, 173.336}, {"B3", 332.847, 309.976}, {"B4", 332.847, 204.376},
    {"C1", 32.847, 111.876},  {"C2", 32.847, 11.796},   {"C3", 32.847, 339.666},  {"C4", 32.847, 241.556},
    {"D1", 92.847, 135.226},  {"D2", 92.847, 265.446},  {"D3", 92.847, 35.156},   {"D4", 92.847, 167.356},
    {"E1", 152.847, 197.046}, {"E2", 152.847, 302.596}, {"E3", 152.847, 66.066},  {"E4", 152.847, 333.686},
    {"F1", 212.847, 238.886}, {"F2", 212.847, 345.226}, {"F3", 212.847, 105.206}, {"F4", 212.847, 135.346},
}};

constexpr double kDeg = kPi / 180.0;
constexpr double kSemiMajorAxis_m = 26559.7e3;
constexpr double kInclination_rad = 55.0 * kDeg;
// Nodal regression of the SPS PS almanac (-4.4874e-7 deg/s).
constexpr double kOmegaDot_radps = -4.4874e-7 * kDeg;
constexpr double kGreenwichHourAngleAtEpoch_rad = (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0 * kDeg;
constexpr double kTwoPi = 2.0 * kPi;

double wrap_two_pi(double a) {
  a = std::fmod(a, kTwoPi);
  return a < 0.0 ? a + kTwoPi : a;
}

// Broadcast angles are given in [-pi, pi).
double wrap_pi(double a) { return wrap_two_pi(a + kPi) - kPi; }

}  // namespace

NominalConstellation nominal_constellation(const GpsTime& t_in) {
  const GpsTime t = normalised(t_in);
  // toe: the multiple of 7200 s nearest to t (it may fall in the next week).
  const GpsTime toe = normalised({t.week, std::round(t.tow_s / 7200.0) * 7200.0});
  // Defined epoch 1993-07-01 00:00 UTC; GPS - UTC was 9 s from that instant.
  const GpsTime epoch = gps_time_from_utc({1993, 7, 1, 0, 0, 0.0}, 9);
  const double node_rate_ecef = kOmegaDot_radps - kEarthRotationRate_radps;  // rad/s, negative
  const double repeat_s = kTwoPi / -node_rate_ecef;
  const double dt = std::fmod(seconds_between(toe, epoch), repeat_s);  // same geometry as the full span
  const double n = 2.0 * -node_rate_ecef;                              // argument-of-latitude rate
  const double n0 = std::sqrt(kGM_m3ps2 / (kSemiMajorAxis_m * kSemiMajorAxis_m * kSemiMajorAxis_m));

  NominalConstellation c;
  for (size_t k = 0; k < kSlots.size(); ++k) {
    const Slot& slot = kSlots[k];
    const int prn = static_cast<int>(k) + 1;
    Ephemeris e;
    e.prn = prn;
    e.week = toe.week;
    e.toe_s = e.toc_s = toe.tow_s;
    e.code_on_l2 = 1;
    e.ura_index = 0;
    e.health = 0;
    // IODE outside 240-255 (reserved for extended operations) and changing with toe; IODC = IODE.
    e.iode = static_cast<int>((static_cast<long>(toe.tow_s / 7200.0) + 7L * prn) % 240);
    e.iodc = e.iode;
    e.fit_interval_flag = 0;
    // Near-circular orbit with a deterministic small eccentricity and argument of perigee per slot.
    e.e = 0.0015 + 0.001 * std::sin(1.3 * prn);
    e.omega_rad = wrap_pi(2.1 * prn);
    e.sqrt_a_sqrtm = std::sqrt(kSemiMajorAxis_m);
    e.delta_n_radps = n - n0;
    e.i0_rad = kInclination_rad;
    e.idot_radps = 0.0;
    e.omega_dot_radps = kOmegaDot_radps;
    // Earth-fixed longitude of the node at toe, then OMEGA_0 = that + omega_e * toe (Table 20-IV at t_k=0).
    const double node_lon = slot.raan_deg * kDeg - kGreenwichHourAngleAtEpoch_rad + node_rate_ecef * dt;
    e.omega0_rad = wrap_pi(node_lon + kEarthRotationRate_radps * toe.tow_s);
    // The slot's argument of latitude is taken as the mean argument of latitude M + omega (the nominal
    // plan is circular, where the two agree); it advances linearly, so the repeat above is exact.
    e.m0_rad = wrap_pi(slot.arg_lat_deg * kDeg + n * dt - e.omega_rad);
    // Clock: offsets of a few tens of microseconds, drifts of a few 1e-12 s/s, TGD of a few ns.
    e.af0_s = 1.5e-4 * std::sin(2.7 * prn);
    e.af1_sps = 4e-12 * std::cos(1.9 * prn);
    e.af2_sps2 = 0.0;
    e.tgd_s = -4.0e-9 + 1.0e-9 * (prn % 7);
    c.ephemerides.push_back(e);
    c.slots.emplace_back(slot.name);
  }
  // Klobuchar: the values broadcast on 2022-01-01 (IGS brdc0010.22n header), a typical mid-activity set.
  c.klobuchar.alpha[0] = 0.1211e-07;
  c.klobuchar.alpha[1] = -0.7451e-08;
  c.klobuchar.alpha[2] = -0.5960e-07;
  c.klobuchar.alpha[3] = 0.1192e-06;
  c.klobuchar.beta[0] = 0.1167e+06;
  c.klobuchar.beta[1] = -0.2458e+06;
  c.klobuchar.beta[2] = -0.6554e+05;
  c.klobuchar.beta[3] = 0.1114e+07;
  c.klobuchar.valid = true;
  // UTC: small realistic A0/A1 referenced to the toe week; 18 leap seconds since 2017-01-01 (the last
  // one at the end of GPS week 1929, day 7).
  c.utc.a0_s = 2.8e-9;
  c.utc.a1_sps = 8.0e-15;
  c.utc.tot_s = static_cast<int>(std::floor(toe.tow_s / 4096.0)) * 4096;
  c.utc.wnt = toe.week;
  c.utc.delta_t_ls_s = 18;
  c.utc.wn_lsf = 1929;
  c.utc.dn = 7;
  c.utc.delta_t_lsf_s = 18;
  c.utc.valid = true;
  return c;
}

}  // namespace ultratrack::signals
