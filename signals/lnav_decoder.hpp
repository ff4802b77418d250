// Reads the LNAV message back (IS-GPS-200 20.3): decode_lnav_subframe checks one 300-bit subframe word by
// word (parity 20.3.5, either polarity) and returns its TLM/HOW fields and 24-bit data words;
// LnavDecoder collects one satellite's subframes into an Ephemeris (SI units, full weeks), the Klobuchar and
// UTC parameters, and the GPS time of each subframe start.
//
// Use from a receiver: once the bit synchroniser has found the preamble (frame sync), hand each
// consecutive block of 300 bits (0/1 as received, any polarity) to LnavDecoder::add_bits together with the
// two bits received just before it. Subframes may arrive starting anywhere in the frame; a subframe with
// a parity failure is counted and dropped, never used.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "signals/ephemeris.hpp"
#include "signals/gps_time.hpp"
#include "signals/lnav_fields.hpp"

namespace ultratrack::signals {

enum class LnavStatus {
  kOk,
  kNoPreamble,      // bits 1-8 are neither 10001011 nor its complement
  kParityError,     // some word failed its parity check
  kBadSubframeId,   // HOW subframe ID outside 1..5
};

struct LnavSubframe {
  LnavDataWords words{};   // d1..d24 of each word, polarity restored (d1 in bit 23)
  int subframe_id = 0;     // 1..5
  int tow_count = 0;       // HOW TOW count: start of the NEXT subframe in 6 s units, 0..100799
  bool alert = false;
  bool anti_spoof = false;
  bool inverted = false;   // the bits were received with inverted polarity
  int page_sv_id = -1;     // subframes 4/5: the page's SV ID (IS-GPS-200 Table 20-V); -1 for 1-3

  // Seconds of week at which this subframe's first bit was transmitted (TOW count x 6 s - 6 s, wrapped).
  double start_tow_s() const;
};

struct LnavSubframeResult {
  LnavStatus status = LnavStatus::kNoPreamble;
  int failed_word = 0;     // kParityError: the first word (1..10) whose parity failed
  LnavSubframe subframe;   // meaningful only when status == kOk
};

// previous_bits: the two bits received just before the subframe (the previous word's D29*, D30*) in the
// received polarity; without them the IS-GPS-200 value 0, 0 (upright) is assumed. Polarity comes from the
// preamble: a complemented preamble means the whole subframe (and previous_bits) is inverted.
LnavSubframeResult decode_lnav_subframe(std::span<const std::uint8_t, 300> bits,
                                        std::optional<std::array<std::uint8_t, 2>> previous_bits = std::nullopt);

// What one accepted subframe changed.
struct LnavUpdate {
  bool ephemeris = false;  // a complete ephemeris that differs from the previous one (new IODC/IODE/toe)
  bool iono_utc = false;   // subframe 4 page 18 decoded
};

// One satellite's LNAV stream -> ephemeris, Klobuchar/UTC, time. Not thread-safe; one per channel.
class LnavDecoder {
 public:
  struct Counters {
    int accepted = 0;        // subframes that passed parity
    int parity_errors = 0;   // subframes dropped for a parity failure
    int no_preamble = 0;
    int bad_subframe_id = 0;
    int inconsistent = 0;    // subframes 1-3 all present but IODC/IODE disagree (waiting for a new set)
  };

  // reference_week: a full GPS week within +-512 weeks of the signal's time (e.g. from the recording's
  // date); the 10-bit WN of subframe 1 is resolved against it (resolve_week_rollover), and later against the
  // last resolved week.
  LnavDecoder(int prn, int reference_week);

  // Decodes 300 received bits (see decode_lnav_subframe) and accepts them when they pass.
  LnavStatus add_bits(std::span<const std::uint8_t, 300> bits,
                      std::optional<std::array<std::uint8_t, 2>> previous_bits = std::nullopt);
  // Accepts one parity-checked subframe.
  LnavUpdate add(const LnavSubframe& subframe);
  // The last result of add/add_bits.
  const LnavUpdate& last_update() const { return last_update_; }

  // The latest complete ephemeris (subframes 1-3 with IODE2 = IODE3 = IODC mod 256).
  const std::optional<Ephemeris>& ephemeris() const { return ephemeris_; }
  // Valid once subframe 4 page 18 has been decoded (valid flags set). wnt and wn_lsf are full weeks
  // resolved from their 8 bits against the current week.
  const KlobucharParameters& klobuchar() const { return iono_; }
  const UtcParameters& utc() const { return utc_; }
  // GPS time at which the last accepted subframe's first bit left the satellite, and its HOW TOW count.
  // The week is the last subframe 1 WN (resolved), or the reference week before one has been read.
  std::optional<GpsTime> last_subframe_start() const { return last_start_; }
  std::optional<int> last_tow_count() const { return last_tow_count_; }
  const Counters& counters() const { return counters_; }
  int prn() const { return prn_; }

 private:
  void try_complete_ephemeris();

  int prn_;
  int week_;  // current full week of transmission
  std::optional<LnavSubframe> sf_[3];  // latest subframes 1, 2, 3
  int sf1_week_ = 0;                   // full transmission week of the stored subframe 1
  std::optional<Ephemeris> ephemeris_;
  KlobucharParameters iono_;
  UtcParameters utc_;
  std::optional<GpsTime> last_start_;
  std::optional<int> last_tow_count_;
  Counters counters_;
  LnavUpdate last_update_;
};

}  // namespace ultratrack::signals
