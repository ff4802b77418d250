#include "receive_vector.hpp"

#include <fmt/core.h>
#include <fmt/ostream.h>

#include "io/input_error.hpp"

namespace ultratrack::tools {

fusion::VectorCarrier parse_vector_carrier(const std::string& text) {
  if (text == "aided-pll") return fusion::VectorCarrier::kAidedPll;
  if (text == "fll") return fusion::VectorCarrier::kFll;
  if (text == "pll") return fusion::VectorCarrier::kPll;
  throw io::InputError("command line", "--vector-carrier must be aided-pll, fll or pll, got '" + text + "'");
}

fusion::VectorTrackingOptions vector_tracking_options(const receiver::ReceiverOptions& options,
                                                     fusion::VectorCarrier carrier) {
  fusion::VectorTrackingOptions v;
  v.carrier = carrier;
  v.ionosphere = options.pvt.ionosphere;
  v.troposphere = options.pvt.troposphere;
  v.code_spacing_chips = 2.0 * options.tracking.early_late_offset_chips;
  v.min_cn0_dbhz = options.tracking.cn0_loss_threshold_dbhz;
  return v;
}

ReceiveVector::ReceiveVector(const receiver::ReceiverOptions& options, const std::filesystem::path& dir,
                             fusion::VectorCarrier carrier)
    : fs_hz_(options.fs_hz),
      carrier_(carrier),
      filter_(vector_tracking_options(options, carrier)),
      channels_(dir / "vector.csv"),
      state_(dir / "vector_state.csv") {
  channels_.stream() << "sample,time_s,prn,vector,cn0_dbhz,pr_used,pr_innovation_m,pr_sigma_m,rate_used,"
                        "rate_innovation_mps,rate_sigma_mps,measured_doppler_hz,predicted_doppler_hz,"
                        "replica_code_rate_chips_per_s,predicted_code_rate_chips_per_s,code_jump_chips,coasting,coast_s,"
                        "predicted_sigma_chips,phase_tracking,phase_disc_cycles,phase_innovation_cycles,phase_sigma_cycles,"
                        "phase_nu_hz,phase_lock,phase_bn_hz,phase_jump_cycles,measurement_sample,replica_phase_mid_cycles\n";
  state_.stream() << "sample,time_s,week,tow_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,clock_bias_m,clock_drift_mps,"
                     "sigma_x_m,sigma_y_m,sigma_z_m,sigma_vx_mps,sigma_vy_mps,sigma_vz_mps,sigma_bias_m,"
                     "sigma_drift_mps,used,vector\n";
  filter_.set_log([this](const fusion::VectorEpochLog& e) { log(e); });
}

void ReceiveVector::attach(receiver::ReceiverEngine& engine, double interval_s) {
  engine.set_vector_loop(&filter_, interval_s);
}

void ReceiveVector::log(const fusion::VectorEpochLog& e) {
  const double t = static_cast<double>(e.sample) / fs_hz_;
  for (const auto& c : e.channels)
    fmt::print(channels_.stream(), "{},{:.3f},{},{:d},{:.2f},{:d},{:.3f},{:.3f},{:d},{:.4f},{:.4f},{:.3f},{:.3f},{:.4f},{:.4f},{:.4f},{:d},{:.3f},{:.4f},{:d},{:.5f},{:.5f},{:.5f},{:.3f},{:.3f},{:.2f},{:.5f},{},{:.5f}\n",
               e.sample, t, c.prn, c.vector, c.cn0_dbhz, c.pr_used, c.pr_innovation_m, c.pr_sigma_m, c.rate_used,
               c.rate_innovation_mps, c.rate_sigma_mps, c.measured_doppler_hz, c.predicted_doppler_hz,
               c.replica_code_rate_chips_per_s, c.predicted_code_rate_chips_per_s, c.code_jump_chips, c.coasting,
               c.coast_s, c.predicted_sigma_chips, c.phase_tracking, c.phase_disc_cycles, c.phase_innovation_cycles,
               c.phase_sigma_cycles, c.phase_nu_hz, c.phase_lock, c.phase_bn_hz, c.phase_jump_cycles, c.measurement_sample,
               c.replica_phase_mid_cycles);
  for (const auto& c : e.channels) coasting_channel_epochs_ += c.vector && c.coasting;
  const auto& x = e.x;
  const auto& s = e.sigma;
  fmt::print(state_.stream(),
             "{},{:.3f},{},{:.6f},{:.3f},{:.3f},{:.3f},{:.4f},{:.4f},{:.4f},{:.3f},{:.4f},{:.3f},{:.3f},{:.3f},{:.4f},"
             "{:.4f},{:.4f},{:.3f},{:.4f},{},{}\n",
             e.sample, t, e.receive_time.week, e.receive_time.tow_s, x(0), x(1), x(2), x(3), x(4), x(5), x(6), x(7), s(0),
             s(1), s(2), s(3), s(4), s(5), s(6), s(7), e.used, e.vector);
  if (e.vector > 0) ++vector_epochs_;
  vector_channel_epochs_ += e.vector;
}

std::string ReceiveVector::summary_json() const {
  return fmt::format("\"vector\": {{\"carrier\": \"{}\", \"vector_epochs\": {}, \"vector_channel_epochs\": {}, "
                     "\"coasting_channel_epochs\": {}, \"filter_starts\": {}, \"filter_resets\": {}, \"frequency_resets\": {}, "
                     "\"phase_arcs\": {}, \"phase_losses\": {}}}",
                     fusion::to_string(carrier_), vector_epochs_, vector_channel_epochs_, coasting_channel_epochs_,
                     filter_.initialisations(), filter_.resets(), filter_.frequency_resets(), filter_.phase_arcs(),
                     filter_.phase_losses());
}

void ReceiveVector::finish() {
  channels_.commit();
  state_.commit();
}

}  // namespace ultratrack::tools
