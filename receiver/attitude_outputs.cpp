// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/attitude_outputs.hpp"

#include <fmt/core.h>

#include <cmath>

#include "io/units.hpp"
#include "receiver/receiver_summary.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::receiver {
namespace {

std::filesystem::path made(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw signals::InputError(dir.string(), "cannot create the output folder: " + ec.message());
  return dir;
}

std::string json_text(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

AttitudeOutputs::AttitudeOutputs(const std::filesystem::path& dir, double fs_hz, double observation_interval_s,
                                 receiver::AttitudeSolverOptions solver, std::vector<double> line_bias_cycles)
    : dir_(made(dir)),
      fs_hz_(fs_hz),
      position_(made(dir / "position"), fs_hz, observation_interval_s),
      solver_(std::move(solver)),
      line_bias_cycles_(std::move(line_bias_cycles)),
      attitude_(dir_ / "attitude.csv"),
      phases_(dir_ / "antenna_phases.csv") {
  attitude_.stream() << "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,"
                        "num_sats,fixed,ratio\n";
  phases_.stream() << "gps_week,tow_s,prn,antenna,elevation_deg,carrier_phase_cycles,cn0_dbhz,usable,slip\n";
}

void AttitudeOutputs::on_antenna_phases(const receiver::AntennaPhaseEpoch& epoch) {
  corrected_ = epoch;
  for (auto& sat : corrected_.satellites)
    for (int k = 0; k < sat.num_antennas && k < static_cast<int>(line_bias_cycles_.size()); ++k)
      sat.carrier_phase_cycles[static_cast<std::size_t>(k)] -= line_bias_cycles_[static_cast<std::size_t>(k)];
  auto& ph = phases_.stream();
  for (const auto& sat : corrected_.satellites) {
    for (int k = 0; k < sat.num_antennas; ++k) {
      const auto i = static_cast<std::size_t>(k);
      ph << fmt::format("{},{:.4f},{},{},{:.3f},{:.5f},{:.2f},{},{}\n", epoch.receive_time.week,
                        epoch.receive_time.tow_s, sat.prn, k, sat.elevation_rad / io::kRadPerDeg,
                        sat.carrier_phase_cycles[i], sat.cn0_dbhz[i], sat.usable[i] ? 1 : 0, sat.slip[i] ? 1 : 0);
      if (sat.slip[i]) ++stats_.slips[i];
      if (!sat.usable[i]) ++stats_.unusable[i];
    }
  }
  const receiver::AttitudeSolution sol = solver_.update(corrected_);
  ++stats_.epochs;
  if (!stats_.first_epoch_sample) stats_.first_epoch_sample = epoch.sample_index;
  if (sol.fixed) ++stats_.fixed_epochs;
  if (sol.new_fix) ++stats_.new_fixes;
  auto& out = attitude_.stream();
  out << fmt::format("{},{:.4f},", epoch.receive_time.week, epoch.receive_time.tow_s);
  if (sol.valid) {
    ++stats_.attitude_epochs;
    stats_.sum_sats += sol.num_sats;
    if (!stats_.first_attitude_sample) stats_.first_attitude_sample = epoch.sample_index;
    const auto sd = [&](int i) { return std::sqrt(std::max(0.0, sol.covariance_rad2(i, i))) / io::kRadPerDeg; };
    out << fmt::format("{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},", sol.roll_rad / io::kRadPerDeg,
                       sol.pitch_rad / io::kRadPerDeg, sol.yaw_rad / io::kRadPerDeg, sd(0), sd(1), sd(2));
  } else {
    out << "nan,nan,nan,nan,nan,nan,";
  }
  out << fmt::format("{},{},{:.3f}\n", sol.num_sats, sol.fixed ? 1 : 0, sol.ratio);
}

void AttitudeOutputs::finish(const receiver::ReceiverEngine& engine, const receiver::RunDescription& run,
                             const std::vector<std::string>& inputs) {
  position_.finish(engine, run);
  attitude_.commit();
  phases_.commit();
  const double signal_s = receiver::processed_seconds(engine);
  const auto& s = stats_;
  const double first_s = s.first_attitude_sample
                             ? static_cast<double>(*s.first_attitude_sample - engine.stats().first_sample) / fs_hz_
                             : -1.0;
  int after_first = 0;  // epochs from the first attitude on
  if (s.first_attitude_sample && s.first_epoch_sample)
    after_first =
        s.epochs - static_cast<int>(std::llround(static_cast<double>(*s.first_attitude_sample - *s.first_epoch_sample) /
                                                 (engine.options().observation_interval_s * fs_hz_)));
  std::string files, slips, unusable;
  for (const auto& f : inputs) files += fmt::format("{}\"{}\"", files.empty() ? "" : ", ", json_text(f));
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    slips += fmt::format("{}{}", k ? ", " : "", s.slips[k]);
    unusable += fmt::format("{}{}", k ? ", " : "", s.unusable[k]);
  }
  const std::string json = fmt::format(
      "{{\n  \"command\": \"attitude\",\n  \"inputs\": [{}],\n  \"antennas\": {},\n  \"format\": \"{}\",\n"
      "  \"fs_hz\": {},\n  \"if_hz\": {},\n  \"signal_s\": {:.3f},\n  \"wall_s\": {:.3f},\n  \"realtime_factor\": "
      "{:.2f},\n"
      "  \"interrupted\": {},\n  \"position_fix\": {},\n  \"phase_epochs\": {},\n  \"attitude_epochs\": {},\n"
      "  \"fixed_epochs\": {},\n  \"fix_rate\": {:.4f},\n  \"fix_rate_after_first_fix\": {:.4f},\n  \"new_fixes\": "
      "{},\n"
      "  \"time_to_first_attitude_s\": {:.3f},\n  \"mean_satellites\": {:.2f},\n"
      "  \"slip_flags_per_antenna\": [{}],\n  \"unusable_per_antenna\": [{}]\n}}\n",
      files, inputs.size(), json_text(run.format), run.fs_hz, run.if_hz, signal_s, run.wall_time_s,
      run.wall_time_s > 0 ? signal_s / run.wall_time_s : 0.0, run.interrupted, engine.stats().fixes > 0, s.epochs,
      s.attitude_epochs, s.fixed_epochs, s.epochs ? static_cast<double>(s.fixed_epochs) / s.epochs : 0.0,
      after_first > 0 ? static_cast<double>(s.fixed_epochs) / after_first : 0.0, s.new_fixes, first_s,
      s.attitude_epochs ? s.sum_sats / s.attitude_epochs : 0.0, slips, unusable);
  io::write_file_atomically(dir_ / "summary.json", json);
}

}  // namespace ultratrack::receiver
