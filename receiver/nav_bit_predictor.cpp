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

// The issue of data a subframe 1-3 carries (IODC in subframe 1, IODE in 2 and 3).
std::uint32_t issue_of_data(const signals::LnavDataWords& w, int subframe_id) {
  namespace l = signals::lnav;
  if (subframe_id == 1)
    return signals::get_lnav_field(w, l::kIodcMsb.first, l::kIodcMsb.length) << 8 |
           signals::get_lnav_field(w, l::kIodcLsb.first, l::kIodcLsb.length);
  const l::Field f = subframe_id == 2 ? l::kIode2 : l::kIode3;
  return signals::get_lnav_field(w, f.first, f.length);
}

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

// Words 3-10 of a decoded subframe 1-3 against the nav file's under the same issue of data, once per stored copy.
void NavBitPredictor::compare_with_nav_file(std::size_t index) {
  auto& stored = subframes_[index];
  if (!transmitter_ || !stored || stored->compared) return;
  stored->compared = true;
  signals::LnavDataWords predicted{};
  try {
    predicted = transmitter_->subframe_data(stored->start);
  } catch (const io::InputError&) {
    return;  // a nav-file field that does not fit its bits: nothing to compare
  }
  const int id = static_cast<int>(index) + 1;
  if (issue_of_data(predicted, id) != issue_of_data(stored->words, id)) return;
  for (std::size_t w = 2; w < 10; ++w) {
    const std::uint32_t mask = w == 9 ? 0xFFFFFCu : 0xFFFFFFu;  // word 10's last two bits solve its parity
    if (((predicted[w] ^ stored->words[w]) & mask) == 0)
      ++nav_words_agreed_;
    else
      ++nav_words_disagreed_;
  }
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
  if (data_known) w = stored->words;
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
