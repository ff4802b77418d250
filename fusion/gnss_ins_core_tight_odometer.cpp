// SPDX-License-Identifier: GPL-3.0-or-later
// The GNSS/INS filter of the tight coupling with odometer aiding: 15 INS + 2 clock + 4 odometer states (EKF and UKF).
#include "fusion/gnss_ins_core_impl.hpp"

namespace ultratrack::fusion::gnss_ins_detail {

template std::unique_ptr<CoreBase> make_core<TightOdometerLayout>(const ins::NavState&, const IntegrationOptions&);

}  // namespace ultratrack::fusion::gnss_ins_detail
