// SPDX-License-Identifier: GPL-3.0-or-later
// A CSV file read by column names, for our own outputs whose later columns a reader does not need (tracking.csv,
// satellite_truth.csv): the header, then rows of exactly as many fields, trimmed. Blank lines are skipped. A missing
// column, a row of the wrong width, an empty file or a field that is not a number where one is asked for is an
// InputError naming the file (and line).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace ultratrack::io {

struct NamedCsv {
  std::string file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // 1-based line of each row

  // The index of a column; InputError when the header has no such column.
  std::size_t column(const std::string& name) const;
  // A field as a number (nan allowed, as parse_csv_number); InputError when empty or not a number.
  double number(std::size_t row, std::size_t column) const;
};

NamedCsv read_named_csv(const std::filesystem::path& path);

}  // namespace ultratrack::io
