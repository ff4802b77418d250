// SPDX-License-Identifier: GPL-3.0-or-later
// Strict reading of numeric CSV files (IMU increments, navigation/truth rows, trajectories, segments):
// a header row naming the columns, then rows of exactly that many finite numbers. Blank lines and lines
// starting with '#' are skipped; anything else that is wrong is an InputError naming the file and line.
// A file is read as it is when opened (its size then): rows appended meanwhile are not read, a last line without its
// newline is left out while the file is being written (it grew while read or changed in the last 2 s), and a file
// that shrinks meanwhile is an InputError.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace ultratrack::io {

// The row callback gets the 1-based line number (for its own range checks) and the parsed values.
using NumericRowHandler = std::function<void(int line, std::span<const double> values)>;

// Reads `file` (described as `what` in errors, e.g. "IMU file"); the header must equal `columns`.
// Returns the number of data rows; a file without a header or without rows is an InputError.
int read_numeric_csv(const std::filesystem::path& file, std::string_view what, const std::vector<std::string>& columns,
                     const NumericRowHandler& row);

// The same reading with the fields left as text, for formats with their own field rules (empty or nan fields
// allowed in some columns): each data row is split into exactly columns.size() fields (trimmed), else an
// InputError. Same header, comment, empty-file and no-rows rules; returns the number of data rows.
using CsvFieldsHandler = std::function<void(int line, std::span<const std::string_view> fields)>;
int read_csv_rows(const std::filesystem::path& file, std::string_view what, const std::vector<std::string>& columns,
                  const CsvFieldsHandler& row);

// One field as a number ('+' allowed; nan and inf parse, finiteness is the caller's rule): nothing for an empty
// field; an InputError "<column> is not a number: '<field>'" for anything else that is not a number.
std::optional<double> parse_csv_number(const std::string& file, int line, std::string_view column,
                                       std::string_view field);

// The building blocks, for formats that wrap them.
std::string_view trim(std::string_view s);
void check_csv_header(const std::string& file, int line, std::string_view text, const std::vector<std::string>& names);

}  // namespace ultratrack::io
