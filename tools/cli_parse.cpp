// SPDX-License-Identifier: GPL-3.0-or-later
#include "cli_parse.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "signals/gps_time.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::tools {
namespace {

signals::InputError bad(const std::string& option, const std::string& problem) {
  return signals::InputError("command line", option + ": " + problem);
}

}  // namespace

double parse_double_option(const std::string& option, const std::string& text) {
  double value = 0.0;
  std::size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value)) throw bad(option, "'" + text + "' is not a number");
  return value;
}

int parse_int_option(const std::string& option, const std::string& text) {
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) throw bad(option, "'" + text + "' is not an integer");
  return value;
}

std::vector<int> parse_prn_list_option(const std::string& option, const std::string& text) {
  std::vector<int> prns;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const std::size_t dash = item.find('-');
    const int first = parse_int_option(option, item.substr(0, dash));
    const int last = dash == std::string::npos ? first : parse_int_option(option, item.substr(dash + 1));
    if (first < 1 || last > 32 || first > last) throw bad(option, "'" + item + "' is not a PRN range within 1-32");
    for (int prn = first; prn <= last; ++prn)
      if (std::find(prns.begin(), prns.end(), prn) == prns.end()) prns.push_back(prn);
    start = comma + 1;
  }
  return prns;
}

bool parse_on_off_option(const std::string& option, const std::string& value, const char* on, const char* off) {
  if (value == on) return true;
  if (value == off) return false;
  throw signals::InputError("command line", option + ": '" + value + "' is neither " + on + " nor " + off);
}

int build_gps_week() {
  static const char* months = "JanFebMarAprMayJunJulAugSepOctNovDec";
  const std::string date = __DATE__;  // "Mmm dd yyyy"
  signals::CalendarTime c;
  c.month = static_cast<int>(std::string(months).find(date.substr(0, 3)) / 3) + 1;
  c.day = std::stoi(date.substr(4, 2));
  c.year = std::stoi(date.substr(7, 4));
  return signals::gps_time_from_calendar(c).week;
}

fusion::FilterKind parse_filter_option(const std::string& value) {
  if (value == "ekf") return fusion::FilterKind::Ekf;
  if (value == "ukf") return fusion::FilterKind::Ukf;
  throw signals::InputError("command line", "--filter must be ekf or ukf, got '" + value + "'");
}

signals::GpsTime parse_gps_time_option(const std::string& option, const std::vector<double>& week_tow) {
  const double week = week_tow.at(0), tow = week_tow.at(1);
  if (week < 0.0 || week != std::floor(week) || !(tow >= 0.0 && tow < 604800.0))
    throw signals::InputError("command line", option + " takes WEEK (integer) TOW (seconds in [0, 604800))");
  return {static_cast<int>(week), tow};
}

}  // namespace ultratrack::tools
