// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/nav_bit_predictor.hpp"

#include <cmath>

#include "io/input_error.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/lnav_layout.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kSubframe_s = 6.0;
constexpr double kBit_s = 0.02;
constexpr std::uint32_t kTowCountModulus = 100800;  // 6 s counts in a week

}  // namespace

bool NavBitPredictor::supply_navigation(int prn, const std::vector<signals::Ephemeris>& sets,
                                        const signals::KlobucharParameters& iono, const signals::UtcParameters& utc,
                                        const signals::GpsTime& at, bool include_unhealthy) {
  signals::EphemerisSelectionOptions opt;
  opt.include_unhealthy = include_unhealthy;
  std::vector<signals::Ephemeris> selected;
  std::optional<signals::Ephemeris> own;
  for (int p = 1; p <= 32; ++p) {
    if (auto e = signals::select_ephemeris(sets, p, at, opt)) {
      selected.push_back(*e);
      if (p == prn) own = *e;
    }
  }
  if (!own) return false;
  transmitter_.emplace(*own, iono, utc, std::move(selected));
  for (std::size_t i = 0; i < subframes_.size(); ++i) compare_with_nav_file(i);
  ++version_;
  return true;
}

bool NavBitPredictor::nav_file_subframe(const signals::GpsTime& start) {
  if (start.week == nav_start_.week && start.tow_s == nav_start_.tow_s) return nav_ok_;
  nav_start_ = start;
  try {
    nav_data_ = transmitter_->subframe_data(start);
    nav_bits_ = transmitter_->subframe_starting_at(start);
    nav_ok_ = true;
  } catch (const io::InputError&) {
    nav_ok_ = false;  // a nav-file field that does not fit its bits: nothing to verify
  }
  return nav_ok_;
}

bool NavBitPredictor::issue_of_data_trusted(int id) const {
  const auto& t = trusted_[static_cast<std::size_t>(id - 1)];
  return id == 1 ? t[2] && t[7] : id == 2 ? t[2] : t[9];
}

void NavBitPredictor::add_word(const signals::GpsTime& start, int index, std::uint32_t data24, int prev_d29,
                               int prev_d30) {
  const int id = signals::lnav_subframe_id_at(start.tow_s);
  if (!transmitter_ || id > 3 || index < 2 || index > 9 || !nav_file_subframe(start)) return;
  const auto w = static_cast<std::size_t>(index);
  const std::uint32_t mask = index == 9 ? 0xFFFFFCu : 0xFFFFFFu;  // word 10's last two bits solve its parity
  const bool agrees =
      ((nav_data_[w] ^ data24) & mask) == 0 && nav_bits_[30 * w - 2] == prev_d29 && nav_bits_[30 * w - 1] == prev_d30;
  auto& trusted = trusted_[static_cast<std::size_t>(id - 1)];
  auto& rejected = rejected_[static_cast<std::size_t>(id - 1)];
  if (agrees && !trusted[w]) {
    ++nav_words_agreed_;
    trusted.set(w);
    rejected.reset(w);
    ++version_;
  } else if (!agrees && !rejected[w]) {
    ++nav_words_disagreed_;
    rejected.set(w);
    trusted.reset(w);
    const bool holds_issue = id == 1 ? (index == 2 || index == 7) : id == 2 ? index == 2 : index == 9;
    if (holds_issue) trusted.reset();
    ++version_;
  }
}

// Words 3-10 of a decoded subframe 1-3 against the nav file's, once per stored copy.
void NavBitPredictor::compare_with_nav_file(std::size_t index) {
  auto& stored = subframes_[index];
  if (!transmitter_ || !stored || stored->compared) return;
  stored->compared = true;
  const signals::SubframeBits bits = signals::encode_lnav_subframe(stored->words);
  for (int w = 2; w < 10; ++w)
    add_word(stored->start, w, stored->words[static_cast<std::size_t>(w)], bits[static_cast<std::size_t>(30 * w - 2)],
             bits[static_cast<std::size_t>(30 * w - 1)]);
}

void NavBitPredictor::add_subframe(const signals::LnavSubframe& sf, const signals::GpsTime& start) {
  tlm_ = sf.words[0];
  alert_ = signals::get_lnav_field(sf.words, signals::lnav::kAlert.first, signals::lnav::kAlert.length);
  anti_spoof_ = signals::get_lnav_field(sf.words, signals::lnav::kAntiSpoof.first, signals::lnav::kAntiSpoof.length);
  if (sf.subframe_id >= 1 && sf.subframe_id <= 3) {
    const auto index = static_cast<std::size_t>(sf.subframe_id - 1);
    auto& stored = subframes_[index];
    bool same = stored.has_value();
    for (std::size_t w = 2; same && w < 10; ++w) same = stored->words[w] == sf.words[w];
    if (!same) {
      new_data_ = true;
      stopped_ = false;
    }
    const bool compared = same && stored->compared;
    stored = Stored{sf.words, start, compared};
    compare_with_nav_file(index);
  }
  ++version_;
}

void NavBitPredictor::stop() {
  stopped_ = true;
  ++version_;
}

bool NavBitPredictor::take_new_data() {
  const bool fresh = new_data_;
  new_data_ = false;
  return fresh;
}

void NavBitPredictor::build(const signals::GpsTime& start) {
  cached_start_ = start;
  cached_version_ = version_;
  known_.reset();
  if (transmitter_ && source_ == NavBitSource::kOracle) {
    bits_ = transmitter_->subframe_starting_at(start);
    known_.set();
    return;
  }
  if (!tlm_ || stopped_) return;
  const int id = signals::lnav_subframe_id_at(start.tow_s);
  signals::LnavDataWords w{};
  const auto& stored = id <= 3 ? subframes_[static_cast<std::size_t>(id - 1)] : std::nullopt;
  // Subframe 1 carries the week: a stored one from another week does not repeat.
  const bool data_known = stored && stored->start.week == start.week;
  // Else the nav file's words the signal confirmed (their bits depend on the words before them only through the
  // preceding D29*, D30*, which were confirmed with them).
  const bool nav_words =
      !data_known && id <= 3 && transmitter_ && issue_of_data_trusted(id) && nav_file_subframe(start);
  if (data_known) w = stored->words;
  if (nav_words) w = nav_data_;
  w[0] = *tlm_;
  const auto tow_count = static_cast<std::uint32_t>(
      (static_cast<std::int64_t>(std::llround(start.tow_s / kSubframe_s)) + 1) % kTowCountModulus);
  w[1] = 0;
  signals::put_lnav_field(w, signals::lnav::kTowCount.first, signals::lnav::kTowCount.length, tow_count);
  signals::put_lnav_field(w, signals::lnav::kAlert.first, signals::lnav::kAlert.length, alert_);
  signals::put_lnav_field(w, signals::lnav::kAntiSpoof.first, signals::lnav::kAntiSpoof.length, anti_spoof_);
  signals::put_lnav_field(w, signals::lnav::kSubframeId.first, signals::lnav::kSubframeId.length,
                          static_cast<std::uint32_t>(id));
  bits_ = signals::encode_lnav_subframe(w);  // words 1-2 do not depend on the later words
  for (int i = 0; i < (data_known ? 300 : 60); ++i) known_.set(static_cast<std::size_t>(i));
  if (nav_words)
    for (std::size_t k = 2; k < 10; ++k)
      if (trusted_[static_cast<std::size_t>(id - 1)][k])
        for (std::size_t i = 30 * k; i < 30 * k + 30; ++i) known_.set(i);
}

std::optional<int> NavBitPredictor::bit_at(const signals::GpsTime& t) {
  if (!(transmitter_ && source_ == NavBitSource::kOracle) && !tlm_) return std::nullopt;
  // The middle of the bit: robust to t being a hair off its edge.
  const signals::GpsTime mid = signals::add_seconds(t, 0.5 * kBit_s);
  const double start_tow = std::floor(mid.tow_s / kSubframe_s) * kSubframe_s;
  if (mid.week != cached_start_.week || start_tow != cached_start_.tow_s || cached_version_ != version_)
    build(signals::GpsTime{mid.week, start_tow});
  const int index = static_cast<int>((mid.tow_s - start_tow) / kBit_s);
  if (index < 0 || index >= 300 || !known_[static_cast<std::size_t>(index)]) return std::nullopt;
  return static_cast<int>(bits_[static_cast<std::size_t>(index)]);
}

}  // namespace ultratrack::receiver
