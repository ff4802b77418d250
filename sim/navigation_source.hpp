// SPDX-License-Identifier: GPL-3.0-or-later
// The broadcast data a scenario transmits: one ephemeris per PRN selected for the start time (healthy only
// unless the scenario includes unhealthy ones) from its RINEX nav file or the built-in nominal constellation,
// with the ionosphere and UTC parameters. A receiver given these ephemerides starts hot.
#pragma once

#include <string>
#include <vector>

#include "signals/ephemeris.hpp"
#include "signals/rinex_nav.hpp"
#include "sim/scenario.hpp"

namespace ultratrack::sim {

struct NavigationSource {
  std::string name;  // the RINEX file or "nominal"
  std::vector<signals::Ephemeris> ephemerides;
  signals::KlobucharParameters klobuchar;
  signals::UtcParameters utc;
};

// Throws io::InputError naming the RINEX file when it cannot be read or no ephemeris is valid at the start.
NavigationSource load_navigation(const Scenario& scenario);
// What a receiver of the scenario's signal could load from a nav file of that day (a hot start): the same
// ephemerides, ionosphere and UTC parameters.
signals::RinexNavData to_rinex_nav(const NavigationSource& navigation);

}  // namespace ultratrack::sim
