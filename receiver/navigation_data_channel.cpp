#include "receiver/navigation_data_channel.hpp"

namespace ultratrack::receiver {

NavigationDataChannel::NavigationDataChannel(int prn, int reference_week) : decoder_(prn, reference_week) {}

void NavigationDataChannel::reset() {
  frame_sync_.reset();
  tag_.reset();
  holding_ = false;
}

bool NavigationDataChannel::take_new_ephemeris() {
  const bool fresh = new_ephemeris_;
  new_ephemeris_ = false;
  return fresh;
}

void NavigationDataChannel::add_bit(float soft, std::int64_t first_code_period) {
  code_periods_[static_cast<std::size_t>(frame_sync_.bits_pushed() % kHistory)] = first_code_period;
  const auto out = frame_sync_.push(soft < 0.0f ? 1 : 0);
  if (!out) return;
  if (out->result.status != signals::LnavStatus::kOk) {
    if (!frame_sync_.locked() && !holding_) tag_.reset();
    return;
  }
  holding_ = false;
  decoder_.add(out->result.subframe);
  if (decoder_.last_update().ephemeris) new_ephemeris_ = true;
  polarity_ = out->result.subframe.inverted ? -1 : 1;
  const auto start = decoder_.last_subframe_start();
  if (start) predictor_.add_subframe(out->result.subframe, *start);
  if (start) tag_ = TransmitTimeTag{code_periods_[static_cast<std::size_t>(out->first_bit_index % kHistory)], *start};
}

}  // namespace ultratrack::receiver
