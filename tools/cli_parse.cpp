#include "cli_parse.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

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

}  // namespace ultratrack::tools
