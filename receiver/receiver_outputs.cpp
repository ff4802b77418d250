// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/receiver_outputs.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <cmath>
#include <system_error>

#include "signals/input_error.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::receiver {
namespace {

const std::filesystem::path& made(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw signals::InputError(dir.string(), "cannot create the output folder" + (ec ? ": " + ec.message() : ""));
  return dir;
}

RinexObsHeaderInfo obs_header(double interval_s) {
  RinexObsHeaderInfo info;
  info.interval_s = interval_s;
  return info;
}

}  // namespace

ReceiverOutputs::ReceiverOutputs(const std::filesystem::path& dir, double fs_hz, double observation_interval_s)
    : dir_(made(dir)),
      fs_hz_(fs_hz),
      solution_(dir_ / "solution.csv"),
      kml_(dir_ / "solution.kml"),
      obs_(dir_ / "observations.rnx", obs_header(observation_interval_s)),
      tracking_(dir_ / "tracking.csv") {
  tracking_.stream() << "prn,sample,time_s,prompt_i,prompt_q,integration_ms,cn0_dbhz,doppler_hz,code_phase_chips,"
                        "state,pli,phase_locked,frame_synced,coherent_ms\n";
}

void ReceiverOutputs::on_tracking(const TrackingRecord& r) {
  fmt::print(tracking_.stream(), "{},{},{:.6f},{:.1f},{:.1f},{},{:.2f},{:.3f},{:.4f},{},{:.3f},{},{},{}\n", r.prn,
             r.sample_index, static_cast<double>(r.sample_index) / fs_hz_, r.prompt.real(), r.prompt.imag(),
             r.integration_ms, r.cn0_dbhz, r.doppler_hz, r.code_phase_chips, to_string(r.state), r.pli,
             r.phase_locked ? 1 : 0, r.frame_synced ? 1 : 0, r.coherent_ms);
}

void ReceiverOutputs::on_observations(const ObservationEpoch& epoch) { obs_.write(epoch); }

void ReceiverOutputs::on_fix(const PvtSolution& fix, const ObservationEpoch&) {
  if (!nmea_) nmea_.emplace(dir_ / "solution.nmea", signals::leap_seconds_at(fix.time));
  solution_.write(fix);
  nmea_->write(fix);
  kml_.write(fix);
  sum_r_e_m_ += fix.r_e_m;
  ++fixes_;
}

void ReceiverOutputs::finish(const ReceiverEngine& engine, const RunDescription& run) {
  if (!nmea_) nmea_.emplace(dir_ / "solution.nmea", 18);  // no fix: an empty NMEA file
  obs_.set_comments(ionosphere_comment_lines(engine.ionosphere(), engine.stats().first_sample, fs_hz_,
                                             engine.options().pvt.ionosphere));
  obs_.finish(fixes_ > 0 ? Eigen::Vector3d(sum_r_e_m_ / fixes_) : Eigen::Vector3d::Zero());
  signals::RinexNavData nav;
  nav.ephemerides = engine.decoded_ephemerides();
  nav.klobuchar = engine.ionosphere().known();
  nav.utc = engine.utc();
  nav.has_leap_seconds = engine.utc().valid;
  write_rinex_nav_304(dir_ / "navigation.rnx", nav);
  write_summary_json(dir_ / "summary.json", engine, run);
  solution_.finish();
  nmea_->finish();
  kml_.finish();
  tracking_.commit();
}

}  // namespace ultratrack::receiver
