// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/navigation_store.hpp"

#include <algorithm>
#include <cmath>

#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"

namespace ultratrack::receiver {
namespace {

bool same_set(const signals::Ephemeris& a, const signals::Ephemeris& b) {
  return a.prn == b.prn && a.iode == b.iode && a.iodc == b.iodc && a.week == b.week && a.toe_s == b.toe_s;
}

}  // namespace

void NavigationStore::add_supplied(const std::vector<signals::Ephemeris>& ephemerides,
                                   const signals::KlobucharParameters& iono, const signals::UtcParameters& utc) {
  ephemerides_.insert(ephemerides_.end(), ephemerides.begin(), ephemerides.end());
  ionosphere_.set(iono, IonosphereSource::kNavigationFile, std::nullopt);
  if (utc.valid) utc_ = utc;
  supplied_navigation_ = std::make_shared<const SuppliedNavigation>(SuppliedNavigation{ephemerides_, iono, utc});
}

void NavigationStore::collect(NavigationDataChannel& nav, SatelliteStats& stats, std::int64_t sample) {
  if (nav.synchronised()) stats.frame_synced = true;
  const auto& decoder = nav.decoder();
  // Almanacs of every PRN, from any channel (a page every 30 s); the latest reference time wins.
  for (std::size_t prn = 1; prn < almanacs_.size(); ++prn) {
    const auto& a = decoder.almanacs()[prn];
    auto& mine = almanacs_[prn];
    if (a && (!mine || mine->week != a->week || mine->toa_s != a->toa_s)) mine = a;
  }
  if (!nav.take_new_ephemeris()) return;
  ionosphere_.set(decoder.klobuchar(), IonosphereSource::kBroadcast, sample);
  if (decoder.utc().valid) utc_ = decoder.utc();
  if (!decoder.ephemeris()) return;
  const signals::Ephemeris& eph = *decoder.ephemeris();
  stats.ephemeris_decoded = true;
  if (std::none_of(decoded_.begin(), decoded_.end(), [&](const auto& e) { return same_set(e, eph); }))
    decoded_.push_back(eph);
  if (std::none_of(ephemerides_.begin(), ephemerides_.end(), [&](const auto& e) { return same_set(e, eph); }))
    ephemerides_.push_back(eph);
}

std::optional<signals::Ephemeris> NavigationStore::orbit_of(int prn, const signals::GpsTime& t) const {
  if (auto eph = signals::select_ephemeris(ephemerides_, prn, t, {.include_unhealthy = true})) return *eph;
  const auto& a = almanacs_[static_cast<std::size_t>(prn)];
  if (a && std::abs(signals::seconds_between(t, signals::GpsTime{a->week, a->toa_s})) < signals::kSecondsPerWeek)
    return signals::almanac_orbit(*a);
  return std::nullopt;
}

}  // namespace ultratrack::receiver
