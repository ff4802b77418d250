// SPDX-License-Identifier: GPL-3.0-or-later
// Command-line values parsed as text so that a malformed one is an InputError (exit 2) like any other bad
// input: numbers, integers, PRN lists ("1-32", "3,7,12-15") and two-valued switches; the build date's GPS week.
#pragma once

#include <string>
#include <vector>

#include "fusion/gnss_ins_integration.hpp"
#include "signals/gps_time.hpp"

namespace ultratrack::tools {

double parse_double_option(const std::string& option, const std::string& text);
int parse_int_option(const std::string& option, const std::string& text);
std::vector<int> parse_prn_list_option(const std::string& option, const std::string& text);
// true for the value `on`, false for `off`.
bool parse_on_off_option(const std::string& option, const std::string& value, const char* on, const char* off);
// `--filter ekf|ukf`.
fusion::FilterKind parse_filter_option(const std::string& value);
// `--attitude-origin WEEK TOW` (two values): a whole week >= 0 and a tow in [0, 604800).
signals::GpsTime parse_gps_time_option(const std::string& option, const std::vector<double>& week_tow);
// The GPS week of the build date: a reference within +-512 weeks of any recording made near it.
int build_gps_week();

}  // namespace ultratrack::tools
