// SPDX-License-Identifier: GPL-3.0-or-later
// What the receiver knows of the navigation message: every ephemeris (supplied and decoded, each set once), the
// decoded ones apart, the latest almanac per PRN, the Klobuchar parameters in use and UTC parameters, and the supplied
// sets shared with the channels as known bits (data wipe-off). Filled on the engine's caller thread only.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "receiver/ionosphere_model.hpp"
#include "receiver/receiver_channel.hpp"
#include "receiver/receiver_results.hpp"
#include "signals/almanac.hpp"
#include "signals/ephemeris.hpp"

namespace ultratrack::receiver {

class NavigationStore final {
 public:
  // Hot start: ephemerides (and Klobuchar/UTC when valid) known before decoding any.
  void add_supplied(const std::vector<signals::Ephemeris>& ephemerides, const signals::KlobucharParameters& iono,
                    const signals::UtcParameters& utc);
  // What a channel's decoder holds: almanacs of every PRN, and with a new ephemeris its set and the broadcast
  // Klobuchar/UTC parameters (in use from `sample`, the end of the part just fed); stats: the channel's PRN's
  // frame-sync and ephemeris flags.
  void collect(NavigationDataChannel& nav, SatelliteStats& stats, std::int64_t sample);
  // The orbit known for a PRN at t: its broadcast ephemeris, else its decoded almanac (within a week of toa).
  std::optional<signals::Ephemeris> orbit_of(int prn, const signals::GpsTime& t) const;

  const std::vector<signals::Ephemeris>& ephemerides() const { return ephemerides_; }  // supplied + decoded
  const std::vector<signals::Ephemeris>& decoded() const { return decoded_; }
  // The Klobuchar set in use (a default one until a nav file's or the broadcast one is known) and its history.
  const signals::KlobucharParameters& klobuchar() const { return ionosphere_.parameters(); }
  const IonosphereModel& ionosphere() const { return ionosphere_; }
  const signals::UtcParameters& utc() const { return utc_; }
  const std::array<std::optional<signals::Almanac>, 33>& almanacs() const { return almanacs_; }
  const std::shared_ptr<const SuppliedNavigation>& supplied() const { return supplied_navigation_; }

 private:
  std::vector<signals::Ephemeris> ephemerides_;  // all known: supplied + decoded
  std::vector<signals::Ephemeris> decoded_;
  std::array<std::optional<signals::Almanac>, 33> almanacs_{};
  IonosphereModel ionosphere_;                                     // Klobuchar in use (default, nav file, broadcast)
  std::shared_ptr<const SuppliedNavigation> supplied_navigation_;  // the nav file's sets: known bits (issue 7)
  signals::UtcParameters utc_;
};

}  // namespace ultratrack::receiver
