// Command-line values parsed as text so that a malformed one is an InputError (exit 2) like any other bad
// input: numbers, integers and PRN lists ("1-32", "3,7,12-15").
#pragma once

#include <string>
#include <vector>

namespace ultratrack::tools {

double parse_double_option(const std::string& option, const std::string& text);
int parse_int_option(const std::string& option, const std::string& text);
std::vector<int> parse_prn_list_option(const std::string& option, const std::string& text);

}  // namespace ultratrack::tools
