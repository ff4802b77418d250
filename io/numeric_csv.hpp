// Strict reading of numeric CSV files (IMU increments, navigation/truth rows, trajectories, segments):
// a header row naming the columns, then rows of exactly that many finite numbers. Blank lines and lines
// starting with '#' are skipped; anything else that is wrong is an InputError naming the file and line.
#pragma once

#include <filesystem>
#include <functional>
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

// The building blocks, for formats that wrap them.
std::string_view trim(std::string_view s);
void check_csv_header(const std::string& file, int line, std::string_view text, const std::vector<std::string>& names);
void parse_numeric_row(const std::string& file, int line, std::string_view text, std::span<double> out);

}  // namespace ultratrack::io
