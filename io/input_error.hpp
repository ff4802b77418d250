// SPDX-License-Identifier: GPL-3.0-or-later
// The typed exception for bad input at the edges (files, configs, command line): it names the file,
// optionally the line, and what is wrong. The `ultratrack` program turns it into one message and exit 2.
#pragma once

#include <stdexcept>
#include <string>

namespace ultratrack::io {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string problem, int line = 0)
      : std::runtime_error(format(file, problem, line)), file_(std::move(file)), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  static std::string format(const std::string& file, const std::string& problem, int line) {
    std::string where = file.empty() ? std::string("input") : file;
    if (line > 0) {  // appended in two steps: `":" + std::to_string()` trips GCC 12's false -Wrestrict
      where += ':';
      where += std::to_string(line);
    }
    where.append(": ").append(problem);
    return where;
  }
  std::string file_;
  int line_;
};

}  // namespace ultratrack::io
