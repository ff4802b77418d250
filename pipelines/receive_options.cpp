// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/receive_options.hpp"

#include <algorithm>

#include "ins/imu_error_model.hpp"
#include "io/why_invalid.hpp"

namespace ultratrack::pipelines {

bool ReceiveOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string why) {
    if (error) *error = std::move(why);
    return false;
  };
  if (std::string why = io::why_invalid(receiver); !why.empty()) return fail(why);
  if (coupling != Coupling::kVector && vector_carrier != fusion::VectorCarrier::kAidedPll)
    return fail("--vector-carrier needs --coupling vector");
  if (std::string why; !nis_release.IsValid(&why)) return fail(why);
  if (!(ut_clock_loop_bw_hz >= 0.0 && ut_clock_loop_bw_hz <= 12.5))
    return fail("--ut-clock-loop-bw must be 0 (off) or in (0, 12.5] Hz (Bn T <= 0.25 at 20 ms)");
  if (!uses_imu(coupling)) return true;
  const auto& names = ins::imu_preset_names();
  if (std::find(names.begin(), names.end(), navigation.imu_preset) == names.end())
    return fail("unknown IMU preset '" + navigation.imu_preset + "'");
  if (!odometer.empty() && coupling != Coupling::kLoose && navigation.height_aiding.enabled)
    return fail("--odometer and [height_aiding] mode = \"auto\" are not combined (the odometer bounds the height)");
  if (align == AlignMode::Attitude) return fail("--align attitude is `fuse`'s (GPS attitude rows)");
  if (align == AlignMode::Config && !navigation.attitude_deg)
    return fail("--align config needs [initial] attitude_deg in --fusion-config");
  if (imu_time_origin.kind == ImuTimeOrigin::Kind::Tow &&
      !(imu_time_origin.tow_s >= 0.0 && imu_time_origin.tow_s < 604800.0))
    return fail("--imu-time-origin: a GPS time of week lies in [0, 604800) s");
  return true;
}

}  // namespace ultratrack::pipelines
