// SPDX-License-Identifier: GPL-3.0-or-later
#include "receiver/solution_writer.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/units.hpp"

namespace ultratrack::receiver {
namespace {

constexpr double kMpsToKnots = 3600.0 / 1852.0;

// NMEA angle "ddmm.mmmmmm" (latitude, 2 degree digits) or "dddmm.mmmmmm" (longitude, 3 digits).
std::string nmea_angle(double angle_deg, int degree_digits) {
  const double a = std::fabs(angle_deg);
  int degrees = static_cast<int>(a);
  double minutes = (a - degrees) * 60.0;
  if (minutes >= 59.9999995) {  // would print as 60.000000
    minutes = 0.0;
    ++degrees;
  }
  return fmt::format("{:0{}d}{:09.6f}", degrees, degree_digits, minutes);
}

struct UtcStamp {
  std::string hhmmss, ddmmyy;
};

UtcStamp utc_stamp(const signals::GpsTime& t, int leap_seconds) {
  const signals::CalendarTime c = signals::utc_from_gps_time(t, leap_seconds);
  return {fmt::format("{:02d}{:02d}{:05.2f}", c.hour, c.minute, std::floor(c.second * 100.0) / 100.0),
          fmt::format("{:02d}{:02d}{:02d}", c.day, c.month, c.year % 100)};
}

}  // namespace

SolutionCsvWriter::SolutionCsvWriter(const std::filesystem::path& path) : file_(path) {
  file_.stream() << kSolutionCsvHeader << '\n';
}

void SolutionCsvWriter::write(const PvtSolution& f) {
  file_.stream() << fmt::format(
      "{},{:.4f},{:.9f},{:.9f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{:.4f},{},{:.3f},{:.3f},{:.3f},{"
      "}\n",
      f.time.week, f.time.tow_s, f.lat_rad * io::kDegPerRad, f.lon_rad * io::kDegPerRad, f.height_m, f.r_e_m.x(),
      f.r_e_m.y(), f.r_e_m.z(), f.v_enu_mps.x(), f.v_enu_mps.y(), f.v_enu_mps.z(), f.clock_bias_m, f.clock_drift_mps,
      f.used_prns.size(), f.pdop, f.hdop, f.vdop, f.excluded_prn ? std::to_string(*f.excluded_prn) : std::string());
}

std::string nmea_sentence(const std::string& body) {
  unsigned char sum = 0;
  for (char ch : body) sum ^= static_cast<unsigned char>(ch);
  return fmt::format("${}*{:02X}", body, sum);
}

NmeaWriter::NmeaWriter(const std::filesystem::path& path, int leap_seconds)
    : file_(path), leap_seconds_(leap_seconds) {}

void NmeaWriter::write(const PvtSolution& f) {
  auto& out = file_.stream();
  const UtcStamp utc = utc_stamp(f.time, leap_seconds_);
  const double lat_deg = f.lat_rad * io::kDegPerRad, lon_deg = f.lon_rad * io::kDegPerRad;
  const std::string lat = nmea_angle(lat_deg, 2), lon = nmea_angle(lon_deg, 3);
  const char ns = lat_deg >= 0 ? 'N' : 'S', ew = lon_deg >= 0 ? 'E' : 'W';
  out << nmea_sentence(fmt::format("GPGGA,{},{},{},{},{},1,{:02d},{:.1f},{:.3f},M,0.000,M,,", utc.hhmmss, lat, ns, lon,
                                   ew, f.used_prns.size(), f.hdop, f.height_m))
      << "\r\n";
  const double speed = std::hypot(f.v_enu_mps.x(), f.v_enu_mps.y());
  double course = std::atan2(f.v_enu_mps.x(), f.v_enu_mps.y()) * io::kDegPerRad;
  if (course < 0) course += 360.0;
  out << nmea_sentence(fmt::format("GPRMC,{},A,{},{},{},{},{:.3f},{:.2f},{},,,A", utc.hhmmss, lat, ns, lon, ew,
                                   speed * kMpsToKnots, course, utc.ddmmyy))
      << "\r\n";
  std::string gsa = "GPGSA,A,3";
  for (int i = 0; i < 12; ++i)
    gsa += i < static_cast<int>(f.used_prns.size()) ? fmt::format(",{:02d}", f.used_prns[i]) : std::string(",");
  gsa += fmt::format(",{:.1f},{:.1f},{:.1f}", f.pdop, f.hdop, f.vdop);
  out << nmea_sentence(gsa) << "\r\n";
  const int in_view = static_cast<int>(f.satellites.size());
  const int messages = std::max(1, (in_view + 3) / 4);
  for (int m = 0; m < messages; ++m) {
    std::string gsv = fmt::format("GPGSV,{},{},{:02d}", messages, m + 1, in_view);
    for (int k = 4 * m; k < std::min(in_view, 4 * m + 4); ++k) {
      const auto& s = f.satellites[k];
      gsv += fmt::format(",{:02d},{:02.0f},{:03.0f},{:02.0f}", s.prn, s.elevation_rad * io::kDegPerRad,
                         s.azimuth_rad * io::kDegPerRad, std::clamp(s.cn0_dbhz, 0.0, 99.0));
    }
    out << nmea_sentence(gsv) << "\r\n";
  }
}

KmlWriter::KmlWriter(const std::filesystem::path& path) : file_(path) {}

void KmlWriter::write(const PvtSolution& f) {
  const double lat = f.lat_rad * io::kDegPerRad, lon = f.lon_rad * io::kDegPerRad;
  coordinates_.push_back(fmt::format("{:.9f},{:.9f},{:.3f}", lon, lat, f.height_m));
  sum_lat_deg_ += lat;
  sum_lon_deg_ += lon;
  sum_h_m_ += f.height_m;
}

void KmlWriter::finish() {
  auto& out = file_.stream();
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n"
      << "<name>ultratrack</name>\n";
  if (!coordinates_.empty()) {
    const double n = static_cast<double>(coordinates_.size());
    out << "<Placemark><name>track</name><LineString><altitudeMode>absolute</altitudeMode><coordinates>\n";
    for (const auto& c : coordinates_) out << c << '\n';
    out << "</coordinates></LineString></Placemark>\n";
    out << fmt::format(
        "<Placemark><name>mean position</name><Point><altitudeMode>absolute</altitudeMode>"
        "<coordinates>{:.9f},{:.9f},{:.3f}</coordinates></Point></Placemark>\n",
        sum_lon_deg_ / n, sum_lat_deg_ / n, sum_h_m_ / n);
  }
  out << "</Document>\n</kml>\n";
  file_.commit();
}

}  // namespace ultratrack::receiver
