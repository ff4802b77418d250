// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/vector_loop_driver.hpp"

#include <fmt/core.h>

namespace ultratrack::pipelines {

fusion::VectorTrackingOptions vector_tracking_options(const receiver::ReceiverOptions& options,
                                                      fusion::VectorCarrier carrier,
                                                      const fusion::NisReleaseOptions& nis) {
  fusion::VectorTrackingOptions v;
  v.carrier = carrier;
  v.nis = nis;
  v.ionosphere = options.pvt.ionosphere;
  v.troposphere = options.pvt.troposphere;
  v.code_spacing_chips = 2.0 * options.tracking.early_late_offset_chips;
  v.min_cn0_dbhz = options.tracking.cn0_loss_threshold_dbhz;
  return v;
}

VectorLoopDriver::VectorLoopDriver(const receiver::ReceiverOptions& options, ReceiveSink& sink,
                                   fusion::VectorCarrier carrier, const fusion::NisReleaseOptions& nis)
    : carrier_(carrier), filter_(vector_tracking_options(options, carrier, nis)), sink_(sink) {
  filter_.set_log([this](const fusion::VectorEpochLog& e) { log(e); });
}

void VectorLoopDriver::attach(receiver::ReceiverEngine& engine, double interval_s) {
  engine.set_vector_loop(&filter_, interval_s);
}

void VectorLoopDriver::log(const fusion::VectorEpochLog& e) {
  sink_.on_vector_epoch(e);
  for (const auto& c : e.channels) coasting_channel_epochs_ += c.vector && c.coasting;
  if (e.vector > 0) ++vector_epochs_;
  vector_channel_epochs_ += e.vector;
}

std::string VectorLoopDriver::summary_json() const {
  return fmt::format(
      "\"vector\": {{\"carrier\": \"{}\", \"vector_epochs\": {}, \"vector_channel_epochs\": {}, "
      "\"coasting_channel_epochs\": {}, \"filter_starts\": {}, \"filter_resets\": {}, \"frequency_resets\": {}, "
      "\"phase_arcs\": {}, \"phase_losses\": {}, \"nis_window\": {}, \"nis_probability\": {:g}, {}}}",
      fusion::to_string(carrier_), vector_epochs_, vector_channel_epochs_, coasting_channel_epochs_,
      filter_.initialisations(), filter_.resets(), filter_.frequency_resets(), filter_.phase_arcs(),
      filter_.phase_losses(), filter_.options().nis.window, filter_.options().nis.probability,
      filter_.release_log().json_members());
}

std::string VectorLoopDriver::report() const {
  return fmt::format(
      "receive: vector tracking: {} epochs with channels in vector mode ({} channel-epochs), filter "
      "started {} times, reset {} times; {} channel-epochs coasting; {} channels released by their NIS",
      vector_epochs_, vector_channel_epochs_, filter_.initialisations(), filter_.resets(), coasting_channel_epochs_,
      filter_.release_log().count("channel_nis"));
}

}  // namespace ultratrack::pipelines
