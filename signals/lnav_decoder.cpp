// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/lnav_decoder.hpp"

#include <cmath>

#include "signals/gps_constants.hpp"
#include "signals/lnav_fields.hpp"
#include "signals/lnav_layout.hpp"
#include "signals/lnav_parity.hpp"

namespace ultratrack::signals {
namespace {

using namespace lnav;

std::uint32_t get(const LnavDataWords& w, Field f) { return get_lnav_field(w, f.first, f.length); }
std::uint32_t get(const LnavDataWords& w, SplitField f) {
  return get_lnav_split(w, f.msb_first, f.msb_length, f.lsb_first, f.lsb_length);
}
double sgn(const LnavDataWords& w, Field f, int scale) { return lnav_from_signed(get(w, f), scale, f.length); }
double sgn(const LnavDataWords& w, SplitField f, int scale) {
  return lnav_from_signed(get(w, f), scale, f.msb_length + f.lsb_length);
}
double uns(const LnavDataWords& w, Field f, int scale) { return lnav_from_unsigned(get(w, f), scale); }
double uns(const LnavDataWords& w, SplitField f, int scale) { return lnav_from_unsigned(get(w, f), scale); }

// Full week nearest to `week` whose low 8 bits are raw (WNt, WNLSF, WNa are broadcast modulo 256).
int resolve_week_mod256(std::uint32_t raw, int week) {
  int full = week - ((week - static_cast<int>(raw)) % 256 + 256) % 256;
  if (week - full > 128) full += 256;
  return full;
}

}  // namespace

LnavDecoder::LnavDecoder(int prn, int reference_week) : prn_(prn), week_(reference_week) {}

void LnavDecoder::count(LnavStatus status) {
  switch (status) {
    case LnavStatus::kOk:
      break;
    case LnavStatus::kNoPreamble:
      ++counters_.no_preamble;
      break;
    case LnavStatus::kParityError:
      ++counters_.parity_errors;
      break;
    case LnavStatus::kBadHow:
      ++counters_.bad_how;
      break;
  }
}

LnavStatus LnavDecoder::add_bits(std::span<const std::uint8_t, 300> bits,
                                 std::optional<std::array<std::uint8_t, 2>> previous_bits) {
  const LnavSubframeResult r = decode_lnav_subframe(bits, previous_bits);
  last_update_ = {};
  count(r.status);
  if (r.status == LnavStatus::kOk) add(r.subframe);
  return r.status;
}

std::optional<LnavFrameSyncOutput> LnavDecoder::add_bit(std::uint8_t bit) {
  auto out = frame_sync_.push(bit);
  if (!out) return out;
  last_update_ = {};
  count(out->result.status);
  if (out->result.status == LnavStatus::kOk) add(out->result.subframe);
  return out;
}

LnavUpdate LnavDecoder::add(const LnavSubframe& sf) {
  last_update_ = {};
  ++counters_.accepted;
  const double start_tow = sf.start_tow_s();
  // Time of week running backwards by more than half a week: the stream crossed a week boundary.
  if (last_start_ && start_tow < last_start_->tow_s - 0.5 * kSecondsPerWeek) ++week_;
  if (sf.subframe_id == 1) {
    week_ = resolve_week_rollover(static_cast<int>(get(sf.words, kWeek)), week_);
    week_known_ = true;
  }
  last_start_ = GpsTime{week_, start_tow};
  last_tow_count_ = sf.tow_count;

  if (sf.subframe_id <= 3) {
    sf_[sf.subframe_id - 1] = sf;
    if (sf.subframe_id == 1) sf1_week_ = week_;
    try_complete_ephemeris();
  } else if ((sf.subframe_id == 4 && sf.page_sv_id >= 25 && sf.page_sv_id <= 32) ||
             (sf.subframe_id == 5 && sf.page_sv_id >= 1 && sf.page_sv_id <= 24)) {
    decode_almanac(sf);
  } else if (sf.subframe_id == 4 && sf.page_sv_id == kIonoUtcSvId) {
    const LnavDataWords& w = sf.words;
    for (int i = 0; i < 4; ++i) {
      iono_.alpha[i] = sgn(w, kAlpha[i], kAlphaScale[i]);
      iono_.beta[i] = sgn(w, kBeta[i], kBetaScale[i]);
    }
    iono_.valid = true;
    utc_.a1_sps = sgn(w, kA1, kA1Scale);
    utc_.a0_s = sgn(w, kA0, kA0Scale);
    utc_.tot_s = static_cast<int>(get(w, kTot)) << kTotScale;
    utc_.wnt = resolve_week_mod256(get(w, kWnt), week_);
    utc_.delta_t_ls_s = static_cast<int>(lnav_from_signed(get(w, kDeltaTls), 0, 8));
    utc_.wn_lsf = resolve_week_mod256(get(w, kWnLsf), week_);
    utc_.dn = static_cast<int>(get(w, kDn));
    utc_.delta_t_lsf_s = static_cast<int>(lnav_from_signed(get(w, kDeltaTlsf), 0, 8));
    utc_.valid = true;
    last_update_.iono_utc = true;
  }
  return last_update_;
}

// Table 20-VI: e 2^-21, toa 2^12 s, delta i 2^-19 sc (from 0.30 sc), Omega dot 2^-38 sc/s, sqrt A 2^-11,
// Omega0 / omega / M0 2^-23 sc, af0 2^-20 s, af1 2^-38 s/s.
void LnavDecoder::decode_almanac(const LnavSubframe& sf) {
  const LnavDataWords& w = sf.words;
  if (get(w, kDataId) != static_cast<std::uint32_t>(kLnavDataIdNav)) return;  // LNAV data (20.3.3.5.1.1)
  Almanac a;
  a.prn = sf.page_sv_id;
  a.toa_s = static_cast<double>(get(w, kAlmToa) << kAlmToaScale);
  const double sent = sf.start_tow_s();
  const double dt = a.toa_s - sent;
  a.week = week_ + (dt < -0.5 * kSecondsPerWeek ? 1 : 0) - (dt > 0.5 * kSecondsPerWeek ? 1 : 0);
  a.e = uns(w, kAlmE, kAlmEScale);
  a.i_rad = (kAlmReferenceInclination_sc + sgn(w, kAlmDeltaI, kAlmDeltaIScale)) * kPi;
  a.omega_dot_radps = sgn(w, kAlmOmegaDot, kAlmOmegaDotScale) * kPi;
  a.health = static_cast<int>(get(w, kAlmHealth));
  a.sqrt_a_sqrtm = uns(w, kAlmSqrtA, kAlmSqrtAScale);
  a.omega0_rad = sgn(w, kAlmOmega0, kAlmAngleScale) * kPi;
  a.omega_rad = sgn(w, kAlmOmega, kAlmAngleScale) * kPi;
  a.m0_rad = sgn(w, kAlmM0, kAlmAngleScale) * kPi;
  a.af0_s = sgn(w, kAlmAf0, kAlmAf0Scale);
  a.af1_sps = sgn(w, kAlmAf1, kAlmAf1Scale);
  if (!(a.sqrt_a_sqrtm > 0.0)) return;  // not an orbit
  almanacs_[static_cast<std::size_t>(a.prn)] = a;
  last_update_.almanac_prn = a.prn;
}

void LnavDecoder::try_complete_ephemeris() {
  if (!sf_[0] || !sf_[1] || !sf_[2]) return;
  const LnavDataWords& w1 = sf_[0]->words;
  const LnavDataWords& w2 = sf_[1]->words;
  const LnavDataWords& w3 = sf_[2]->words;
  const int iodc = static_cast<int>((get(w1, kIodcMsb) << 8) | get(w1, kIodcLsb));
  const int iode2 = static_cast<int>(get(w2, kIode2));
  const int iode3 = static_cast<int>(get(w3, kIode3));
  // IS-GPS-200 20.3.4.4: the set is consistent when both IODEs equal the 8 LSBs of IODC.
  if (iode2 != iode3 || (iodc & 0xFF) != iode2) {
    ++counters_.inconsistent;
    return;
  }
  Ephemeris e;
  e.prn = prn_;
  e.code_on_l2 = static_cast<int>(get(w1, kCodeOnL2));
  e.ura_index = static_cast<int>(get(w1, kUra));
  e.health = static_cast<int>(get(w1, kHealth));
  e.iodc = iodc;
  e.l2p_data_flag = static_cast<int>(get(w1, kL2pFlag));
  e.tgd_s = sgn(w1, kTgd, kTgdScale);
  e.toc_s = uns(w1, kToc, kTocScale);
  e.af2_sps2 = sgn(w1, kAf2, kAf2Scale);
  e.af1_sps = sgn(w1, kAf1, kAf1Scale);
  e.af0_s = sgn(w1, kAf0, kAf0Scale);

  e.iode = iode2;
  e.crs_m = sgn(w2, kCrs, kCrsScale);
  e.delta_n_radps = sgn(w2, kDeltaN, kDeltaNScale) * kPi;
  e.m0_rad = sgn(w2, kM0, kM0Scale) * kPi;
  e.cuc_rad = sgn(w2, kCuc, kCucScale);
  e.e = uns(w2, kE, kEScale);
  e.cus_rad = sgn(w2, kCus, kCusScale);
  e.sqrt_a_sqrtm = uns(w2, kSqrtA, kSqrtAScale);
  e.toe_s = uns(w2, kToe, kToeScale);
  e.fit_interval_flag = static_cast<int>(get(w2, kFitFlag));
  e.aodo = static_cast<int>(get(w2, kAodo));

  e.cic_rad = sgn(w3, kCic, kCicScale);
  e.omega0_rad = sgn(w3, kOmega0, kOmega0Scale) * kPi;
  e.cis_rad = sgn(w3, kCis, kCisScale);
  e.i0_rad = sgn(w3, kI0, kI0Scale) * kPi;
  e.crc_m = sgn(w3, kCrc, kCrcScale);
  e.omega_rad = sgn(w3, kOmega, kOmegaScale) * kPi;
  e.omega_dot_radps = sgn(w3, kOmegaDot, kOmegaDotScale) * kPi;
  e.idot_radps = sgn(w3, kIdot, kIdotScale) * kPi;

  // WN is the week of transmission; toe may lie in the neighbouring week near a week boundary.
  const double dt = e.toe_s - sf_[0]->start_tow_s();
  e.week = sf1_week_ + (dt < -0.5 * kSecondsPerWeek ? 1 : 0) - (dt > 0.5 * kSecondsPerWeek ? 1 : 0);

  const bool changed = !ephemeris_ || ephemeris_->iodc != e.iodc || ephemeris_->iode != e.iode ||
                       ephemeris_->toe_s != e.toe_s || ephemeris_->week != e.week;
  ephemeris_ = e;
  last_update_.ephemeris = changed;
}

}  // namespace ultratrack::signals
