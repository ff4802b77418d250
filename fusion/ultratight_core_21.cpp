// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight filter on 21 states: + the odometer's four (UltraTightOptions::odometer), EKF and UKF.
#include "fusion/ultratight_core.hpp"

namespace ultratrack::fusion::ultratight_detail {

template std::unique_ptr<UltraTightCoreBase> make_core<21>(const ins::NavState&, std::vector<signals::Ephemeris>,
                                                           const UltraTightOptions&, const StateMatrix<21>&);

}  // namespace ultratrack::fusion::ultratight_detail
