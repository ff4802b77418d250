// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_transmitter.hpp"

#include <fmt/format.h>

#include <cmath>
#include <random>
#include <string>

#include "signals/gps_constants.hpp"
#include "signals/lnav_layout.hpp"
#include "signals/lnav_parity.hpp"

namespace ultratrack::signals {
namespace {

using namespace lnav;

void put(LnavDataWords& w, Field f, std::uint32_t v) { put_lnav_field(w, f.first, f.length, v); }
void put(LnavDataWords& w, SplitField f, std::uint32_t v) {
  put_lnav_split(w, f.msb_first, f.msb_length, f.lsb_first, f.lsb_length, v);
}
int bits_of(Field f) { return f.length; }
int bits_of(SplitField f) { return f.msb_length + f.lsb_length; }
// Fields of the ephemeris subframes take the transmitter's rounding convention; the pages round to nearest.
template <class F>
std::uint32_t sgn(double v, int scale, F f, const char* what, FieldRounding r = FieldRounding::kNearest) {
  return lnav_signed(v, scale, bits_of(f), what, r);
}
template <class F>
std::uint32_t uns(double v, int scale, F f, const char* what, FieldRounding r = FieldRounding::kNearest) {
  return lnav_unsigned(v, scale, bits_of(f), what, r);
}
template <class F>
std::uint32_t ang(double rad, int scale, F f, FieldRounding r = FieldRounding::kNearest) {
  return lnav_angle(rad, scale, bits_of(f), r);
}

// Alternating 1010... in every data bit from subframe bit `first` to the end of word 10's bit 22
// (IS-GPS-200 20.3.2: fill of pages without meaningful data and of dummy-SV almanacs).
void alternating_fill(LnavDataWords& w, int first) {
  int k = 0;
  for (int bit = first; bit <= 292; ++bit) {
    if ((bit - 1) % 30 >= 24) continue;  // parity positions
    put_lnav_field(w, bit, 1, (k++ % 2 == 0) ? 1u : 0u);
  }
}

// 6-bit ephemeris health (NAV data summary + 5-bit signal code) as the 8-bit almanac health (3-bit NAV
// data health + the same 5-bit code, Tables 20-VII/20-VIII): a bad NAV summary becomes "all data bad".
std::uint32_t almanac_health(int health6) {
  const std::uint32_t nav = (health6 & 0x20) ? 0x7u : 0x0u;
  return (nav << 5) | (static_cast<std::uint32_t>(health6) & 0x1Fu);
}

constexpr std::uint32_t kAbsentHealth6 = 0x3F;  // no almanac for this SV
constexpr std::uint32_t kConfigAsOnIIF = 0xB;   // A-S on, configuration 011 (Block IIF-like)

}  // namespace

SubframeBits encode_lnav_subframe(const LnavDataWords& data) {
  SubframeBits bits{};
  int d29 = 0, d30 = 0;
  for (int i = 0; i < 10; ++i) {
    std::uint32_t d = data[i] & 0xFFFFFFu;
    if (i == 1 || i == 9) d = solve_lnav_parity_bits(d, d29, d30);
    const std::uint32_t word = encode_lnav_word(d, d29, d30);
    for (int b = 0; b < 30; ++b) bits[i * 30 + b] = static_cast<std::uint8_t>((word >> (29 - b)) & 1u);
    d29 = static_cast<int>((word >> 1) & 1u);
    d30 = static_cast<int>(word & 1u);
  }
  return bits;
}

int lnav_subframe_id_at(double tow_s) {
  return static_cast<int>(static_cast<std::int64_t>(std::floor(tow_s / kSubframeDuration_s)) % 5) + 1;
}

int lnav_page_at(double tow_s) {
  return static_cast<int>(static_cast<std::int64_t>(std::floor(tow_s / 30.0)) % 25) + 1;
}

LnavTransmitter::LnavTransmitter(Ephemeris ephemeris, KlobucharParameters iono, UtcParameters utc,
                                 std::vector<Ephemeris> almanac_source, LnavConventions conventions)
    : ephemeris_(std::move(ephemeris)),
      iono_(iono),
      utc_(utc),
      almanac_source_(std::move(almanac_source)),
      conventions_(conventions) {
  // Fail at construction, not in the middle of a synthesis run, when a field does not fit.
  const auto check = [&](int value, int bits, const char* what) {
    if (value < 0 || value >= (1 << bits))
      throw_lnav_encoding_error(fmt::format("PRN {} {} = {} does not fit {} bits", ephemeris_.prn, what, value, bits));
  };
  check(ephemeris_.iodc, 10, "IODC");
  check(ephemeris_.iode, 8, "IODE");
  check(ephemeris_.health, 6, "health");
  check(ephemeris_.ura_index, 4, "URA index");
  check(ephemeris_.code_on_l2, 2, "code on L2");
  check(ephemeris_.l2p_data_flag, 1, "L2 P data flag");
  check(ephemeris_.fit_interval_flag, 1, "fit interval flag");
  check(ephemeris_.aodo, 5, "AODO");
  check(utc_.dn, 8, "UTC DN");
  for (const auto& a : almanac_source_) check(a.health, 6, "almanac health");
  const GpsTime start{ephemeris_.week, std::floor(ephemeris_.toe_s / 30.0) * 30.0};
  (void)subframe1(start.week), (void)subframe2(), (void)subframe3();
  for (int page = 1; page <= 25; ++page) (void)subframe4(page), (void)subframe5(page);
}

GpsTime LnavTransmitter::almanac_reference() const {
  return {ephemeris_.week, std::floor(ephemeris_.toe_s / 4096.0) * 4096.0};
}

const Ephemeris* LnavTransmitter::almanac_of(int prn) const {
  for (const auto& e : almanac_source_)
    if (e.prn == prn) return &e;
  return nullptr;
}

LnavDataWords LnavTransmitter::subframe_data(const GpsTime& start_in) const {
  GpsTime start = normalised(start_in);
  start.tow_s = std::floor(start.tow_s / kSubframeDuration_s + 1e-9) * kSubframeDuration_s;
  const int id = lnav_subframe_id_at(start.tow_s);
  LnavDataWords w{};
  switch (id) {
    case 1:
      w = subframe1(start.week);
      break;
    case 2:
      w = subframe2();
      break;
    case 3:
      w = subframe3();
      break;
    case 4:
      w = subframe4(lnav_page_at(start.tow_s));
      break;
    default:
      w = subframe5(lnav_page_at(start.tow_s));
      break;
  }
  if (conventions_.random_pages && id >= 4) randomise_page(w, start);
  // TLM: preamble, TLM message 0, integrity status 0 (legacy accuracy), reserved 0.
  put(w, kPreamble, kLnavPreamble);
  const auto tow_count = static_cast<std::uint32_t>(
      (static_cast<std::int64_t>(std::llround(start.tow_s / kSubframeDuration_s)) + 1) % kLnavTowCountModulus);
  put(w, kTowCount, tow_count);
  put(w, kAlert, 0);
  put(w, kAntiSpoof, 1);
  put(w, kSubframeId, static_cast<std::uint32_t>(id));
  return w;
}

SubframeBits LnavTransmitter::subframe_starting_at(const GpsTime& start) const {
  return encode_lnav_subframe(subframe_data(start));
}

int LnavTransmitter::data_symbol_at(const GpsTime& t_in) {
  // A time a hair (1 ns) before a bit edge counts as after it: a double TOW resolves only ~0.1 ns, so
  // "start + 0.02 k" computed by a caller may land just short of the edge it means.
  constexpr double kEdgeTolerance_s = 1e-9;
  const GpsTime t = add_seconds(t_in, kEdgeTolerance_s);
  const double start_tow = std::floor(t.tow_s / kSubframeDuration_s) * kSubframeDuration_s;
  if (t.week != cached_start_.week || start_tow != cached_start_.tow_s) {
    cached_start_ = {t.week, start_tow};
    cached_bits_ = subframe_starting_at(cached_start_);
  }
  const double offset_s = t.tow_s - start_tow;  // exact (Sterbenz): both within 6 s of each other
  int bit = static_cast<int>(offset_s * (1000.0 / kNavBitPeriod_ms));
  if (bit < 0) bit = 0;
  if (bit >= kSubframeBits) bit = kSubframeBits - 1;
  return cached_bits_[static_cast<std::size_t>(bit)] ? -1 : +1;
}

LnavDataWords LnavTransmitter::subframe1(int transmit_week) const {
  const Ephemeris& e = ephemeris_;
  LnavDataWords w{};
  const FieldRounding r = conventions_.field_rounding;
  put(w, kWeek, static_cast<std::uint32_t>(((transmit_week % 1024) + 1024) % 1024));
  put(w, kCodeOnL2, static_cast<std::uint32_t>(e.code_on_l2));
  put(w, kUra, static_cast<std::uint32_t>(e.ura_index));
  put(w, kHealth, static_cast<std::uint32_t>(e.health));
  put(w, kIodcMsb, static_cast<std::uint32_t>(e.iodc >> 8));
  put(w, kL2pFlag, static_cast<std::uint32_t>(e.l2p_data_flag));
  put(w, kTgd, sgn(e.tgd_s, kTgdScale, kTgd, "TGD", r));
  put(w, kIodcLsb, static_cast<std::uint32_t>(e.iodc));
  put(w, kToc, uns(e.toc_s, kTocScale, kToc, "toc", r));
  put(w, kAf2, sgn(e.af2_sps2, kAf2Scale, kAf2, "af2", r));
  put(w, kAf1, sgn(e.af1_sps, kAf1Scale, kAf1, "af1", r));
  put(w, kAf0, sgn(e.af0_s, kAf0Scale, kAf0, "af0", r));
  return w;
}

LnavDataWords LnavTransmitter::subframe2() const {
  const Ephemeris& e = ephemeris_;
  LnavDataWords w{};
  const FieldRounding r = conventions_.field_rounding;
  put(w, kIode2, static_cast<std::uint32_t>(e.iode));
  put(w, kCrs, sgn(e.crs_m, kCrsScale, kCrs, "Crs", r));
  put(w, kDeltaN, sgn(e.delta_n_radps / kPi, kDeltaNScale, kDeltaN, "delta n", r));
  put(w, kM0, ang(e.m0_rad, kM0Scale, kM0, r));
  put(w, kCuc, sgn(e.cuc_rad, kCucScale, kCuc, "Cuc", r));
  put(w, kE, uns(e.e, kEScale, kE, "e", r));
  put(w, kCus, sgn(e.cus_rad, kCusScale, kCus, "Cus", r));
  put(w, kSqrtA, uns(e.sqrt_a_sqrtm, kSqrtAScale, kSqrtA, "sqrt A", r));
  put(w, kToe, uns(e.toe_s, kToeScale, kToe, "toe", r));
  put(w, kFitFlag, static_cast<std::uint32_t>(e.fit_interval_flag));
  put(w, kAodo, static_cast<std::uint32_t>(e.aodo));
  return w;
}

LnavDataWords LnavTransmitter::subframe3() const {
  const Ephemeris& e = ephemeris_;
  LnavDataWords w{};
  const FieldRounding r = conventions_.field_rounding;
  put(w, kCic, sgn(e.cic_rad, kCicScale, kCic, "Cic", r));
  put(w, kOmega0, ang(e.omega0_rad, kOmega0Scale, kOmega0, r));
  put(w, kCis, sgn(e.cis_rad, kCisScale, kCis, "Cis", r));
  put(w, kI0, ang(e.i0_rad, kI0Scale, kI0, r));
  put(w, kCrc, sgn(e.crc_m, kCrcScale, kCrc, "Crc", r));
  put(w, kOmega, ang(e.omega_rad, kOmegaScale, kOmega, r));
  put(w, kOmegaDot, sgn(e.omega_dot_radps / kPi, kOmegaDotScale, kOmegaDot, "Omega dot", r));
  put(w, kIode3, static_cast<std::uint32_t>(e.iode));
  put(w, kIdot, sgn(e.idot_radps / kPi, kIdotScale, kIdot, "IDOT", r));
  return w;
}

// Almanac of `prn` referenced to the almanac time: the ephemeris propagated from toe to toa in the
// Keplerian terms (M0 by the mean motion, Omega0 by Omega dot, i by IDOT, af0 by af1).
void LnavTransmitter::almanac_page(LnavDataWords& w, int prn) const {
  put(w, kDataId, kLnavDataIdNav);
  const Ephemeris* a = almanac_of(prn);
  if (a == nullptr) {  // dummy SV: SV ID 0 and alternating fill
    put(w, kPageSvId, 0);
    alternating_fill(w, 69);
    return;
  }
  const GpsTime toa = almanac_reference();
  const double dt = seconds_between(toa, a->toe());
  const double dtc = seconds_between(toa, a->toc());
  const double sqrt_a = a->sqrt_a_sqrtm;
  const double n = std::sqrt(kGM_m3ps2) / (sqrt_a * sqrt_a * sqrt_a) + a->delta_n_radps;
  put(w, kPageSvId, static_cast<std::uint32_t>(prn));
  put(w, kAlmE, uns(a->e, kAlmEScale, kAlmE, "almanac e"));
  put(w, kAlmToa, uns(toa.tow_s, kAlmToaScale, kAlmToa, "toa"));
  put(w, kAlmDeltaI,
      sgn((a->i0_rad + a->idot_radps * dt) / kPi - kAlmReferenceInclination_sc, kAlmDeltaIScale, kAlmDeltaI,
          "almanac delta i"));
  put(w, kAlmOmegaDot, sgn(a->omega_dot_radps / kPi, kAlmOmegaDotScale, kAlmOmegaDot, "almanac Omega dot"));
  put(w, kAlmHealth, almanac_health(a->health));
  put(w, kAlmSqrtA, uns(sqrt_a, kAlmSqrtAScale, kAlmSqrtA, "almanac sqrt A"));
  put(w, kAlmOmega0, ang(a->omega0_rad + a->omega_dot_radps * dt, kAlmAngleScale, kAlmOmega0));
  put(w, kAlmOmega, ang(a->omega_rad, kAlmAngleScale, kAlmOmega));
  put(w, kAlmM0, ang(a->m0_rad + n * dt, kAlmAngleScale, kAlmM0));
  put(w, kAlmAf0, sgn(a->af0_s + a->af1_sps * dtc, kAlmAf0Scale, kAlmAf0, "almanac af0"));
  put(w, kAlmAf1, sgn(a->af1_sps, kAlmAf1Scale, kAlmAf1, "almanac af1"));
}

// Words 3-10 after the data ID and SV ID (subframe bits 69..292, parity positions skipped) become random and
// the SV ID 0 (a dummy SV, whose page a decoder skips: random almanac or health bits must not be taken for
// broadcast ones), except page 18's ionosphere and UTC (SV ID 56).
void LnavTransmitter::randomise_page(LnavDataWords& w, const GpsTime& start) const {
  if (get_lnav_field(w, kPageSvId.first, kPageSvId.length) == static_cast<std::uint32_t>(kIonoUtcSvId)) return;
  put(w, kPageSvId, 0);
  const auto subframe_count = static_cast<std::uint64_t>(std::llround(start.tow_s / kSubframeDuration_s)) +
                              static_cast<std::uint64_t>(start.week) * 100800u;
  std::seed_seq seq{conventions_.page_seed, static_cast<std::uint64_t>(ephemeris_.prn), subframe_count};
  std::mt19937_64 rng(seq);
  for (int bit = 69; bit <= 292; ++bit) {
    if ((bit - 1) % 30 >= 24) continue;  // parity positions
    put_lnav_field(w, bit, 1, static_cast<std::uint32_t>(rng() >> 63));
  }
}

LnavDataWords LnavTransmitter::subframe4(int page) const {
  LnavDataWords w{};
  const int sv_id = kSubframe4PageSvId[page - 1];
  if (sv_id >= 25 && sv_id <= 32) {
    almanac_page(w, sv_id);
    return w;
  }
  put(w, kDataId, kLnavDataIdNav);
  put(w, kPageSvId, static_cast<std::uint32_t>(sv_id));
  if (sv_id == kIonoUtcSvId) {
    for (int i = 0; i < 4; ++i) {
      put(w, kAlpha[i], sgn(iono_.alpha[i], kAlphaScale[i], kAlpha[i], "Klobuchar alpha"));
      put(w, kBeta[i], sgn(iono_.beta[i], kBetaScale[i], kBeta[i], "Klobuchar beta"));
    }
    put(w, kA1, sgn(utc_.a1_sps, kA1Scale, kA1, "UTC A1"));
    put(w, kA0, sgn(utc_.a0_s, kA0Scale, kA0, "UTC A0"));
    put(w, kTot, uns(utc_.tot_s, kTotScale, kTot, "tot"));
    put(w, kWnt, static_cast<std::uint32_t>(utc_.wnt) & 0xFFu);
    put(w, kDeltaTls, lnav_signed(utc_.delta_t_ls_s, 0, 8, "delta t LS"));
    put(w, kWnLsf, static_cast<std::uint32_t>(utc_.wn_lsf) & 0xFFu);
    put(w, kDn, static_cast<std::uint32_t>(utc_.dn) & 0xFFu);
    put(w, kDeltaTlsf, lnav_signed(utc_.delta_t_lsf_s, 0, 8, "delta t LSF"));
  } else if (sv_id == kSf4HealthSvId) {
    for (int prn = 1; prn <= 32; ++prn)
      put_lnav_field(w, sf4_config_bit(prn), 4, almanac_of(prn) ? kConfigAsOnIIF : 0u);
    for (int prn = 25; prn <= 32; ++prn) {
      const Ephemeris* a = almanac_of(prn);
      put_lnav_field(w, sf4_health_bit(prn), 6, a ? static_cast<std::uint32_t>(a->health) : kAbsentHealth6);
    }
  } else {
    alternating_fill(w, 69);
  }
  return w;
}

LnavDataWords LnavTransmitter::subframe5(int page) const {
  LnavDataWords w{};
  if (page <= 24) {
    almanac_page(w, page);
    return w;
  }
  const GpsTime toa = almanac_reference();
  put(w, kDataId, kLnavDataIdNav);
  put(w, kPageSvId, kSf5HealthSvId);
  put(w, kToa, uns(toa.tow_s, kAlmToaScale, kToa, "toa"));
  put(w, kWna, static_cast<std::uint32_t>(toa.week) & 0xFFu);
  for (int prn = 1; prn <= 24; ++prn) {
    const Ephemeris* a = almanac_of(prn);
    put_lnav_field(w, sf5_health_bit(prn), 6, a ? static_cast<std::uint32_t>(a->health) : kAbsentHealth6);
  }
  return w;
}

}  // namespace ultratrack::signals
