// SPDX-License-Identifier: GPL-3.0-or-later
#include "sim/navigation_source.hpp"

#include <fmt/core.h>

#include "io/input_error.hpp"
#include "signals/ephemeris_selection.hpp"
#include "signals/gps_constants.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::sim {

NavigationSource load_navigation(const Scenario& s) {
  NavigationSource nav;
  const signals::GpsTime start{s.gps_week, s.tow_s};
  std::vector<signals::Ephemeris> sets;
  if (!s.rinex.empty()) {
    const auto path = resolve_path(s, s.rinex);
    auto data = signals::read_rinex_nav(path);
    nav.name = path.string();
    sets = std::move(data.ephemerides);
    nav.klobuchar = data.klobuchar;
    nav.utc = data.utc;
  } else {
    auto c = signals::nominal_constellation(start);
    nav.name = "nominal";
    sets = std::move(c.ephemerides);
    nav.klobuchar = c.klobuchar;
    nav.utc = c.utc;
  }
  signals::EphemerisSelectionOptions opt;
  opt.include_unhealthy = s.include_unhealthy;
  for (int prn = signals::kMinPrn; prn <= signals::kMaxPrn; ++prn)
    if (auto e = signals::select_ephemeris(sets, prn, start, opt)) nav.ephemerides.push_back(*e);
  if (nav.ephemerides.empty()) {
    throw io::InputError(nav.name, fmt::format("no ephemeris is valid at GPS week {} tow {} s (scenario {})",
                                               s.gps_week, s.tow_s, s.source.string()));
  }
  return nav;
}

signals::RinexNavData to_rinex_nav(const NavigationSource& navigation) {
  signals::RinexNavData nav;
  nav.ephemerides = navigation.ephemerides;
  nav.klobuchar = navigation.klobuchar;
  nav.utc = navigation.utc;
  return nav;
}

}  // namespace ultratrack::sim
