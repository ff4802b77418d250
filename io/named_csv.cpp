// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/named_csv.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"
#include "io/open_failure.hpp"

namespace ultratrack::io {
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ',')) fields.emplace_back(trim(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

std::size_t NamedCsv::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) throw InputError(file, "no column '" + name + "'");
  return static_cast<std::size_t>(it - header.begin());
}

double NamedCsv::number(std::size_t row, std::size_t column) const {
  const auto v = parse_csv_number(file, lines[row], header[column], rows[row][column]);
  if (!v) throw InputError(file, header[column] + " is empty", lines[row]);
  return *v;
}

NamedCsv read_named_csv(const std::filesystem::path& path) {
  NamedCsv csv;
  csv.file = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(csv.file, "cannot open the file: " + open_failure_reason());
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty()) continue;
    std::vector<std::string> fields = split(line);
    if (csv.header.empty()) {
      csv.header = std::move(fields);
      continue;
    }
    if (fields.size() != csv.header.size())
      throw InputError(csv.file,
                       std::to_string(fields.size()) + " fields, the header has " + std::to_string(csv.header.size()),
                       number);
    csv.rows.push_back(std::move(fields));
    csv.lines.push_back(number);
  }
  if (csv.header.empty()) throw InputError(csv.file, "empty file");
  return csv;
}

}  // namespace ultratrack::io
