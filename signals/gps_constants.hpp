// SPDX-License-Identifier: GPL-3.0-or-later
// Physical and signal constants of GPS L1 C/A and WGS-84, from IS-GPS-200 (sections 20.3.3.4.3 and
// 3.3.1) and NIMA TR8350.2. SI units throughout. These are the values the control segment uses in the
// broadcast orbit model; do not mix them with other datums' constants.
#pragma once

namespace ultratrack::signals {

inline constexpr double kSpeedOfLight_mps = 299792458.0;
inline constexpr double kPi = 3.1415926535898;    // IS-GPS-200 uses this exact value for semicircles
inline constexpr double kGM_m3ps2 = 3.986005e14;  // WGS-84 value used by GPS
inline constexpr double kEarthRotationRate_radps = 7.2921151467e-5;
inline constexpr double kRelativisticF_spsqrtm = -4.442807633e-10;  // F in dt_r = F e sqrt(A) sin(E)

inline constexpr double kL1Frequency_hz = 1575.42e6;
inline constexpr double kL1Wavelength_m = kSpeedOfLight_mps / kL1Frequency_hz;
inline constexpr double kCaChipRate_hz = 1.023e6;
inline constexpr int kCaCodeLength_chips = 1023;
inline constexpr double kCaCodePeriod_s = 1e-3;
inline constexpr int kNavBitPeriod_ms = 20;  // 50 bit/s LNAV
inline constexpr int kSubframeBits = 300;
inline constexpr double kSubframeDuration_s = 6.0;

inline constexpr int kMinPrn = 1;
inline constexpr int kMaxPrn = 32;

inline constexpr int kSecondsPerWeek = 604800;

}  // namespace ultratrack::signals
