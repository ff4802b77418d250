// SPDX-License-Identifier: GPL-3.0-or-later
// The ultra-tight filter on 17 states: the INS and receiver clock errors, EKF and UKF.
#include "fusion/ultratight_core.hpp"

namespace ultratrack::fusion::ultratight_detail {

template std::unique_ptr<UltraTightCoreBase> make_core<17>(const ins::NavState&, std::vector<signals::Ephemeris>,
                                                           const UltraTightOptions&, const StateMatrix<17>&);

}  // namespace ultratrack::fusion::ultratight_detail
