// SPDX-License-Identifier: GPL-3.0-or-later
// The GNSS/INS filter behind fusion::GnssInsIntegration, one compiled variant per state layout (internal to fusion).
// A layout says which states follow the INS errors: the receiver clock (tight), the terrain height (tight with
// height aiding), the odometer's (loose with odometer aiding), three Gauss-Markov fix errors (loose). Each layout's
// make_core is compiled in its own gnss_ins_core_<layout>.cpp from gnss_ins_core_impl.hpp, so that the twelve
// EKF/UKF variants build in parallel instead of one source taking minutes and gigabytes.
#pragma once

#include <memory>
#include <variant>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"

namespace ultratrack::fusion::gnss_ins_detail {

struct PendingFix {
  GnssFix fix;
};
struct PendingEpoch {
  receiver::ObservationEpoch epoch;
  std::vector<signals::Ephemeris> ephemerides;
  signals::KlobucharParameters iono;
};
struct PendingAttitude {
  GnssAttitude attitude;
};
struct PendingOdometer {
  OdometerSpeed speed;
};
using Pending = std::variant<PendingFix, PendingEpoch, PendingAttitude, PendingOdometer>;

struct CoreBase {
  virtual ~CoreBase() = default;
  virtual void add_pending(double t_s, Pending p) = 0;
  virtual void add_imu(const ins::ImuIncrement& inc) = 0;
  virtual NominalState nominal() const = 0;
  virtual Eigen::MatrixXd covariance() const = 0;
  IntegrationOutput output;
  IntegrationCounters counters;
  std::vector<UpdateRecord> records;
  std::vector<RecoveryEvent> recovery_events;
};

// The filter's states: the INS errors (15; 17 with the receiver clock in tight mode), then what is appended.
// Tight with height aiding: + the terrain height [17] (height_aiding.hpp). Odometer aiding: + VMS delay,
// misalignment, scale factor at [kNav, kNav + 4) (odometer_error_model.hpp; [15, 19) loose, [17, 21) tight). Loose
// with Gauss-Markov fix errors: + three NED fix-error states after all the others (fix_error_model.hpp).
template <bool Tight, bool Terrain, bool Odometer, bool FixError>
struct Layout {
  static_assert(!(Terrain && Odometer), "height aiding and odometer aiding are not combined");
  static_assert(!(Tight && FixError), "fix-error states are for fixes (loose)");
  static constexpr bool kHasClock = Tight, kHasTerrain = Terrain, kHasOdometer = Odometer, kHasFixError = FixError;
  static constexpr int kNav = Tight ? 17 : 15;                                 // INS (and clock) error states
  static constexpr int kBase = kNav + (Terrain ? 1 : 0) + (Odometer ? 4 : 0);  // before the fix-error states
  static constexpr int kOdo = kNav;                                            // first odometer state
  static constexpr int kFix = kBase;                                           // first fix-error state
  static constexpr int N = kBase + (FixError ? 3 : 0);
};

using LooseLayout = Layout<false, false, false, false>;
using LooseFixErrorLayout = Layout<false, false, false, true>;
using OdometerLayout = Layout<false, false, true, false>;
using OdometerFixErrorLayout = Layout<false, false, true, true>;
using TightLayout = Layout<true, false, false, false>;
using TightTerrainLayout = Layout<true, true, false, false>;
using TightOdometerLayout = Layout<true, false, true, false>;

// The filter of layout L (EKF or UKF as the options say), started at `initial`.
template <class L>
std::unique_ptr<CoreBase> make_core(const ins::NavState& initial, const IntegrationOptions& options);
extern template std::unique_ptr<CoreBase> make_core<LooseLayout>(const ins::NavState&, const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<LooseFixErrorLayout>(const ins::NavState&,
                                                                         const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<OdometerLayout>(const ins::NavState&, const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<OdometerFixErrorLayout>(const ins::NavState&,
                                                                            const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<TightLayout>(const ins::NavState&, const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<TightTerrainLayout>(const ins::NavState&,
                                                                        const IntegrationOptions&);
extern template std::unique_ptr<CoreBase> make_core<TightOdometerLayout>(const ins::NavState&,
                                                                         const IntegrationOptions&);

}  // namespace ultratrack::fusion::gnss_ins_detail
