// SPDX-License-Identifier: GPL-3.0-or-later
// Where each LNAV field sits: subframe bit numbers (1-based, parity bits counted, IS-GPS-200 Figure 20-1)
// and fixed-point scale factors (Tables 20-I, 20-III, 20-VI) of the TLM/HOW, subframes 1-3 and the
// subframe 4/5 pages used here. One table for the transmitter and the decoder.
#pragma once

namespace ultratrack::signals::lnav {

struct Field {
  int first;   // subframe bit number of the MSB
  int length;  // bits
};
struct SplitField {  // transmitted as MSB part and LSB part in different words
  int msb_first, msb_length, lsb_first, lsb_length;
};

// TLM and HOW (words 1 and 2).
inline constexpr Field kPreamble{1, 8}, kTlmMessage{9, 14}, kIntegrity{23, 1};
inline constexpr Field kTowCount{31, 17}, kAlert{48, 1}, kAntiSpoof{49, 1}, kSubframeId{50, 3};

// Subframe 1 (Table 20-I): value = raw * 2^scale.
inline constexpr Field kWeek{61, 10}, kCodeOnL2{71, 2}, kUra{73, 4}, kHealth{77, 6}, kIodcMsb{83, 2};
inline constexpr Field kL2pFlag{91, 1}, kTgd{197, 8}, kIodcLsb{211, 8}, kToc{219, 16};
inline constexpr Field kAf2{241, 8}, kAf1{249, 16}, kAf0{271, 22};
inline constexpr int kTgdScale = -31, kTocScale = 4, kAf2Scale = -55, kAf1Scale = -43, kAf0Scale = -31;

// Subframe 2 (Table 20-III).
inline constexpr Field kIode2{61, 8}, kCrs{69, 16}, kDeltaN{91, 16}, kCuc{151, 16}, kCus{211, 16};
inline constexpr SplitField kM0{107, 8, 121, 24}, kE{167, 8, 181, 24}, kSqrtA{227, 8, 241, 24};
inline constexpr Field kToe{271, 16}, kFitFlag{287, 1}, kAodo{288, 5};
inline constexpr int kCrsScale = -5, kDeltaNScale = -43, kM0Scale = -31, kCucScale = -29, kEScale = -33;
inline constexpr int kCusScale = -29, kSqrtAScale = -19, kToeScale = 4;

// Subframe 3 (Table 20-III).
inline constexpr Field kCic{61, 16}, kCis{121, 16}, kCrc{181, 16}, kOmegaDot{241, 24};
inline constexpr SplitField kOmega0{77, 8, 91, 24}, kI0{137, 8, 151, 24}, kOmega{197, 8, 211, 24};
inline constexpr Field kIode3{271, 8}, kIdot{279, 14};
inline constexpr int kCicScale = -29, kOmega0Scale = -31, kCisScale = -29, kI0Scale = -31, kCrcScale = -5;
inline constexpr int kOmegaScale = -31, kOmegaDotScale = -43, kIdotScale = -43;

// Subframes 4 and 5: data ID and page SV ID (Table 20-V).
inline constexpr Field kDataId{61, 2}, kPageSvId{63, 6};

// Almanac page (Figure 20-1 sheets 4/5, Table 20-VI).
inline constexpr Field kAlmE{69, 16}, kAlmToa{91, 8}, kAlmDeltaI{99, 16}, kAlmOmegaDot{121, 16};
inline constexpr Field kAlmHealth{137, 8}, kAlmSqrtA{151, 24}, kAlmOmega0{181, 24}, kAlmOmega{211, 24};
inline constexpr Field kAlmM0{241, 24}, kAlmAf1{279, 11};
inline constexpr SplitField kAlmAf0{271, 8, 290, 3};
inline constexpr int kAlmEScale = -21, kAlmToaScale = 12, kAlmDeltaIScale = -19, kAlmOmegaDotScale = -38;
inline constexpr int kAlmSqrtAScale = -11, kAlmAngleScale = -23, kAlmAf0Scale = -20, kAlmAf1Scale = -38;
inline constexpr double kAlmReferenceInclination_sc = 0.30;  // delta_i is relative to 0.30 semicircles

// Subframe 4 page 18: ionosphere and UTC (IS-GPS-200 20.3.3.5.1.6/7).
inline constexpr Field kAlpha[4] = {{69, 8}, {77, 8}, {91, 8}, {99, 8}};
inline constexpr Field kBeta[4] = {{107, 8}, {121, 8}, {129, 8}, {137, 8}};
inline constexpr int kAlphaScale[4] = {-30, -27, -24, -24};
inline constexpr int kBetaScale[4] = {11, 14, 16, 16};
inline constexpr Field kA1{151, 24}, kTot{219, 8}, kWnt{227, 8}, kDeltaTls{241, 8}, kWnLsf{249, 8};
inline constexpr Field kDn{257, 8}, kDeltaTlsf{271, 8};
inline constexpr SplitField kA0{181, 24, 211, 8};
inline constexpr int kA1Scale = -50, kA0Scale = -30, kTotScale = 12;

// Subframe 5 page 25: almanac reference time/week and health of SV 1-24 (six bits each, 4 per word from
// word 4); subframe 4 page 25: A-S/configuration of SV 1-32 (four bits each) and health of SV 25-32.
inline constexpr Field kToa{69, 8}, kWna{77, 8};
constexpr int sf5_health_bit(int prn) { return (3 + (prn - 1) / 4) * 30 + 1 + 6 * ((prn - 1) % 4); }
constexpr int sf4_config_bit(int prn) {
  if (prn <= 4) return 69 + 4 * (prn - 1);
  if (prn <= 28) return (3 + (prn - 5) / 6) * 30 + 1 + 4 * ((prn - 5) % 6);
  return 211 + 4 * (prn - 29);
}
constexpr int sf4_health_bit(int prn) {
  if (prn == 25) return 229;
  if (prn <= 29) return 241 + 6 * (prn - 26);
  return 271 + 6 * (prn - 30);
}

// Page SV IDs of subframe 4 pages 1..25 (Table 20-V); subframe 5 pages 1..24 carry SV 1..24, page 25 is 51.
inline constexpr int kSubframe4PageSvId[25] = {57, 25, 26, 27, 28, 57, 29, 30, 31, 32, 57, 62, 52,
                                               53, 54, 57, 55, 56, 58, 59, 57, 60, 61, 62, 63};
inline constexpr int kIonoUtcSvId = 56;    // subframe 4 page 18
inline constexpr int kSf4HealthSvId = 63;  // subframe 4 page 25
inline constexpr int kSf5HealthSvId = 51;  // subframe 5 page 25

}  // namespace ultratrack::signals::lnav
