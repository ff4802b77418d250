// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/numeric_csv.hpp"

#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "io/input_error.hpp"
#include "io/open_failure.hpp"

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

namespace {

// Splits a data row into exactly fields.size() trimmed fields.
void split_row(const std::string& file, int line, std::string_view text, std::span<std::string_view> fields) {
  std::size_t n = 0;
  while (true) {
    const std::size_t comma = text.find(',');
    if (n == fields.size()) throw InputError(file, "more than " + std::to_string(fields.size()) + " fields", line);
    fields[n++] = trim(text.substr(0, comma));
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  if (n != fields.size())
    throw InputError(file, "expected " + std::to_string(fields.size()) + " fields, got " + std::to_string(n), line);
}

}  // namespace

std::optional<double> parse_csv_number(const std::string& file, int line, std::string_view column,
                                       std::string_view field) {
  field = trim(field);
  if (field.empty()) return std::nullopt;
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (*first == '+') ++first;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last)
    throw InputError(file, std::string(column) + " is not a number: '" + std::string(field) + "'", line);
  return v;
}

namespace {

// The file as it is when opened: its bytes up to the size read then; a file that shrinks meanwhile is an error. A
// last line without its newline is left out while the file is being written (it grew while read, or changed less
// than 2 s ago: a logger may pause mid-line for a buffer's worth of rows), since its cut may fall inside a number.
// A finished file without a final newline keeps its last row.
std::string csv_snapshot(const std::filesystem::path& file, std::string_view what) {
  const std::string name = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(name, "cannot open " + std::string(what) + ": " + open_failure_reason());
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(name, "cannot read the size of the " + std::string(what) + ": " + ec.message());
  std::string text(size, '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size))
    throw InputError(name, std::string(what) + " shrank while being read (" + std::to_string(in.gcount()) + " of " +
                               std::to_string(size) + " bytes)");
  if (!text.empty() && text.back() != '\n') {
    const bool grew = std::filesystem::file_size(file, ec) > size && !ec;
    const auto modified = std::filesystem::last_write_time(file, ec);
    const bool recent = !ec && std::filesystem::file_time_type::clock::now() - modified < std::chrono::seconds(2);
    if (grew || recent) {
      const auto last_newline = text.find_last_of('\n');
      text.erase(last_newline == std::string::npos ? 0 : last_newline + 1);
    }
  }
  return text;
}

}  // namespace

int read_csv_rows(const std::filesystem::path& file, std::string_view what, const std::vector<std::string>& columns,
                  const CsvFieldsHandler& row) {
  const std::string name = file.string();
  std::istringstream in(csv_snapshot(file, what));
  std::vector<std::string_view> fields(columns.size());
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
    split_row(name, line_no, t, fields);
    row(line_no, fields);
    ++rows;
  }
  if (!have_header) throw InputError(name, "empty " + std::string(what) + ": missing header");
  if (rows == 0) throw InputError(name, std::string(what) + " has no data rows");
  return rows;
}

int read_numeric_csv(const std::filesystem::path& file, std::string_view what, const std::vector<std::string>& columns,
                     const NumericRowHandler& row) {
  const std::string name = file.string();
  std::vector<double> values(columns.size());
  std::vector<std::string> field_names;  // errors name fields by position
  for (std::size_t i = 0; i < columns.size(); ++i) field_names.push_back("field " + std::to_string(i + 1));
  return read_csv_rows(file, what, columns, [&](int line, std::span<const std::string_view> fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::string& column = field_names[i];
      const auto v = parse_csv_number(name, line, column, fields[i]);
      if (!v) throw InputError(name, column + " is not a number: ''", line);
      if (!std::isfinite(*v)) throw InputError(name, column + " is not finite: '" + std::string(fields[i]) + "'", line);
      values[i] = *v;
    }
    row(line, values);
  });
}

}  // namespace ultratrack::io
