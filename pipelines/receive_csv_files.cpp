// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/receive_csv_files.hpp"

#include <fmt/core.h>
#include <fmt/format.h>
#include <fmt/ostream.h>

#include <iterator>

namespace ultratrack::pipelines {

ReceiveCsvFiles::ReceiveCsvFiles(const std::filesystem::path& dir, Coupling coupling, double fs_hz) : fs_hz_(fs_hz) {
  if (uses_imu(coupling)) nav_.emplace(dir / "nav.csv");
  if (coupling == Coupling::kVector) {
    vector_channels_.emplace(dir / "vector.csv");
    vector_state_.emplace(dir / "vector_state.csv");
    vector_channels_->stream()
        << "sample,time_s,prn,vector,cn0_dbhz,pr_used,pr_innovation_m,pr_sigma_m,rate_used,"
           "rate_innovation_mps,rate_sigma_mps,measured_doppler_hz,predicted_doppler_hz,"
           "replica_code_rate_chips_per_s,predicted_code_rate_chips_per_s,code_jump_chips,coasting,coast_s,"
           "predicted_sigma_chips,phase_tracking,phase_disc_cycles,phase_innovation_cycles,phase_sigma_cycles,"
           "phase_nu_hz,phase_lock,phase_bn_hz,phase_jump_cycles,measurement_sample,replica_phase_mid_cycles\n";
    vector_state_->stream() << "sample,time_s,week,tow_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,clock_bias_m,clock_drift_mps,"
                               "sigma_x_m,sigma_y_m,sigma_z_m,sigma_vx_mps,sigma_vy_mps,sigma_vz_mps,sigma_bias_m,"
                               "sigma_drift_mps,used,vector\n";
  }
  if (coupling == Coupling::kUltraTight) {
    ultratight_.emplace(dir / "ultratight.csv");
    ultratight_->stream()
        << "sample,time_s,prn,synchronised,ultratight,coasting,coast_s,cn0_dbhz,measured_pseudorange_m,"
           "predicted_pseudorange_m,measured_doppler_hz,predicted_doppler_hz,replica_carrier_hz,"
           "replica_code_rate_chips_per_s,predicted_code_rate_chips_per_s,code_jump_chips,updated,accepted,"
           "nis,innovation_1,innovation_2,innovation_3,innovation_4,innovation_5,innovation_6,carrier_offset_hz,"
           "carrier_runaway\n";
  }
}

void ReceiveCsvFiles::on_navigation(const ins::NavState& nav, const NavSigma& sigma) {
  if (nav_) nav_->write(nav, sigma);
}

void ReceiveCsvFiles::on_vector_epoch(const fusion::VectorEpochLog& e) {
  if (!vector_channels_) return;
  const double t = static_cast<double>(e.sample) / fs_hz_;
  for (const auto& c : e.channels)
    fmt::print(vector_channels_->stream(),
               "{},{:.3f},{},{:d},{:.2f},{:d},{:.3f},{:.3f},{:d},{:.4f},{:.4f},{:.3f},{:.3f},{:.4f},{:.4f},{:.4f},{:d},"
               "{:.3f},{:.4f},{:d},{:.5f},{:.5f},{:.5f},{:.3f},{:.3f},{:.2f},{:.5f},{},{:.5f}\n",
               e.sample, t, c.prn, c.vector, c.cn0_dbhz, c.pr_used, c.pr_innovation_m, c.pr_sigma_m, c.rate_used,
               c.rate_innovation_mps, c.rate_sigma_mps, c.measured_doppler_hz, c.predicted_doppler_hz,
               c.replica_code_rate_chips_per_s, c.predicted_code_rate_chips_per_s, c.code_jump_chips, c.coasting,
               c.coast_s, c.predicted_sigma_chips, c.phase_tracking, c.phase_disc_cycles, c.phase_innovation_cycles,
               c.phase_sigma_cycles, c.phase_nu_hz, c.phase_lock, c.phase_bn_hz, c.phase_jump_cycles,
               c.measurement_sample, c.replica_phase_mid_cycles);
  const auto& x = e.x;
  const auto& s = e.sigma;
  fmt::print(vector_state_->stream(),
             "{},{:.3f},{},{:.6f},{:.3f},{:.3f},{:.3f},{:.4f},{:.4f},{:.4f},{:.3f},{:.4f},{:.3f},{:.3f},{:.3f},{:.4f},"
             "{:.4f},{:.4f},{:.3f},{:.4f},{},{}\n",
             e.sample, t, e.receive_time.week, e.receive_time.tow_s, x(0), x(1), x(2), x(3), x(4), x(5), x(6), x(7),
             s(0), s(1), s(2), s(3), s(4), s(5), s(6), s(7), e.used, e.vector);
}

void ReceiveCsvFiles::on_ultratight_epoch(const UltraTightEpochLog& e) {
  if (!ultratight_) return;
  // The epoch's rows formatted into one buffer and written at once (fmt::print on the stream formats each call
  // into a temporary string first).
  fmt::memory_buffer rows;
  for (const UltraTightChannelLog& c : e.channels) {
    fmt::format_to(std::back_inserter(rows),
                   "{},{:.3f},{},{:d},{:d},{:d},{:.2f},{:.2f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.4f},{:.4f},{:.5f},{"
                   ":d},{:d},{:.3f}",
                   e.sample, e.time_s, c.prn, c.synchronised, c.ultratight, c.coasting, c.coast_s, c.cn0_dbhz,
                   c.measured_pseudorange_m, c.predicted_pseudorange_m, c.measured_doppler_hz, c.predicted_doppler_hz,
                   c.replica_carrier_hz, c.replica_code_rate_chips_per_s, c.predicted_code_rate_chips_per_s,
                   c.code_jump_chips, c.updated, c.accepted, c.nis);
    for (const double v : c.innovation) fmt::format_to(std::back_inserter(rows), ",{:.4f}", v);
    fmt::format_to(std::back_inserter(rows), ",{:.3f},{:d}\n", c.carrier_offset_hz, c.carrier_runaway);
  }
  ultratight_->stream().write(rows.data(), static_cast<std::streamsize>(rows.size()));
}

void ReceiveCsvFiles::commit() {
  if (nav_) nav_->commit();
  if (vector_channels_) vector_channels_->commit();
  if (vector_state_) vector_state_->commit();
  if (ultratight_) ultratight_->commit();
}

}  // namespace ultratrack::pipelines
