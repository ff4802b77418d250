// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/fade_detector.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

void FadeDetector::add(std::complex<float> prompt, std::complex<float> noise, std::optional<double> cn0_dbhz,
                       double t_s) {
  const double power = std::norm(std::complex<double>(prompt));
  if (!std::isfinite(power) || !(t_s > 0.0)) return;
  // The sample count of an epoch varies with the code Doppler: lengths within 1 % are the same length.
  if (std::abs(t_s - epoch_s_) > 0.01 * t_s) {
    epoch_s_ = t_s;
    mean_power_ = power;
    mean_time_s_ = t_s;
    faded_ = false;
    above_ = 0;
    return;
  }
  const double threshold = opt_.fade_ratio * mean_power_;
  if (faded_) {
    above_ = power >= threshold ? above_ + 1 : 0;
    if (above_ >= opt_.recover_epochs) {
      faded_ = false;
      return;  // the reference stays that of the signal before the fade
    }
    if (presence_.add(prompt, noise, t_s).value_or(false)) {  // a step down: the signal is there, weaker
      faded_ = false;
      mean_power_ = power;
      mean_time_s_ = opt_.reference_time_s;
    }
    return;
  }
  const bool tested =
      mean_time_s_ >= opt_.reference_time_s && cn0_dbhz && std::pow(10.0, *cn0_dbhz / 10.0) * t_s >= opt_.min_snr;
  if (tested && power < threshold) {
    faded_ = true;
    above_ = 0;
    ++fades_;
    const int window = std::max(1, static_cast<int>(std::lround(opt_.present_window_s / t_s)));
    presence_ = SignalPresenceTest(window, opt_.present_dbhz);
    return;
  }
  mean_power_ += std::min(1.0, t_s / opt_.reference_time_s) * (power - mean_power_);
  mean_time_s_ += t_s;
}

}  // namespace ultratrack::receiver
