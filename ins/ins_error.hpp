// The typed exception of the ins layer for bad input at its edges (IMU/nav CSV files, profile names,
// segment files). It names the file, optionally the line, and the problem; `ultratrack` prints it as one
// line and exits with 2. ins/ cannot see signals/, so this mirrors signals::InputError.
#pragma once

#include <stdexcept>
#include <string>

namespace ultratrack::ins {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string problem, int line = 0)
      : std::runtime_error(format(file, problem, line)), file_(std::move(file)), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  static std::string format(const std::string& file, const std::string& problem, int line) {
    std::string where = file.empty() ? std::string("input") : file;
    if (line > 0) where.append(1, ':').append(std::to_string(line));
    where.append(": ").append(problem);
    return where;
  }
  std::string file_;
  int line_;
};

}  // namespace ultratrack::ins
