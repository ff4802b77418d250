#include "receiver/presence_test.hpp"

#include <algorithm>
#include <cmath>

namespace ultratrack::receiver {

SignalPresenceTest::SignalPresenceTest(int window_epochs, double threshold_dbhz)
    : window_(std::max(1, window_epochs)), threshold_dbhz_(threshold_dbhz) {}

std::optional<bool> SignalPresenceTest::add(std::complex<float> prompt, std::complex<float> noise, double t_s) {
  // Epochs of one length vary by a sample with the code Doppler (20 code periods): 1 % tells another length.
  if (n_ > 0 && std::abs(t_s - t_s_) > 0.01 * t_s_) reset();
  t_s_ = t_s;
  prompt_power_ += std::norm(std::complex<double>(prompt));
  noise_power_ += std::norm(std::complex<double>(noise));
  if (++n_ < window_) return std::nullopt;
  const double snr = noise_power_ > 0.0 ? prompt_power_ / noise_power_ - 1.0 : 0.0;
  last_cn0_dbhz_ = snr > 0.0 && t_s > 0.0 ? 10.0 * std::log10(snr / t_s) : -100.0;
  const bool present = t_s > 0.0 && snr >= std::pow(10.0, threshold_dbhz_ / 10.0) * t_s;
  reset();
  t_s_ = t_s;
  return present;
}

}  // namespace ultratrack::receiver
