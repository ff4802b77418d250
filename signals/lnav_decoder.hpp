// SPDX-License-Identifier: GPL-3.0-or-later
// Reads the LNAV message back (IS-GPS-200 20.3): LnavDecoder collects one satellite's parity-checked
// subframes (lnav_subframe.hpp) into an Ephemeris (SI units, full weeks), the Klobuchar and UTC
// parameters, the almanacs of subframes 4 and 5 (any satellite's, signals/almanac.hpp), and the GPS time of
// each subframe start.
//
// Use from a receiver: either push every bit from the bit synchroniser with LnavDecoder::add_bit (frame
// sync by preamble search inside, lnav_frame_sync.hpp), or, with frame sync done elsewhere, hand each
// block of 300 bits (0/1 as received, any polarity) to add_bits with the two bits received before it.
// Subframes may arrive starting anywhere in the frame; a subframe with a parity failure is counted and
// dropped, never used.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "signals/almanac.hpp"
#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_frame_sync.hpp"
#include "signals/lnav_subframe.hpp"

namespace ultratrack::signals {

// What one accepted subframe changed.
struct LnavUpdate {
  bool ephemeris = false;  // a complete ephemeris that differs from the previous one (new IODC/IODE/toe)
  bool iono_utc = false;   // subframe 4 page 18 decoded
  int almanac_prn = 0;     // an almanac page of this PRN decoded (0: none)
};

// One satellite's LNAV stream -> ephemeris, Klobuchar/UTC, time. Not thread-safe; one per channel.
class LnavDecoder {
 public:
  struct Counters {
    int accepted = 0;       // subframes that passed parity
    int parity_errors = 0;  // subframes dropped for a parity failure
    int no_preamble = 0;
    int bad_how = 0;
    int inconsistent = 0;  // subframes 1-3 all present but IODC/IODE disagree (waiting for a new set)
  };

  // reference_week: a full GPS week within +-512 weeks of the signal's time (e.g. from the recording's
  // date); the 10-bit WN of subframe 1 is resolved against it (resolve_week_rollover), and later against the
  // last resolved week.
  LnavDecoder(int prn, int reference_week);

  // Decodes 300 received bits (see decode_lnav_subframe) and accepts them when they pass.
  LnavStatus add_bits(std::span<const std::uint8_t, 300> bits,
                      std::optional<std::array<std::uint8_t, 2>> previous_bits = std::nullopt);
  // Pushes one received bit into the internal frame synchroniser; a completed subframe is decoded and
  // accepted as by add_bits. Returns the status and stream position of a subframe when one completed.
  std::optional<LnavFrameSyncOutput> add_bit(std::uint8_t bit);
  bool frame_locked() const { return frame_sync_.locked(); }

  // Accepts one parity-checked subframe.
  LnavUpdate add(const LnavSubframe& subframe);
  // The last result of add/add_bits.
  const LnavUpdate& last_update() const { return last_update_; }

  // The latest complete ephemeris (subframes 1-3 with IODE2 = IODE3 = IODC mod 256).
  const std::optional<Ephemeris>& ephemeris() const { return ephemeris_; }
  // Valid once subframe 4 page 18 has been decoded (valid flags set). wnt and wn_lsf are full weeks
  // resolved from their 8 bits to the nearest week to the current one (IS-GPS-200 keeps WN_LSF within
  // 127 weeks of WN when a leap second is pending; otherwise, delta_t_lsf = delta_t_ls, its week is moot).
  const KlobucharParameters& klobuchar() const { return iono_; }
  const UtcParameters& utc() const { return utc_; }
  // The latest almanac decoded for each PRN (index = PRN, 1..32; dummy-SV pages are skipped). toa's week is
  // the one that puts toa nearest to the page's time of transmission (IS-GPS-200 20.3.4.5: toa lies within
  // a few days of it).
  const std::array<std::optional<Almanac>, 33>& almanacs() const { return almanacs_; }
  // GPS time at which the last accepted subframe's first bit left the satellite, and its HOW TOW count.
  // The week is the last subframe 1 WN (resolved), or the reference week before one has been read.
  std::optional<GpsTime> last_subframe_start() const { return last_start_; }
  // True once a subframe 1 has given the week: until then last_subframe_start()'s week is only the
  // caller's reference week, which may be hundreds of weeks from the signal's.
  bool week_known() const { return week_known_; }
  std::optional<int> last_tow_count() const { return last_tow_count_; }
  const Counters& counters() const { return counters_; }
  int prn() const { return prn_; }

 private:
  void try_complete_ephemeris();
  void decode_almanac(const LnavSubframe& subframe);
  void count(LnavStatus status);

  int prn_;
  int week_;  // current full week of transmission
  bool week_known_ = false;
  std::optional<LnavSubframe> sf_[3];  // latest subframes 1, 2, 3
  int sf1_week_ = 0;                   // full transmission week of the stored subframe 1
  std::optional<Ephemeris> ephemeris_;
  KlobucharParameters iono_;
  UtcParameters utc_;
  std::array<std::optional<Almanac>, 33> almanacs_{};
  std::optional<GpsTime> last_start_;
  std::optional<int> last_tow_count_;
  Counters counters_;
  LnavUpdate last_update_;
  LnavFrameSync frame_sync_;
};

}  // namespace ultratrack::signals
