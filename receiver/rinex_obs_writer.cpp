// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/rinex_obs_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>

#include "signals/input_error.hpp"

namespace ultratrack::receiver {
namespace {

// One header line: 60 columns of content, then the label in columns 61-80.
std::string header_line(const std::string& content, const std::string& label) {
  return fmt::format("{:<60.60}{:<20.20}\n", content, label);
}

// RINEX observation field F14.3 + LLI + signal strength; blank when the value does not fit.
std::string obs_field(double value, int lli, int ssi) {
  if (!(std::fabs(value) < 9.9e9)) return std::string(16, ' ');
  return fmt::format("{:14.3f}{}{}", value, lli ? std::to_string(lli) : std::string(" "),
                     ssi ? std::to_string(ssi) : std::string(" "));
}

// RINEX signal strength indicator 1-9 from C/N0 (RINEX 3.04 table: 9 for >= 54 dB-Hz ... 1 for < 12).
int signal_strength_indicator(double cn0_dbhz) { return std::clamp(static_cast<int>(cn0_dbhz / 6.0), 1, 9); }

}  // namespace

RinexObsWriter::RinexObsWriter(const std::filesystem::path& path, RinexObsHeaderInfo info)
    : path_(path), info_(std::move(info)), body_(path.string() + ".body") {}

void RinexObsWriter::write(const ObservationEpoch& epoch) {
  if (epoch.observations.empty()) return;
  if (!first_epoch_) first_epoch_ = epoch.receive_time;
  const signals::CalendarTime c = signals::calendar_from_gps_time(epoch.receive_time);
  auto& out = body_.stream();
  out << fmt::format("> {:4d} {:02d} {:02d} {:02d} {:02d}{:11.7f}  0{:3d}\n", c.year, c.month, c.day, c.hour, c.minute,
                     c.second, epoch.observations.size());
  for (const auto& o : epoch.observations) {
    const int ssi = signal_strength_indicator(o.cn0_dbhz);
    // LLI bit 0: lock lost since the previous epoch; bit 1: half-cycle ambiguity not yet resolved.
    const int lli = (o.loss_of_lock ? 1 : 0) | (o.half_cycle_resolved ? 0 : 2);
    out << fmt::format("G{:02d}", o.prn) << obs_field(o.pseudorange_m, 0, ssi)
        << obs_field(o.carrier_phase_cycles, lli, ssi) << obs_field(o.doppler_hz, 0, 0) << obs_field(o.cn0_dbhz, 0, 0)
        << '\n';
  }
  ++epochs_;
}

void RinexObsWriter::finish(const Eigen::Vector3d& approx_r_e_m) {
  body_.commit();
  const std::filesystem::path body_path = body_.path();
  io::AtomicFile file(path_);
  auto& out = file.stream();
  out << header_line(fmt::format("{:>9}{:11}{:<20}{:<20}", "3.04", "", "OBSERVATION DATA", "G (GPS)"),
                     "RINEX VERSION / TYPE");
  out << header_line(fmt::format("{:<20}{:<20}{:<20}", "ultratrack", "", ""), "PGM / RUN BY / DATE");
  for (const std::string& c : comments_) out << header_line(c, "COMMENT");
  out << header_line(info_.marker_name, "MARKER NAME");
  out << header_line("NON_GEODETIC", "MARKER TYPE");
  out << header_line(fmt::format("{:<20}{:<40}", "", ""), "OBSERVER / AGENCY");
  out << header_line(fmt::format("{:<20}{:<20}{:<20}", "0", info_.receiver_type, "0.1.0"), "REC # / TYPE / VERS");
  out << header_line(fmt::format("{:<20}{:<20}", "0", "UNKNOWN"), "ANT # / TYPE");
  out << header_line(fmt::format("{:14.4f}{:14.4f}{:14.4f}", approx_r_e_m.x(), approx_r_e_m.y(), approx_r_e_m.z()),
                     "APPROX POSITION XYZ");
  out << header_line(fmt::format("{:14.4f}{:14.4f}{:14.4f}", 0.0, 0.0, 0.0), "ANTENNA: DELTA H/E/N");
  out << header_line(fmt::format("G{:5d} C1C L1C D1C S1C", 4), "SYS / # / OBS TYPES");
  out << header_line("DBHZ", "SIGNAL STRENGTH UNIT");
  out << header_line(fmt::format("{:10.3f}", info_.interval_s), "INTERVAL");
  if (first_epoch_) {
    const signals::CalendarTime c = signals::calendar_from_gps_time(*first_epoch_);
    out << header_line(
        fmt::format("{:6d}{:6d}{:6d}{:6d}{:6d}{:13.7f}     GPS", c.year, c.month, c.day, c.hour, c.minute, c.second),
        "TIME OF FIRST OBS");
  }
  out << header_line("G L1C", "SYS / PHASE SHIFT");
  out << header_line("", "END OF HEADER");
  {
    std::ifstream body(body_path);
    if (epochs_ > 0) out << body.rdbuf();  // inserting an empty streambuf would set failbit
  }
  file.commit();
  std::filesystem::remove(body_path);
}

}  // namespace ultratrack::receiver
