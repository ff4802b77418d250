#include "io/numeric_csv.hpp"

#include <charconv>
#include <cmath>
#include <fstream>

#include "io/input_error.hpp"

namespace ultratrack::io {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n'))
    s.remove_suffix(1);
  return s;
}

void check_csv_header(const std::string& file, int line, std::string_view text, const std::vector<std::string>& names) {
  std::size_t i = 0;
  std::string_view rest = text;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view field = trim(rest.substr(0, comma));
    if (i >= names.size() || field != names[i]) {
      std::string expected;
      for (const auto& n : names) expected += (expected.empty() ? "" : ",") + n;
      throw InputError(file, "bad header, expected '" + expected + "'", line);
    }
    ++i;
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  if (i != names.size()) {
    std::string expected;
    for (const auto& n : names) expected += (expected.empty() ? "" : ",") + n;
    throw InputError(file, "bad header, expected '" + expected + "'", line);
  }
}

void parse_numeric_row(const std::string& file, int line, std::string_view text, std::span<double> out) {
  std::string_view rest = text;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::size_t comma = rest.find(',');
    if (comma == std::string_view::npos && i + 1 < out.size())
      throw InputError(file, "expected " + std::to_string(out.size()) + " fields, got " + std::to_string(i + 1), line);
    const std::string_view field = trim(rest.substr(0, comma));
    double v = 0.0;
    const char* first = field.data();
    const char* last = field.data() + field.size();
    if (!field.empty() && *first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (field.empty() || ec != std::errc() || ptr != last)
      throw InputError(file, "field " + std::to_string(i + 1) + " is not a number: '" + std::string(field) + "'", line);
    if (!std::isfinite(v))
      throw InputError(file, "field " + std::to_string(i + 1) + " is not finite: '" + std::string(field) + "'", line);
    out[i] = v;
    if (comma == std::string_view::npos) {
      rest = {};
    } else {
      rest.remove_prefix(comma + 1);
    }
    if (i + 1 == out.size() && comma != std::string_view::npos)
      throw InputError(file, "more than " + std::to_string(out.size()) + " fields", line);
  }
}

int read_numeric_csv(const std::filesystem::path& file, std::string_view what, const std::vector<std::string>& columns,
                     const NumericRowHandler& row) {
  const std::string name = file.string();
  std::ifstream in(file);
  if (!in) throw InputError(name, "cannot open " + std::string(what));
  std::vector<double> values(columns.size());
  std::string line;
  int line_no = 0, rows = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    if (!have_header) {
      check_csv_header(name, line_no, t, columns);
      have_header = true;
      continue;
    }
    parse_numeric_row(name, line_no, t, values);
    row(line_no, values);
    ++rows;
  }
  if (!have_header) throw InputError(name, "empty " + std::string(what) + ": missing header");
  if (rows == 0) throw InputError(name, std::string(what) + " has no data rows");
  return rows;
}

}  // namespace ultratrack::io
