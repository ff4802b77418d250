// SPDX-License-Identifier: GPL-3.0-or-later
// RINEX navigation reader (2.xx GPS, 3.00-3.05 GPS/mixed) and RINEX 3.04 GPS writer.
// Column positions follow the RINEX 2.11 and 3.04 format tables; every problem is reported with the
// file, the line number and what is wrong.
#include "signals/rinex_nav.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <optional>
#include <sstream>

#include "io/open_failure.hpp"
#include "signals/gps_constants.hpp"
#include "signals/gps_time.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::signals {
namespace {

// Upper bounds of the URA ranges, IS-GPS-200 20.3.3.3.1.3 (index 0..14).
constexpr std::array<double, 15> kUraUpperBound_m = {2.4,  3.4,   4.85,  6.85,  9.65,   13.65,  24.0,  48.0,
                                                     96.0, 192.0, 384.0, 768.0, 1536.0, 3072.0, 6144.0};

std::string trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return std::string(s.substr(b, e - b));
}

// Line-oriented reader that knows the file name and the current line number for error messages.
class LineReader {
 public:
  LineReader(std::istream& in, std::string name) : in_(in), name_(std::move(name)) {}

  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_no_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  [[noreturn]] void fail(const std::string& problem) const { throw InputError(name_, problem, line_no_); }
  int line_no() const { return line_no_; }
  const std::string& name() const { return name_; }

  // Text of columns [first, first + width) (0-based), blank-padded when the line is shorter.
  static std::string field(const std::string& line, size_t first, size_t width) {
    if (first >= line.size()) return {};
    return trim(std::string_view(line).substr(first, width));
  }

  // A floating-point field (Fortran D or E exponent). Blank gives `blank_value` when one is allowed.
  double number(const std::string& line, size_t first, size_t width, const char* what,
                std::optional<double> blank_value = 0.0) const {
    std::string text = field(line, first, width);
    if (text.empty()) {
      if (blank_value) return *blank_value;
      fail(fmt::format("missing {} (columns {}-{})", what, first + 1, first + width));
    }
    for (char& c : text)
      if (c == 'D' || c == 'd') c = 'E';
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
      fail(fmt::format("cannot parse {} from '{}' (columns {}-{})", what, field(line, first, width), first + 1,
                       first + width));
    return v;
  }

  int integer(const std::string& line, size_t first, size_t width, const char* what,
              std::optional<int> blank_value = std::nullopt) const {
    const std::string text = field(line, first, width);
    if (text.empty()) {
      if (blank_value) return *blank_value;
      fail(fmt::format("missing {} (columns {}-{})", what, first + 1, first + width));
    }
    errno = 0;
    char* end = nullptr;
    const long v = std::strtol(text.c_str(), &end, 10);
    if (end != text.c_str() + text.size() || errno == ERANGE || v < -2147483647L || v > 2147483647L)
      fail(fmt::format("cannot parse {} from '{}' (columns {}-{})", what, text, first + 1, first + width));
    return static_cast<int>(v);
  }

 private:
  std::istream& in_;
  std::string name_;
  int line_no_ = 0;
};

bool is_blank(const std::string& line) { return trim(line).empty(); }

std::string header_label(const std::string& line) { return LineReader::field(line, 60, 20); }

struct HeaderInfo {
  double version = 0.0;
  int major = 0;
  char system = 'G';
};

HeaderInfo read_header(LineReader& r, RinexNavData& out) {
  std::string line;
  if (!r.next(line)) throw InputError(r.name(), "empty file: not a RINEX navigation file");
  if (header_label(line) != "RINEX VERSION / TYPE") r.fail("bad header: the first line must be 'RINEX VERSION / TYPE'");
  HeaderInfo h;
  h.version = r.number(line, 0, 9, "RINEX version", std::nullopt);
  h.major = static_cast<int>(std::floor(h.version + 1e-9));
  const char type = line.size() > 20 ? line[20] : ' ';
  if (h.major == 2) {
    if (type != 'N') r.fail(fmt::format("wrong file type '{}': a RINEX 2 GPS navigation file has type 'N'", type));
  } else if (h.major == 3) {
    if (h.version > 3.05 + 1e-9) r.fail(fmt::format("unsupported RINEX version {:.2f}", h.version));
    h.system = line.size() > 40 ? line[40] : ' ';
    if (type != 'N') r.fail(fmt::format("wrong file type '{}': not a navigation file", type));
    if (h.system != 'G' && h.system != 'M')
      r.fail(fmt::format("navigation file for system '{}': only GPS ('G') or mixed ('M') are read", h.system));
  } else {
    r.fail(fmt::format("unsupported RINEX version {:.2f} (2.xx and 3.00-3.05 are read)", h.version));
  }
  out.version = h.version;

  bool alpha = false, beta = false;
  while (true) {
    if (!r.next(line)) r.fail("bad header: end of file before 'END OF HEADER'");
    const std::string label = header_label(line);
    if (label == "END OF HEADER") break;
    if (label == "ION ALPHA" || label == "ION BETA") {
      double* dst = label == "ION ALPHA" ? out.klobuchar.alpha : out.klobuchar.beta;
      for (int k = 0; k < 4; ++k) dst[k] = r.number(line, 2 + 12 * k, 12, label.c_str(), std::nullopt);
      (label == "ION ALPHA" ? alpha : beta) = true;
    } else if (label == "IONOSPHERIC CORR") {
      const std::string kind = LineReader::field(line, 0, 4);
      if (kind == "GPSA" || kind == "GPSB") {
        double* dst = kind == "GPSA" ? out.klobuchar.alpha : out.klobuchar.beta;
        for (int k = 0; k < 4; ++k) dst[k] = r.number(line, 5 + 12 * k, 12, "GPS ionosphere parameter", std::nullopt);
        (kind == "GPSA" ? alpha : beta) = true;
      }
    } else if (label == "DELTA-UTC: A0,A1,T,W") {
      out.utc.a0_s = r.number(line, 3, 19, "UTC A0", std::nullopt);
      out.utc.a1_sps = r.number(line, 22, 19, "UTC A1", std::nullopt);
      out.utc.tot_s = r.integer(line, 41, 9, "UTC reference time");
      out.utc.wnt = r.integer(line, 50, 9, "UTC reference week");
      out.utc.valid = true;
    } else if (label == "TIME SYSTEM CORR") {
      if (LineReader::field(line, 0, 4) == "GPUT") {
        out.utc.a0_s = r.number(line, 5, 17, "GPUT a0", std::nullopt);
        out.utc.a1_sps = r.number(line, 22, 16, "GPUT a1", std::nullopt);
        out.utc.tot_s = r.integer(line, 38, 7, "GPUT reference time");
        out.utc.wnt = r.integer(line, 45, 5, "GPUT reference week");
        out.utc.valid = true;
      }
    } else if (label == "LEAP SECONDS") {
      out.utc.delta_t_ls_s = r.integer(line, 0, 6, "leap seconds");
      // 3.xx adds the future leap seconds, their week and day; absent fields keep the current value.
      out.utc.delta_t_lsf_s = r.integer(line, 6, 6, "future leap seconds", out.utc.delta_t_ls_s);
      out.utc.wn_lsf = r.integer(line, 12, 6, "leap second week", 0);
      out.utc.dn = r.integer(line, 18, 6, "leap second day", 0);
      out.has_leap_seconds = true;
    }
  }
  out.klobuchar.valid = alpha && beta;
  return h;
}

// Lines after the epoch line in a record of each system (RINEX 3.04 tables A8-A16; 3.05 adds a fourth
// GLONASS line).
int continuation_lines(char system, double version) {
  switch (system) {
    case 'R':
      return version >= 3.05 - 1e-9 ? 4 : 3;
    case 'S':
      return 3;
    default:
      return 7;  // G, E, J, C, I
  }
}

Ephemeris parse_gps_record(LineReader& r, const std::string& epoch_line, int major, double& transmit_tow) {
  Ephemeris e;
  CalendarTime toc;
  size_t value0;  // first column of the three clock values on the epoch line
  size_t orbit0;  // first column of the four values on the orbit lines
  if (major == 2) {
    e.prn = r.integer(epoch_line, 0, 2, "PRN");
    const int yy = r.integer(epoch_line, 2, 3, "year");
    if (yy < 0 || yy > 99) r.fail(fmt::format("two-digit year {} out of range", yy));
    toc.year = yy < 80 ? 2000 + yy : 1900 + yy;
    toc.month = r.integer(epoch_line, 5, 3, "month");
    toc.day = r.integer(epoch_line, 8, 3, "day");
    toc.hour = r.integer(epoch_line, 11, 3, "hour");
    toc.minute = r.integer(epoch_line, 14, 3, "minute");
    toc.second = r.number(epoch_line, 17, 5, "second", std::nullopt);
    value0 = 22;
    orbit0 = 3;
  } else {
    e.prn = r.integer(epoch_line, 1, 2, "PRN");
    toc.year = r.integer(epoch_line, 3, 5, "year");
    toc.month = r.integer(epoch_line, 8, 3, "month");
    toc.day = r.integer(epoch_line, 11, 3, "day");
    toc.hour = r.integer(epoch_line, 14, 3, "hour");
    toc.minute = r.integer(epoch_line, 17, 3, "minute");
    toc.second = r.integer(epoch_line, 20, 3, "second");
    value0 = 23;
    orbit0 = 4;
  }
  if (e.prn < kMinPrn || e.prn > kMaxPrn) r.fail(fmt::format("GPS PRN {} out of range 1-32", e.prn));
  if (toc.month < 1 || toc.month > 12 || toc.day < 1 || toc.day > 31 || toc.hour < 0 || toc.hour > 23 ||
      toc.minute < 0 || toc.minute > 59 || toc.second < 0.0 || toc.second >= 61.0)
    r.fail("invalid epoch (toc) date or time");
  e.af0_s = r.number(epoch_line, value0, 19, "af0", std::nullopt);
  e.af1_sps = r.number(epoch_line, value0 + 19, 19, "af1", std::nullopt);
  e.af2_sps2 = r.number(epoch_line, value0 + 38, 19, "af2", std::nullopt);

  double v[7][4];
  const int record_start = r.line_no();
  for (int k = 0; k < 7; ++k) {
    std::string line;
    if (!r.next(line))
      throw InputError(r.name(),
                       fmt::format("truncated record for G{:02d} (started on line {}): file ends after "
                                   "{} of 7 orbit lines",
                                   e.prn, record_start, k),
                       r.line_no());
    if (is_blank(line) || !trim(std::string_view(line).substr(0, std::min(line.size(), orbit0))).empty())
      r.fail(fmt::format("truncated record for G{:02d} (started on line {}): expected orbit line {} of 7", e.prn,
                         record_start, k + 1));
    for (int j = 0; j < 4; ++j) v[k][j] = r.number(line, orbit0 + 19 * j, 19, "orbit parameter");
  }
  const auto bad = [&](const std::string& what) {
    throw InputError(r.name(), fmt::format("record for G{:02d} (line {}): {}", e.prn, record_start, what),
                     record_start);
  };
  // An integer field, range-checked as the number it was written as: rounding a value beyond int first would wrap
  // it (a week of 2^32 + 2190 would read as 2190).
  const auto whole = [&](double x, int lo, int hi, const char* what) {
    if (!(x >= lo - 0.5 && x < hi + 0.5)) bad(fmt::format("{} {} out of range", what, x));
    return static_cast<int>(std::lround(x));
  };
  e.iode = whole(v[0][0], 0, 255, "IODE");
  e.crs_m = v[0][1];
  e.delta_n_radps = v[0][2];
  e.m0_rad = v[0][3];
  e.cuc_rad = v[1][0];
  e.e = v[1][1];
  e.cus_rad = v[1][2];
  e.sqrt_a_sqrtm = v[1][3];
  e.toe_s = v[2][0];
  e.cic_rad = v[2][1];
  e.omega0_rad = v[2][2];
  e.cis_rad = v[2][3];
  e.i0_rad = v[3][0];
  e.crc_m = v[3][1];
  e.omega_rad = v[3][2];
  e.omega_dot_radps = v[3][3];
  e.idot_radps = v[4][0];
  e.code_on_l2 = whole(v[4][1], 0, 3, "codes on L2");
  e.week = whole(v[4][2], 0, 9999, "GPS week");
  e.l2p_data_flag = whole(v[4][3], 0, 1, "L2 P data flag");
  e.ura_index = ura_index_from_metres(v[5][0]);
  e.health = whole(v[5][1], 0, 63, "SV health");
  e.tgd_s = v[5][2];
  e.iodc = whole(v[5][3], 0, 1023, "IODC");
  transmit_tow = v[6][0];
  const double fit_hours = v[6][1];
  e.fit_interval_flag = fit_hours > 4.0 + 1e-6 ? 1 : 0;

  if (!(e.sqrt_a_sqrtm > 1000.0 && e.sqrt_a_sqrtm < 10000.0))
    bad(fmt::format("sqrt(A) = {} m^0.5 is not a GPS orbit", e.sqrt_a_sqrtm));
  if (!(e.e >= 0.0 && e.e < 0.1)) bad(fmt::format("eccentricity {} out of range", e.e));
  if (!(e.toe_s >= 0.0 && e.toe_s < kSecondsPerWeek)) bad(fmt::format("toe {} s out of range", e.toe_s));

  // toc: seconds of the ephemeris week (the broadcast toc and toe share a week; a toc in the neighbouring
  // week is expressed relative to the toe week so that Ephemeris::toc() is the same instant).
  const GpsTime toc_t = gps_time_from_calendar(toc);
  e.toc_s = seconds_between(toc_t, {e.week, 0.0});
  if (e.toc_s < -kSecondsPerWeek || e.toc_s > 2.0 * kSecondsPerWeek)
    bad("epoch (toc) is more than a week away from the GPS week of the record");
  return e;
}

}  // namespace

int ura_index_from_metres(double ura_m) {
  for (size_t n = 0; n < kUraUpperBound_m.size(); ++n)
    if (ura_m <= kUraUpperBound_m[n] + 1e-9) return static_cast<int>(n);
  return 15;
}

double ura_metres_from_index(int ura_index) {
  if (ura_index < 0) return kUraUpperBound_m[0];
  if (ura_index >= 15) return 12288.0;
  return kUraUpperBound_m[static_cast<size_t>(ura_index)];
}

double fit_interval_hours(const Ephemeris& eph) {
  if (eph.fit_interval_flag == 0) return 4.0;
  const int c = eph.iodc;
  // IODC ranges of the extended-operations table (ICD-GPS-200C Table 20-XII) as receivers implement it
  // (libswiftnav, GPSTk); longer entries are not used: a shorter interval is the safe side.
  if (c >= 240 && c <= 247) return 8.0;
  if ((c >= 248 && c <= 255) || c == 496) return 14.0;
  if ((c >= 497 && c <= 503) || (c >= 1021 && c <= 1023)) return 26.0;
  if (c >= 504 && c <= 510) return 50.0;
  if (c == 511 || (c >= 752 && c <= 756)) return 74.0;
  if (c == 757) return 98.0;
  return 6.0;
}

RinexNavData read_rinex_nav(std::istream& in, const std::string& name) {
  RinexNavData out;
  LineReader r(in, name);
  const HeaderInfo h = read_header(r, out);

  std::string line;
  while (r.next(line)) {
    if (is_blank(line)) continue;
    if (std::isspace(static_cast<unsigned char>(line[0])) && h.major == 3)
      r.fail("expected the first line of a record, found a continuation line");
    if (h.major == 3 && line[0] != 'G') {
      const char sys = line[0];
      if (std::string_view("REJCISR").find(sys) == std::string_view::npos)
        r.fail(fmt::format("unknown satellite system '{}' at the start of a record", sys));
      const int start = r.line_no();
      for (int k = 0; k < continuation_lines(sys, h.version); ++k) {
        if (!r.next(line) || is_blank(line) || !std::isspace(static_cast<unsigned char>(line[0])))
          throw InputError(name, fmt::format("truncated record for system '{}' (started on line {})", sys, start),
                           r.line_no());
      }
      continue;
    }
    double transmit = 0.0;
    out.ephemerides.push_back(parse_gps_record(r, line, h.major, transmit));
    out.transmit_tow_s.push_back(transmit);
  }
  // A UTC reference week written modulo 1024 by an old writer: resolve it against the ephemerides.
  if (out.utc.valid && out.utc.wnt < 1024 && !out.ephemerides.empty() && out.ephemerides[0].week >= 1024)
    out.utc.wnt = resolve_week_rollover(out.utc.wnt, out.ephemerides[0].week);
  return out;
}

RinexNavData read_rinex_nav(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "cannot open the RINEX navigation file: " + io::open_failure_reason());
  return read_rinex_nav(in, path.string());
}

void write_rinex_nav_304(const std::filesystem::path& path, const RinexNavData& data) {
  std::string s;
  const auto header = [&s](const std::string& body, const char* label) {
    s += fmt::format("{:<60}{:<20}\n", body, label);
  };
  header(fmt::format("{:9.2f}{:11}{:<20}{:<20}", 3.04, "", "N: GNSS NAV DATA", "G: GPS"), "RINEX VERSION / TYPE");
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y%m%d %H%M%S UTC", &utc);
  header(fmt::format("{:<20}{:<20}{:<20}", "ultratrack", "", date), "PGM / RUN BY / DATE");
  if (data.klobuchar.valid) {
    const KlobucharParameters& k = data.klobuchar;
    header(fmt::format("GPSA {:12.4E}{:12.4E}{:12.4E}{:12.4E}", k.alpha[0], k.alpha[1], k.alpha[2], k.alpha[3]),
           "IONOSPHERIC CORR");
    header(fmt::format("GPSB {:12.4E}{:12.4E}{:12.4E}{:12.4E}", k.beta[0], k.beta[1], k.beta[2], k.beta[3]),
           "IONOSPHERIC CORR");
  }
  if (data.utc.valid)
    header(
        fmt::format("GPUT {:17.10E}{:16.9E} {:6d} {:4d}", data.utc.a0_s, data.utc.a1_sps, data.utc.tot_s, data.utc.wnt),
        "TIME SYSTEM CORR");
  if (data.utc.valid && data.utc.wn_lsf > 0)
    header(fmt::format("{:6d}{:6d}{:6d}{:6d}", data.utc.delta_t_ls_s, data.utc.delta_t_lsf_s, data.utc.wn_lsf,
                       data.utc.dn),
           "LEAP SECONDS");
  else if (data.utc.valid || data.has_leap_seconds)
    header(fmt::format("{:6d}", data.utc.delta_t_ls_s), "LEAP SECONDS");
  header("", "END OF HEADER");

  const auto orbit = [&s](double a, double b, double c, double d) {
    s += fmt::format("    {:19.12E}{:19.12E}{:19.12E}{:19.12E}\n", a, b, c, d);
  };
  for (size_t i = 0; i < data.ephemerides.size(); ++i) {
    const Ephemeris& e = data.ephemerides[i];
    if (e.prn < kMinPrn || e.prn > kMaxPrn || e.week < 0)
      throw InputError(path.string(),
                       fmt::format("cannot write ephemeris {} (PRN {}, week {}): out of range", i, e.prn, e.week));
    const CalendarTime c = calendar_from_gps_time(normalised(e.toc()));
    const int sec = static_cast<int>(std::lround(c.second));
    s += fmt::format("G{:02d} {:04d} {:02d} {:02d} {:02d} {:02d} {:02d}{:19.12E}{:19.12E}{:19.12E}\n", e.prn, c.year,
                     c.month, c.day, c.hour, c.minute, sec, e.af0_s, e.af1_sps, e.af2_sps2);
    orbit(e.iode, e.crs_m, e.delta_n_radps, e.m0_rad);
    orbit(e.cuc_rad, e.e, e.cus_rad, e.sqrt_a_sqrtm);
    orbit(e.toe_s, e.cic_rad, e.omega0_rad, e.cis_rad);
    orbit(e.i0_rad, e.crc_m, e.omega_rad, e.omega_dot_radps);
    orbit(e.idot_radps, e.code_on_l2, e.week, e.l2p_data_flag);
    orbit(ura_metres_from_index(e.ura_index), e.health, e.tgd_s, e.iodc);
    const double transmit = i < data.transmit_tow_s.size() ? data.transmit_tow_s[i] : e.toe_s;
    s += fmt::format("    {:19.12E}{:19.12E}\n", transmit, fit_interval_hours(e));
  }

  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(tmp.string(), "cannot create the RINEX navigation file");
    out << s;
    out.flush();
    if (!out) throw InputError(tmp.string(), "write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path.string(), "cannot rename the temporary file into place");
  }
}

}  // namespace ultratrack::signals
